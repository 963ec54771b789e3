#pragma once
/// \file
/// Scenarios built in code for the flight tests (header-only; link miner_flight).

#include <memory>

#include "miner/pipeline/scenario.hpp"
#include "miner/world/map.hpp"

namespace miner::testing {

/// An empty 20 x 20 x 10 m room with the default vehicle, sensors, N3 and controller;
/// the reference goes through `points` (first: start, last: goal, at least two).
inline pipeline::Scenario open_room_scenario(const Eigen::MatrixX3d& points, double v_max = 1.0,
                                           double a_max = 1.0, std::uint64_t seed = 1) {
  pipeline::Scenario s;
  s.name = "open-room";
  s.origin = "<test scenario>";
  s.map = std::make_shared<const world::Map>(world::Box{{0, 0, 0}, {20, 20, 10}}, 0.5, std::vector<world::Box>{});
  s.start = points.row(0).transpose();
  s.goal = points.row(points.rows() - 1).transpose();
  s.waypoints = points.middleRows(1, points.rows() - 2);
  s.limits = {v_max, a_max};
  s.seed = seed;
  s.hover_after_s = 3.0;
  s.ekf.imu = s.imu;
  s.ekf.pose = s.pose;
  return s;
}

}  // namespace miner::testing
