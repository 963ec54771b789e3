#pragma once
/// \file
/// Step 5 of the filter (REQ-HEUR-014): the strict bridge. Steps 1-4 (region_filter.hpp)
/// connect H on the heuristic grid, where a door narrower than a cell or a wall thinner than
/// one is invisible; a planner restricted to H may then find no collision-free way from
/// x_init to x_goal (the strict definition of REQ-HEUR-011). This step searches, on the
/// continuous map, for a collision-free polyline for the robot radius from x_init to x_goal
/// that stays inside H where it can, and adds the cells it leaves H through.
///
/// The search is A* over two kinds of node, on the cells of H dilated by kStrictReach cells
/// (never a kSolid one):
///   - a kFree cell is one node at its centre (on a box map no point of it is within the
///     robot radius of an obstacle, so every segment inside it, or between it and a
///     face-neighbour's free part, is collision-free: no test needed; a voxel map's kFree
///     comes from voxel centres, so there its moves are tested like the others);
///   - any other cell is split into k_x x k_y x k_z sub-cells of side <= the robot radius
///     (k_a = ceil(cell_a / r), at most kStrictMaxSplit), one node each at its centre;
///     a move between face-neighbouring sub-cells is allowed when the segment between their
///     centres is collision-free for kStrictClearance x the robot radius
///     (world::Map::segment_free, the planner's own test, with a margin).
/// Each move lies inside the two cells it joins. The cost of a path is its length plus
/// kStrictOutsidePenalty x (the longest cell side) per cell outside H it enters, so it stays
/// in H when H holds a way through and otherwise leaves it through as few cells as it can.
/// The search is weighted A* (f = g + kStrictGreed x the straight-line distance to x_goal):
/// any way will do, so it heads for the goal instead of proving the shortest. Moves are
/// tested lazily (when taken, not when seen), so the tests made are about the nodes
/// expanded; at most kStrictMaxExpansions nodes are expanded and kStrictMaxTests segments
/// tested (bounded work on any map). The polyline found is checked before H changes: every
/// segment collision-free (segment_free, same clearance) and every vertex and midpoint in a
/// cell of the repaired H; if the check fails, H is left as it was.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace miner::world {
class Map;
}

namespace miner::heuristic {

/// Cells of H within this Chebyshev distance (in cells) are searched: the bridge may leave
/// H, but only near it, which bounds the search on any map (REQ-HEUR-014).
inline constexpr int kStrictReach = 2;
/// A sub-cell is at most the robot radius on a side, so an opening that leaves the robot's
/// centre a band of one radius always holds a sub-cell centre; at most this many per axis,
/// so a coarse cell costs at most 8^3 nodes.
inline constexpr int kStrictMaxSplit = 8;
/// Entering a cell outside H costs as much as this many of the longest cell side of length:
/// a way through H up to ~4 cells longer is preferred to one cell added.
inline constexpr double kStrictOutsidePenalty = 4.0;
/// The search tests segments for this multiple of the robot radius: a way through a gap
/// that leaves the robot no margin is a way RRT*'s samples seldom find (on 20 held-back
/// rooms maps, exact clearance cut MINER's median iterations to the target by 0 %, 1.5 r
/// by 38 %, 2 r by 0 %: it closes doors; docs/heuristic.md).
inline constexpr double kStrictClearance = 1.5;
/// Weight of the distance-to-goal term (weighted A*): on the same maps, 1 expanded 18.7 k
/// nodes per query on average, 2: 7.7 k, 4: 5.9 k, with the same witnesses found.
inline constexpr double kStrictGreed = 4.0;
/// Work bounds: beyond either, the search stops and H is kept (~5 ms on one core).
inline constexpr std::size_t kStrictMaxExpansions = 20000;
inline constexpr std::size_t kStrictMaxTests = 20000;

struct StrictBridgeReport {
  bool searched = false;       ///< the step ran (start and goal inside the bounds)
  bool connected = false;      ///< a checked polyline inside the (repaired) H joins start and goal
  std::size_t added = 0;       ///< cells added to H
  std::size_t expansions = 0;  ///< nodes expanded
  std::size_t segment_tests = 0;
  bool budget_exhausted = false;
  std::vector<Eigen::Vector3d> polyline;  ///< the witness, start to goal (empty if none)
};

/// Runs step 5 on `mask` (1 = in H, over map.bounds() split into `dims` cells with levels
/// `env`), adding cells to it. `env` must be encode_environment(map, dims, robot_radius).
StrictBridgeReport strict_bridge(const world::Map& map, double robot_radius, const Eigen::Vector3i& dims,
                                 const std::vector<std::uint8_t>& env, std::vector<std::uint8_t>& mask,
                                 const Eigen::Vector3d& start, const Eigen::Vector3d& goal);

}  // namespace miner::heuristic
