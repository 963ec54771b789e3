#pragma once
/// \file
/// Strict quality of a heuristic region, measured on the continuous map rather than on the
/// heuristic grid (REQ-HEUR-011, issue 16 item 3). The grid definitions of REQ-HEUR-004
/// see a wall thinner than a cell as "partial" and a corridor narrower than a cell as
/// open; these do not:
///
///   connected_strict: a collision-free path for the robot radius joins x_init and x_goal
///     inside H. Checked by a planner restricted to H: A*'s own graph (world::grid_moves)
///     searched breadth first over the cells of the map's conservative voxel grid
///     (world::VoxelGrid, occupied when the cell meets an obstacle grown by the robot radius)
///     that are free and whose centres lie in H: 26 neighbours, a diagonal step only where
///     every cell of the block it crosses is free (no corner cutting, REQ-WORLD-008). A step
///     runs between two voxel centres and so stays inside those two voxels, both in H; the
///     block's other voxels need only be free, not in H. The answer is A*'s restricted to H:
///     the A* path's own cells are connected, which a face-to-face search (sessions 12-19)
///     denied whenever a diagonal step crossed the corner of a cell outside H.
///   safe_strict: at most kStrictUnsafeFraction (5 %) of H's volume lies within the robot
///     radius of an obstacle (its interior included), measured by the midpoint rule on the
///     same voxels: a voxel of H counts as unsafe when its centre lies within the robot
///     radius of an obstacle (exact point-to-box distance). The conservative occupancy
///     would overstate the volume by up to a voxel around every obstacle.

#include <cstddef>

#include <Eigen/Core>

namespace miner::world {
class Map;
class VoxelGrid;
}
namespace miner::plan {
class HeuristicRegion;
}

namespace miner::heuristic {

/// The share of H's volume allowed within the robot radius of an obstacle (issue 16).
inline constexpr double kStrictUnsafeFraction = 0.05;

struct StrictQuality {
  bool connected = false;
  bool safe = false;
  double unsafe_fraction = 0.0;  ///< voxels of H within the radius / voxels of H (1 if H has none)
  std::size_t voxels = 0;        ///< voxels whose centre lies in H
};

/// `grid` is `map`'s voxel grid for the robot radius; start and goal are the query.
StrictQuality strict_quality(const world::Map& map, const world::VoxelGrid& grid, const plan::HeuristicRegion& region,
                             const Eigen::Vector3d& start, const Eigen::Vector3d& goal);

}  // namespace miner::heuristic
