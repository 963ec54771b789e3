#include "miner/traj/trapezoidal_allocation.hpp"

#include <cmath>
#include <sstream>

#include "miner/core/error.hpp"

namespace miner::traj {

void validate(const Limits& limits) {
  require_finite(limits.v_max, "limits.v_max");
  require_finite(limits.a_max, "limits.a_max");
  if (!(limits.v_max > 0.0)) throw Error("limits.v_max: must be positive");
  if (!(limits.a_max > 0.0)) throw Error("limits.a_max: must be positive");
}

double trapezoidal_duration(double d, const Limits& limits) {
  const double t_a = limits.v_max / limits.a_max;
  const double d_a = limits.v_max * limits.v_max / (2.0 * limits.a_max);
  if (d < 2.0 * d_a) return 2.0 * std::sqrt(d / limits.a_max);
  return 2.0 * t_a + (d - 2.0 * d_a) / limits.v_max;
}

std::vector<double> trapezoidal_allocation(const Eigen::MatrixX3d& points, const Limits& limits) {
  validate(limits);
  std::vector<double> durations;
  durations.reserve(points.rows() > 0 ? points.rows() - 1 : 0);
  for (Eigen::Index i = 1; i < points.rows(); ++i) {
    durations.push_back(trapezoidal_duration((points.row(i) - points.row(i - 1)).norm(), limits));
  }
  return durations;
}

}  // namespace miner::traj
