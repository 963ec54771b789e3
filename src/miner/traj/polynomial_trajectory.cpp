#include "miner/traj/polynomial_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "miner/core/error.hpp"

namespace miner::traj {

double falling_factorial(int a, int k) {
  double f = 1.0;
  for (int i = 0; i < k; ++i) f *= a - i;
  return f;
}

Eigen::RowVectorXd monomial_derivative_row(int n, int k, double t) {
  Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n);
  for (int a = k; a < n; ++a) r(a) = falling_factorial(a, k) * std::pow(t, a - k);
  return r;
}

PolynomialTrajectory::PolynomialTrajectory(int order, std::vector<double> durations,
                                           Eigen::MatrixX3d coefficients)
    : order_(order), durations_(std::move(durations)), coefficients_(std::move(coefficients)) {
  if (coefficients_.rows() != 2 * order_ * static_cast<Eigen::Index>(durations_.size())) {
    throw Error("trajectory: expected " + std::to_string(2 * order_ * durations_.size()) +
                " coefficient rows (2s per segment), got " + std::to_string(coefficients_.rows()));
  }
}

double PolynomialTrajectory::total_duration() const {
  return std::accumulate(durations_.begin(), durations_.end(), 0.0);
}

Eigen::Vector3d PolynomialTrajectory::evaluate_segment(int i, double tau, int k) const {
  const int n = 2 * order_;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  const auto c = segment_coefficients(i);
  for (int a = n - 1; a >= k; --a) v = v * tau + falling_factorial(a, k) * c.row(a).transpose();
  return v;
}

Eigen::Vector3d PolynomialTrajectory::evaluate(double t, int k) const {
  if (durations_.empty()) throw Error("trajectory: has no segments");
  // A negative order read coefficients before the segment's own, a NaN time answered the start
  // (issue 20, ninth campaign P1, P12: from Python, garbage, NaN and a segmentation fault).
  if (k < 0) throw Error("k: the derivative order must be >= 0, got " + std::to_string(k));
  if (std::isnan(t)) throw Error("t: must be a time in s, got nan");
  int i = 0;
  const int last = segments() - 1;
  t = std::max(0.0, t);
  while (i < last && t >= durations_[i]) t -= durations_[i++];
  return evaluate_segment(i, std::min(t, durations_[i]), k);
}

Eigen::MatrixXd monomial_cost_matrix(int order, double duration) {
  const int n = 2 * order;
  Eigen::MatrixXd q = Eigen::MatrixXd::Zero(n, n);
  for (int a = order; a < n; ++a)
    for (int b = order; b < n; ++b) {
      const int e = a + b - 2 * order + 1;
      q(a, b) = falling_factorial(a, order) * falling_factorial(b, order) * std::pow(duration, e) / e;
    }
  return q;
}

double PolynomialTrajectory::cost() const {
  double j = 0.0;
  for (int i = 0; i < segments(); ++i) {
    const auto c = segment_coefficients(i);
    j += (c.transpose() * monomial_cost_matrix(order_, durations_[i]) * c).trace();
  }
  return j;
}

Eigen::MatrixX3d PolynomialTrajectory::cost_gradient_coefficients() const {
  Eigen::MatrixX3d g(coefficients_.rows(), 3);
  for (int i = 0; i < segments(); ++i) {
    g.middleRows(2 * order_ * i, 2 * order_) =
        2.0 * monomial_cost_matrix(order_, durations_[i]) * segment_coefficients(i);
  }
  return g;
}

}  // namespace miner::traj
