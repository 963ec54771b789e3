#pragma once
/// \file
/// Trapezoidal time allocation (paper Sec. IV-B.2, after Shomin & Hollis 2014), with the
/// erratum of ../shared/design.md fixed (REQ-TRAJ-001):
///
///   t_a = v_max / a_max,  d_a = v_max^2 / (2 a_max)   (time and distance to reach v_max)
///   T(d) = 2 sqrt(d / a_max)                 if d < 2 d_a  (triangular profile)
///   T(d) = 2 t_a + (d - 2 d_a) / v_max       otherwise     (trapezoidal profile)
///
/// (The paper writes d = a_max^2 / 2, which is not a distance.) The two branches meet
/// at d = 2 d_a, where both give 2 t_a, and T is increasing in d.

#include <vector>

#include <Eigen/Core>

namespace miner::traj {

struct Limits {
  double v_max = 2.0;  ///< m/s
  double a_max = 1.0;  ///< m/s^2
};

/// Throws miner::Error unless v_max and a_max are finite and positive.
void validate(const Limits& limits);

/// T(d) above for one segment of length d >= 0.
double trapezoidal_duration(double d, const Limits& limits);

/// T(|p_{i+1} - p_i|) for each consecutive pair of the (M+1) x 3 `points`.
std::vector<double> trapezoidal_allocation(const Eigen::MatrixX3d& points, const Limits& limits);

}  // namespace miner::traj
