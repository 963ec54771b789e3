#pragma once
/// \file
/// Internal to miner_world: the voxel layer of an in-memory OctoMap tree, from its leaves' keys
/// and depths (exact, no float coordinates), each classified as OctoMap's maximum-likelihood tree
/// would (isNodeOccupied). MINER's writer then gives the bytes OctoMap's writeBinary would.

#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "miner/world/octree_io.hpp"

namespace miner::world {

inline std::shared_ptr<const VoxelLayer> layer_of_tree(const octomap::OcTree& tree, const std::string& origin) {
  std::vector<OctreeLeaf> leaves;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey corner = it.getIndexKey();
    leaves.push_back({{corner[0], corner[1], corner[2]}, static_cast<std::uint8_t>(it.getDepth()),
                      tree.isNodeOccupied(*it) ? VoxelState::kOccupied : VoxelState::kFree});
  }
  return layer_from_leaves(leaves, tree.getResolution(), origin);
}

}  // namespace miner::world
