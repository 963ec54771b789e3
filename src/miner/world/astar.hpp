#pragma once
/// \file
/// A* on the 26-connected voxel grid (Hart, Nilsson, Raphael 1968): the ground truth
/// path of the sGAN dataset and the reference cost for planners (REQ-WORLD-007,
/// REQ-WORLD-008).

#include <array>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace miner::world {

class Map;
class VoxelGrid;

struct GridPath {
  /// start, the centre of every cell of the grid path (the start's cell to the
  /// goal's cell), goal.
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> cells;  ///< the grid cells from the start's to the goal's
  double grid_cost = 0.0;  ///< length of the cell-centre chain: sum of res * {1, sqrt2, sqrt3}
  double cost = 0.0;       ///< Euclidean length of `points` (start and goal legs included)
  std::size_t expanded = 0;  ///< cells taken off the open list
};

/// One edge of A*'s graph in index arithmetic for a grid of `dims` cells: the neighbour is
/// `offset` cells away, and the block the step spans with the current cell holds `between`
/// (the cells other than its two ends: 0, 2 or 6 of them), which must be free too, so no move
/// cuts a corner of an occupied cell. The strict connectivity of a heuristic region
/// (REQ-HEUR-011) searches the same graph, so both answer "is there a path" alike.
struct GridMove {
  int dx, dy, dz;
  double length;  ///< in cells: 1, sqrt 2 or sqrt 3
  std::ptrdiff_t offset;
  std::array<std::ptrdiff_t, 6> between;
  int n_between;
};

/// The 26 moves of the grid graph (the caller checks that the neighbour is inside the grid).
std::array<GridMove, 26> grid_moves(const Eigen::Vector3i& dims);

/// Whether every cell of the block step `m` crosses from cell index `from` (its ends aside) is
/// free in `grid` (a VoxelGrid; a template so this header needs none): no corner cutting.
template <class Grid>
inline bool block_free(const Grid& grid, std::size_t from, const GridMove& m) {
  for (int b = 0; b < m.n_between; ++b)
    if (grid.occupied(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(from) + m.between[static_cast<std::size_t>(b)])))
      return false;
  return true;
}

/// Shortest path on the grid's 26-neighbour graph between the cells of `start` and
/// `goal`, with edge length = distance between cell centres. A diagonal move is allowed
/// only if every cell of the 2x2 (or 2x2x2) block it crosses is free, so no move cuts a
/// corner of an occupied cell.
///
/// Throws miner::Error if `grid` was built from another map (VoxelGrid::map_fingerprint), if
/// start or goal is out of bounds, in collision (naming the
/// obstacle) or in an occupied grid cell, and miner::NoSolution if the goal's cell
/// is not reachable from the start's. Those messages call the ends `start_name` and
/// `goal_name` (a command passes where they came from: "map.json: query.start", "--goal").
GridPath astar(const Map& map, const VoxelGrid& grid, const Eigen::Vector3d& start,
               const Eigen::Vector3d& goal, const std::string& start_name = "start",
               const std::string& goal_name = "goal");

/// The grid distance between two cells ignoring obstacles (the consistent heuristic):
/// res * (sqrt3 d3 + sqrt2 (d2 - d3) + (d1 - d2)) for sorted |deltas| d1 >= d2 >= d3.
double octile_distance(const Eigen::Vector3i& a, const Eigen::Vector3i& b, double resolution);

}  // namespace miner::world
