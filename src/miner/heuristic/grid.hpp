#pragma once
/// \file
/// The heuristic grid: a fixed dims grid over the map bounds on which the sGAN sees the
/// world and predicts the region (paper Sec. IV-A.2), and the exact, computable meaning of
/// the paper's "connected" and "safe" regions (Sec. V-A.1, ../shared/design.md errata).
///
/// Cell (i, j, k) is the closed box bounds.min + [i, i+1] x [j, j+1] x [k, k+1] * cell with
/// cell = (bounds.max - bounds.min) / dims; index (k ny + j) nx + i (x fastest), the same
/// convention as plan::HeuristicRegion and the dataset shards.
///
/// Environment levels (channel E):
///   kFree    the cell box does not meet any obstacle grown by the robot radius;
///   kPartial it meets one, but free space remains in it (a path may cross it);
///   kSolid   it is covered by the union of the grown obstacles: no collision-free point
///            lies in its interior, so sampling there is wasted. These are the paper's
///            "obstacles that exceed the size of one grid" (Sec. V-A.1).
/// A region (a set of cells) is *safe* iff it holds no kSolid cell, and *connected* iff the
/// cells of the start and of the goal are in it and a chain of its cells, consecutive ones
/// sharing a face, an edge or a corner (26-connectivity), joins them (REQ-HEUR-004).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/world/box.hpp"

namespace miner::world {
class Map;
}

