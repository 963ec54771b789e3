// Waypoints in, a minimum-snap trajectory out (MINCO, paper Sec. IV-B), with durations from
// the trapezoidal speed profile: the back end alone, linked against miner::traj.
#include <cstdio>

#include <Eigen/Core>

#include "miner/core/error.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

int main() {
  Eigen::MatrixX3d waypoints(5, 3);
  waypoints << 0, 0, 1,  //
      2, 0, 1.5,         //
      2, 2, 2,           //
      4, 3, 1.5,         //
      5, 5, 1;
  try {
    const miner::traj::Limits limits{1.0, 0.8};  // v_max m/s, a_max m/s^2
    const auto durations = miner::traj::trapezoidal_allocation(waypoints, limits);
    // Order 4: minimum snap, at rest at both ends. Every answer is checked before it is
    // returned (finite, through its waypoints, optimality conditions): a refusal throws.
    const auto trajectory = miner::traj::solve_minco(miner::traj::rest_to_rest(4, waypoints, durations));
    std::printf("%d segments, %.3f s, snap cost %.6g\n", trajectory.segments(), trajectory.total_duration(),
                trajectory.cost());
    for (double t = 0.0; t <= trajectory.total_duration(); t += 1.0) {
      const Eigen::Vector3d p = trajectory.evaluate(t), v = trajectory.evaluate(t, 1);
      std::printf("t %.1f s  p (%.3f, %.3f, %.3f) m  |v| %.3f m/s\n", t, p.x(), p.y(), p.z(), v.norm());
    }
  } catch (const miner::Error& e) {
    std::fprintf(stderr, "minco_waypoints: %s\n", e.what());
    return 1;
  }
  return 0;
}
