#pragma once
/// \file
/// OctoMap files in and out of voxel layers (REQ-WORLD-003, REQ-WORLD-014).
///
/// The reader is MINER's own, not OctoMap's: OctoMap's readers recurse once per node on
/// untrusted bytes and overflow the stack on a valid header followed by random data. This one
/// walks the tree with an explicit stack bounded by OctoMap's 16 levels, checks the header
/// (id, size, res), every byte count and the node count against `size`, and caps the leaves
/// and voxels before it allocates them. Every fault is a miner::Error naming the file and
/// what is wrong.
///   .bt  (OcTree binary): per node two bytes, two bits per child: 00 unknown, 01 free leaf
///        (bit 2i), 10 occupied leaf (bit 2i+1), 11 inner; children in pre-order.
///   .ot  (OcTree or ColorOcTree full file): per node its log-odds (float; ColorOcTree adds three
///        colour bytes) and one byte of child bits; a leaf is occupied iff its log-odds >= 0
///        (OctoMap's default threshold, p = 0.5).
/// The format is taken from the header line, not the file name.
///
/// The writer emits the maximum-likelihood, pruned .bt OctoMap itself writes for the same
/// voxels (same bytes: the tests compare them), in one pass over a pyramid of block states.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>
#include <memory>
#include <string>

#include "miner/world/voxel_layer.hpp"

namespace miner::world {

/// Most leaves an OctoMap file may hold (2^26: ~0.5 GB while reading); a larger file is refused.
inline constexpr std::size_t kMaxOctreeLeaves = std::size_t{1} << 26;
/// OctoMap keys are 16 bits; voxel key k has its centre at (k - kOctreeKeyOffset + 0.5) * res.
inline constexpr int kOctreeKeyOffset = 32768;

/// A known leaf of an octree: its lower-corner key, depth (16: one voxel) and state.
struct OctreeLeaf {
  std::array<std::uint16_t, 3> key;
  std::uint8_t depth;
  VoxelState state;
};
/// The layer of a set of leaves: bounded by their extent, unknown between them. Throws
/// (prefixed by `origin`) when the extent exceeds `max_cells` (default kMaxGridCells) or no
/// leaf is given.
std::shared_ptr<const VoxelLayer> layer_from_leaves(const std::vector<OctreeLeaf>& leaves, double resolution,
                                                    const std::string& origin, double max_cells);
std::shared_ptr<const VoxelLayer> layer_from_leaves(const std::vector<OctreeLeaf>& leaves, double resolution,
                                                    const std::string& origin);

/// Reads a .bt or .ot file into a layer whose voxels are unknown outside the tree's leaves and
/// whose bounds are the leaves' extent.
std::shared_ptr<const VoxelLayer> read_octree(const std::string& path);
/// Parses the bytes of a .bt or .ot file; `origin` names it in messages. A tree whose known
/// leaves span more than `max_cells` voxels is refused (the fuzz target lowers the bound so its
/// executions stay fast; the check is the same).
std::shared_ptr<const VoxelLayer> parse_octree(const std::string& bytes, const std::string& origin,
                                               double max_cells);
/// parse_octree bounded by kMaxGridCells, the bound of every map.
std::shared_ptr<const VoxelLayer> parse_octree(const std::string& bytes, const std::string& origin);

/// The .bt bytes of a layer (free and occupied voxels; unknown ones are left out). Throws
/// when the layer lies outside OctoMap's key range or holds no known voxel.
std::string octree_bt_bytes(const VoxelLayer& layer);
/// Writes octree_bt_bytes atomically.
void write_octree_bt(const VoxelLayer& layer, const std::string& path);

}  // namespace miner::world
