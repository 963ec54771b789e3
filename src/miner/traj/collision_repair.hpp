#pragma once
/// \file
/// Collision repair (paper Alg. 2 lines 8-20, after Bry et al. 2015; REQ-TRAJ-008):
/// allocate durations (trapezoid, or optimised: REQ-TRAJ-011), solve MINCO rest-to-rest through the path, check
/// every segment against the map for the robot radius, insert the halfway point of the
/// straight path segment under each colliding trajectory segment, and repeat. As
/// waypoints are added the trajectory converges to the (collision-free) polyline, so the
/// loop ends; it is bounded by `max_iterations` all the same.

#include <Eigen/Core>

#include <optional>

#include "miner/traj/minco.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"
#include "miner/world/map.hpp"

namespace miner::traj {

struct RepairOptions {
  int order = 4;             ///< s: 3 jerk, 4 snap
  Limits limits;             ///< for the trapezoidal allocation
  double robot_radius = 0.0; ///< m
  int max_iterations = 10;   ///< re-solves after the first
  /// Collision sampling: consecutive samples at most this far apart (m); the chords
  /// between samples are checked exactly. 0 means half the map resolution, and at most the
  /// robot radius (the curve then keeps at least three quarters of it between samples).
  double sample_step = 0.0;
  /// Durations by optimise_allocation (REQ-TRAJ-011; its limits are `limits`) instead of the
  /// trapezoid, in every round, so the optimised curve is the one repaired.
  std::optional<AllocationOptions> optimise;
};

struct RepairResult {
  PolynomialTrajectory trajectory;
  Eigen::MatrixX3d waypoints;  ///< the path with the inserted halfway points
  int iterations = 0;          ///< re-solves performed
  int inserted = 0;            ///< halfway points inserted
  std::optional<AllocationResult> allocation;  ///< the last round's, with `optimise`
};

/// The chord spacing the repair and the pipeline's checks use: min(res / 2, robot radius)
/// (res / 2 for a point robot), so the curve between two chords keeps >= 3/4 of the radius.
double collision_sample_step(const world::Map& map, double robot_radius);

/// Index of the first trajectory segment whose sampled chords come within the robot
/// radius of an obstacle, for every colliding segment (empty when free); consecutive samples
/// at most `sample_step` of arc apart. Throws miner::Error for a radius outside the robot
/// radius range, a step that is not positive and finite, or one that would need more than
/// 10^8 samples on a segment.
std::vector<int> colliding_segments(const PolynomialTrajectory& trajectory, const world::Map& map,
                                    double robot_radius, double sample_step);

/// Throws miner::Error if a straight segment of `path` itself collides (naming it: no
/// repair can help) and miner::NoSolution if collisions remain after max_iterations.
RepairResult repair_collisions(const world::Map& map, const Eigen::MatrixX3d& path, const RepairOptions& options);

}  // namespace miner::traj
