#include "miner/traj/trapezoidal_allocation.hpp"

#include <cmath>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::traj {

namespace {

/// The rest-to-rest trapezoid (or triangle) time over d at the limits.
double trapezoid_time(double d, const Limits& limits) {
  const double t_a = limits.v_max / limits.a_max;
  const double d_a = limits.v_max * limits.v_max / (2.0 * limits.a_max);
  if (d < 2.0 * d_a) return 2.0 * std::sqrt(d / limits.a_max);
  return 2.0 * t_a + (d - 2.0 * d_a) / limits.v_max;
}

}  // namespace

void validate(const Limits& limits) {
  require_finite(limits.v_max, "limits.v_max");
  require_finite(limits.a_max, "limits.a_max");
  if (!(limits.v_max > 0.0)) throw Error("limits.v_max: must be positive");
  if (!(limits.a_max > 0.0)) throw Error("limits.a_max: must be positive");
}

double trapezoidal_duration(double d, const Limits& limits) {
  // Tenth campaign L15: a negative, NaN or infinite distance and limits of 5e-324 gave NaN or
  // infinite durations that MINCO then blamed on "durations[i]".
  validate(limits);
  if (!(std::isfinite(d) && d >= 0.0)) {
    std::ostringstream os;
    os << "distance: must be a finite length >= 0 m, got " << exact_number(d);
    throw Error(os.str());
  }
  const double t = trapezoid_time(d, limits);
  if (!std::isfinite(t)) {
    std::ostringstream os;
    os << "limits: v_max " << limits.v_max << " m/s and a_max " << limits.a_max << " m/s^2 give no finite time for "
       << d << " m";
    throw Error(os.str());
  }
  return t;
}

std::vector<double> trapezoidal_allocation(const Eigen::MatrixX3d& points, const Limits& limits) {
  validate(limits);
  std::vector<double> durations;
  durations.reserve(points.rows() > 0 ? points.rows() - 1 : 0);
  if (points.rows() < 2) throw Error("points: a trajectory needs at least 2 points, got " + std::to_string(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    require_finite(Eigen::Vector3d(points.row(i).transpose()), "points[" + std::to_string(i) + "]");
  for (Eigen::Index i = 1; i < points.rows(); ++i) {
    const double d = (points.row(i) - points.row(i - 1)).norm();
    if (!std::isfinite(d))
      throw Error("points[" + std::to_string(i - 1) + "] and points[" + std::to_string(i) +
                  "]: their distance overflows a double");
    durations.push_back(trapezoidal_duration(d, limits));
  }
  return durations;
}

}  // namespace miner::traj
