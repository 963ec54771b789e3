#pragma once
/// \file
/// Reference costs for the front end (REQ-PLAN-009): the A* path on the conservative
/// voxel grid, whose length defines the benchmark's target cost (factor x A* cost) and
/// whose dilation is the ground-truth heuristic region; and the straight-line lower
/// bound |x_goal - x_init| that no collision-free path can beat.

#include <vector>

#include <Eigen/Core>

#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/rrt_star.hpp"

namespace miner::plan {

struct ReferencePath {
  std::vector<Eigen::Vector3d> points;  ///< x_init, cell centres, x_goal
  double cost = 0.0;                    ///< Euclidean length of points
};

/// A* (26-connected, no corner cutting) on the voxel grid of the problem's map at the
/// map's resolution, inflated by the robot radius. Every segment of the result is
/// collision-free in the continuous map. Throws miner::NoSolution if the grid has no path.
ReferencePath astar_reference(const PlanningProblem& problem);

/// The A*-dilated ground-truth region (source "astar-dilated") over the problem's map:
/// HeuristicRegion::from_path of the reference path on a dims grid.
HeuristicRegion astar_dilated_region(const PlanningProblem& problem, const ReferencePath& reference,
                                     const Eigen::Vector3i& dims, int dilation);

/// |x_goal - x_init|: a lower bound on the cost of every path of the problem.
double straight_line_bound(const PlanningProblem& problem);

}  // namespace miner::plan