namespace miner::heuristic {

enum EnvLevel : std::uint8_t { kFree = 0, kPartial = 1, kSolid = 2 };

inline std::size_t cell_index(const Eigen::Vector3i& dims, int i, int j, int k) {
  return (static_cast<std::size_t>(k) * static_cast<std::size_t>(dims.y()) + static_cast<std::size_t>(j)) *
             static_cast<std::size_t>(dims.x()) +
         static_cast<std::size_t>(i);
}
/// The (x, y, z) of cell `index`; throws miner::Error for an index past the grid.
Eigen::Vector3i cell_coords(const Eigen::Vector3i& dims, std::size_t index);
/// (bounds.max - bounds.min) / dims; throws miner::Error for a grid with no cells on an axis
/// (dims < 1) or bounds that are not finite with max > min on every axis: the check of every
/// helper here that places cells (cell_of, cell_box, the encoders).
Eigen::Vector3d cell_size(const world::Box& bounds, const Eigen::Vector3i& dims);
/// The cell holding p (clamped onto the grid for points on or beyond the bounds); throws
/// miner::Error for a point that is not finite or a grid cell_size() refuses.
Eigen::Vector3i cell_of(const world::Box& bounds, const Eigen::Vector3i& dims, const Eigen::Vector3d& p);
/// The box of cell c; a c past the grid gives the box the grid's lattice puts there (the
/// encoder reads cell edges per axis this way).
world::Box cell_box(const world::Box& bounds, const Eigen::Vector3i& dims, const Eigen::Vector3i& c);

/// The most sub-box-in-box tests box_covered() makes (issue 20: n boxes with distinct faces
/// inside one cell cut it into up to (2n + 1)^3 sub-boxes, each tested against n boxes).
inline constexpr std::uint64_t kMaxCoverTests = std::uint64_t{1} << 24;

/// The most sub-box-in-box tests one encoding spends on exact cover tests over all its cells
/// (a per-cell bound alone let 4096 cells at ~2^24 tests each run for minutes).
inline constexpr std::uint64_t kMaxEncodeCoverTests = std::uint64_t{1} << 26;

/// Whether the closed box `cell` lies inside the union of `boxes` (exact: the boxes'
/// faces cut the cell into sub-boxes, each of which is inside one box or outside all). Past
/// kMaxCoverTests tests (sub-boxes x boxes), or past what is left of `*budget` when given (the
/// tests are then taken from it), it answers false unproven: the encoding then keeps such a
/// cell partial, never solid.
bool box_covered(const world::Box& cell, const std::vector<world::Box>& boxes, std::uint64_t* budget = nullptr);

/// Channel E: kFree / kPartial / kSolid per cell for obstacles grown by `radius`. Boxes are cut
/// exactly; a voxel layer (REQ-WORLD-012) is read from its occupancy in one pass over the voxels
/// (REQ-HEUR-012): a cell holding a voxel centre within `radius` of a blocked voxel's centre is
/// partial, solid when all the voxel centres it holds are and the layer covers it.
std::vector<std::uint8_t> encode_environment(const world::Map& map, const Eigen::Vector3i& dims, double radius);

/// Channel P bits (issue 16: a door and a wall are both kPartial in E; P tells them apart).
enum PassabilityBit : std::uint8_t { kPassX = 1, kPassY = 2, kPassZ = 4, kPassAll = 7 };
/// The most cells, summed over a map's grown boxes, that a box meets without holding them
/// whole (its shell on the grid), past which the encoding refuses the map (issue 20: the work
/// grows with it; a box's interior is summed in O(1) per box). 2^27: ~500 MB of lists at most;
/// the 226k-box map of docs/heuristic.md needs ~10^6.
inline constexpr std::uint64_t kMaxEncodeShellCells = std::uint64_t{1} << 27;

/// Sub-cells per axis on which P is decided (4^3 = 64: one bit mask of a 64-bit word per cell).
inline constexpr int kPassabilitySubcells = 4;

/// Channels E and P of one map, from one pass over its obstacles (the same E as
/// encode_environment). P, per cell: bit a (kPassX, kPassY, kPassZ) set when the cell's free
/// space joins its two faces across axis a. Decided on kPassabilitySubcells^3 sub-cells: a
/// sub-cell is blocked when its centre lies in a grown box or in a grown-blocked voxel (the
/// voxel holding it); the face-adjacent free sub-cells of the low face a are flooded through
/// face-adjacent free sub-cells, and the bit is set when the flood reaches the high face. kFree
/// cells are kPassAll and kSolid cells 0 without the flood. A thin wall crossing a cell (its
/// grown slab wider than a sub-cell) clears the bit of the axis it crosses; a door through it
/// (its free gap wider than a sub-cell) keeps it.
struct Encoding {
  std::vector<std::uint8_t> environment, passability;  ///< each dims.prod(), x fastest
};
Encoding encode_environment_passability(const world::Map& map, const Eigen::Vector3i& dims, double radius);

/// The kPassabilitySubcells^3 free-sub-cell mask (bit x + 4 y + 16 z) -> its P bits.
std::uint8_t passability_of(std::uint64_t free_subcells);

/// The sub-cells of `cell` (bit x + 4 y + 16 z of kPassabilitySubcells^3) whose centres lie in
/// the closed box g: the sub-cells a grown box blocks in encode_environment_passability. A
/// centre on g's boundary is inside; g may reach past the cell (what lies outside is ignored).
std::uint64_t subcells_inside(const world::Box& cell, const world::Box& g);

/// Channel S: the (2 dilation + 1)^3 cubes around the cells of start and goal.
std::vector<std::uint8_t> encode_state(const world::Box& bounds, const Eigen::Vector3i& dims,
                                       const Eigen::Vector3d& start, const Eigen::Vector3d& goal, int dilation);

/// Throws miner::Error "<what> (x, y, z) lies outside the nx x ny x nz grid" unless cell c is in
/// the grid: the check of every function here that takes a cell.
void require_cell_in_grid(const Eigen::Vector3i& c, const Eigen::Vector3i& dims, const std::string& what);

/// Throws miner::Error "<what> cell i holds v, outside its levels 0..max" for the first value
/// above max: the check of an encoded channel's levels (E 0..2, S 0..1, P 0..kPassAll).
void require_levels(const std::vector<std::uint8_t>& values, std::uint8_t max, const std::string& what);

/// The index of the first value of p outside [0, 1] (NaN included), p.size() if every value is a
/// probability: the check of R wherever a probability grid is taken or returned.
std::size_t first_non_probability(const std::vector<float>& p);

/// Labels the 26-connected components of the cells with mask != 0: label 0 for cells
/// outside the mask, 1.. for components in order of their lowest index.
std::vector<int> label_components(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims);

/// The 26-connected component of the mask cells that holds `cell`: 1 on its cells, 0 elsewhere
/// (all 0 if mask[cell] is 0). A breadth-first search that touches only that component, not
/// the whole grid as label_components does; `stop`, if a valid index, ends it once reached.
/// Throws miner::Error for a mask that is not dims' size or a cell past it.
std::vector<std::uint8_t> component_of(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims,
                                       std::size_t cell, std::size_t stop = SIZE_MAX);

/// Whether the region `mask` is connected between the cells a and b (see the file comment).
bool connects(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims, const Eigen::Vector3i& a,
              const Eigen::Vector3i& b);

/// Number of kSolid cells of `env` inside the region `mask` (the region is safe iff 0); throws
/// miner::Error when the two differ in size.
std::size_t solid_cells_in(const std::vector<std::uint8_t>& mask, const std::vector<std::uint8_t>& env);

}  // namespace miner::heuristic
