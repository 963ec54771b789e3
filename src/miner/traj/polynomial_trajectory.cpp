#include "miner/traj/polynomial_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::traj {

double falling_factorial(int a, int k) {
  // Eighteenth campaign F8: k = -1 returned 1 and (200, 200) inf.
  if (k < 0) throw Error("falling_factorial: k must be >= 0, got " + std::to_string(k));
  double f = 1.0;
  for (int i = 0; i < k; ++i) f *= a - i;
  if (!std::isfinite(f))
    throw Error("falling_factorial: " + std::to_string(a) + "!/(" + std::to_string(a) + " - " + std::to_string(k) +
                ")! overflows a double");
  return f;
}

void check_order(int order, const std::string& who) {
  if (order < 1 || 2 * order > kMaxCoefficientRows)
    throw Error(who + ": order must be in [1, " + std::to_string(kMaxCoefficientRows / 2) + "], got " + std::to_string(order));
}

Eigen::RowVectorXd monomial_derivative_row(int n, int k, double t) {
  // Tenth campaign L4: k = -1 wrote before the row (heap corruption), n = -1 asked for 2^64 bytes.
  if (n < 0 || n > kMaxCoefficientRows) throw Error("monomial_derivative_row: n must be in [0, " + std::to_string(kMaxCoefficientRows) + "], got " + std::to_string(n));
  if (k < 0) throw Error("monomial_derivative_row: the derivative order k must be >= 0, got " + std::to_string(k));
  // Eighteenth campaign F8: a NaN or huge t gave a row of NaN or inf, returned.
  if (!std::isfinite(t)) throw Error("monomial_derivative_row: t must be finite, got " + exact_number(t));
  Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(n);
  for (int a = k; a < n; ++a) r(a) = falling_factorial(a, k) * std::pow(t, a - k);
  if (!r.allFinite())
    throw Error("monomial_derivative_row: t = " + exact_number(t) + " overflows t^" + std::to_string(n - 1 - k));
  return r;
}

PolynomialTrajectory::PolynomialTrajectory(int order, std::vector<double> durations,
                                           Eigen::MatrixX3d coefficients)
    : order_(order), durations_(std::move(durations)), coefficients_(std::move(coefficients)) {
  // Tenth campaign L17: an order of 0 or 20, negative or NaN durations and NaN coefficients
  // made a trajectory every later step trusted.
  check_order(order_, "trajectory");
  for (std::size_t i = 0; i < durations_.size(); ++i)
    if (!(std::isfinite(durations_[i]) && durations_[i] > 0.0))
      throw Error("trajectory: durations[" + std::to_string(i) + "] must be a positive finite time in s, got " + exact_number(durations_[i]));
  if (!coefficients_.allFinite()) throw Error("trajectory: coefficients must be finite numbers");
  if (coefficients_.rows() != 2 * order_ * static_cast<Eigen::Index>(durations_.size())) {
    throw Error("trajectory: expected " + std::to_string(2 * order_ * durations_.size()) +
                " coefficient rows (2s per segment), got " + std::to_string(coefficients_.rows()));
  }
}

void PolynomialTrajectory::set_order(int order) {
  check_order(order, "trajectory");
  order_ = order;
}

void PolynomialTrajectory::check_consistent(const std::string& who) const {
  check_order(order_, who);
  for (std::size_t i = 0; i < durations_.size(); ++i)
    if (!(std::isfinite(durations_[i]) && durations_[i] > 0.0))
      throw Error(who + ": durations[" + std::to_string(i) + "] must be a positive finite time in s, got " + exact_number(durations_[i]));
  if (coefficients_.rows() != 2 * order_ * static_cast<Eigen::Index>(durations_.size()))
    throw Error(who + ": the trajectory has " + std::to_string(durations_.size()) + " durations and " +
                std::to_string(coefficients_.rows()) + " coefficient rows, not 2s = " + std::to_string(2 * order_) +
                " per duration (changed through its mutable accessors)");
}

double PolynomialTrajectory::total_duration() const {
  // Sixteenth campaign F9: durations edited through mutable_durations() were summed as they
  // were (a negative one shortened the trajectory, a NaN one made it NaN s long).
  for (std::size_t j = 0; j < durations_.size(); ++j)
    if (!(durations_[j] > 0.0 && std::isfinite(durations_[j])))
      throw Error("trajectory: durations[" + std::to_string(j) + "] must be a positive finite time in s, got " +
                  short_number(durations_[j]));
  // Seventeenth campaign F16: two durations of 1e308 summed to inf.
  const double total = std::accumulate(durations_.begin(), durations_.end(), 0.0);
  if (!std::isfinite(total))
    throw Error("trajectory: the durations sum to " + exact_number(total) + " s, not a finite time");
  return total;
}

Eigen::Vector3d PolynomialTrajectory::evaluate_segment(int i, double tau, int k) const {
  // Tenth campaign L3: segment 99 of 5 read past the coefficients, -1 before them.
  if (i < 0 || i >= segments())
    throw Error("trajectory: segment " + std::to_string(i) + " does not exist (the trajectory has " +
                std::to_string(segments()) + ")");
  if (k < 0) throw Error("k: the derivative order must be >= 0, got " + std::to_string(k));
  // Sixteenth campaign F8: a NaN local time answered NaN.
  if (!std::isfinite(tau)) throw Error("tau: must be a finite local time in s, got " + exact_number(tau));
  const int n = 2 * order_;
  const Eigen::Index rows = coefficients_.rows();
  // mutable_coefficients() may have been resized: the segment's rows must be there.
  if (static_cast<Eigen::Index>(n) * (i + 1) > rows)
    throw Error("trajectory: segment " + std::to_string(i) + " needs coefficient rows up to " +
                std::to_string(static_cast<Eigen::Index>(n) * (i + 1)) + ", the matrix has " + std::to_string(rows));
  // Horner's rule per axis on plain doubles: the operations of v = v tau + a!/(a-k)! c_a on a
  // Vector3d, in the same order (so the same bits), without an Eigen expression per step. Every
  // flight, limit check and collision check samples this; in the sanitizer build the
  // expressions cost ~20 % of a flight property's time.
  const double* c = coefficients_.data() + static_cast<Eigen::Index>(n) * i;  // column-major: x, y, z columns
  double x = 0.0, y = 0.0, z = 0.0;
  for (int a = n - 1; a >= k; --a) {
    const double f = falling_factorial(a, k);
    x = x * tau + f * c[a];
    y = y * tau + f * c[a + rows];
    z = z * tau + f * c[a + 2 * rows];
  }
  // Seventeenth campaign F16: finite coefficients at a huge local time gave inf.
  if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z)))
    throw Error("trajectory: derivative " + std::to_string(k) + " of segment " + std::to_string(i) + " at local time " +
                exact_number(tau) + " s is not finite (the coefficients overflow there)");
  return {x, y, z};
}

Eigen::Vector3d PolynomialTrajectory::evaluate(double t, int k) const {
  if (durations_.empty()) throw Error("trajectory: has no segments");
  // A negative order read coefficients before the segment's own, a NaN time answered the start
  // (issue 20, ninth campaign P1, P12: from Python, garbage, NaN and a segmentation fault).
  if (k < 0) throw Error("k: the derivative order must be >= 0, got " + std::to_string(k));
  // ... and an infinite one was clamped to an end (sixteenth campaign F8): a time is finite.
  if (!std::isfinite(t)) throw Error("t: must be a finite time in s, got " + exact_number(t));
  int i = 0;
  const int last = segments() - 1;
  t = std::max(0.0, t);
  while (i < last && t >= durations_[i]) t -= durations_[i++];
  // The walk trusts the durations it passed and the one it stops in (L7: a negative or NaN
  // duration set through mutable_durations() was evaluated).
  for (int j = 0; j <= i; ++j)
    if (!(durations_[j] > 0.0 && std::isfinite(durations_[j])))
      throw Error("trajectory: durations[" + std::to_string(j) + "] must be a positive finite time in s, got " + exact_number(durations_[j]));
  return evaluate_segment(i, std::min(t, durations_[i]), k);
}

Eigen::MatrixXd monomial_cost_matrix(int order, double duration) {
  // Tenth campaign L17: a negative duration gave a negative energy, NaN a NaN matrix.
  check_order(order, "monomial_cost_matrix");
  if (!(std::isfinite(duration) && duration >= 0.0))
    throw Error("monomial_cost_matrix: duration must be a finite time >= 0 s, got " + exact_number(duration));
  const int n = 2 * order;
  Eigen::MatrixXd q = Eigen::MatrixXd::Zero(n, n);
  for (int a = order; a < n; ++a)
    for (int b = order; b < n; ++b) {
      const int e = a + b - 2 * order + 1;
      q(a, b) = falling_factorial(a, order) * falling_factorial(b, order) * std::pow(duration, e) / e;
    }
  // Eighteenth campaign F8: 1e300 s gave inf entries, returned.
  if (!q.allFinite())
    throw Error("monomial_cost_matrix: Q(T) is not finite (the duration " + exact_number(duration) +
                " s overflows T^" + std::to_string(2 * order - 1) + ")");
  return q;
}

namespace {
/// monomial_cost_matrix, its overflow named for `who` (cost, gradient).
Eigen::MatrixXd cost_matrix(int order, double duration, const char* who) {
  try {
    return monomial_cost_matrix(order, duration);
  } catch (const Error& e) {
    throw Error(std::string(who) + ": not finite: " + e.what());
  }
}
}  // namespace

double PolynomialTrajectory::cost() const {
  check_consistent("trajectory cost");
  double j = 0.0;
  for (int i = 0; i < segments(); ++i) {
    const auto c = segment_coefficients(i);
    j += (c.transpose() * cost_matrix(order_, durations_[i], "trajectory cost") * c).trace();
  }
  // Seventeenth campaign F16: a duration of 1e100 gave a NaN cost (inf x 0 in Q(T) c).
  if (!std::isfinite(j))
    throw Error("trajectory cost: is " + exact_number(j) + ", not finite (durations up to " +
                exact_number(*std::max_element(durations_.begin(), durations_.end())) + " s overflow Q(T))");
  return j;
}

Eigen::MatrixX3d PolynomialTrajectory::cost_gradient_coefficients() const {
  check_consistent("trajectory cost gradient");
  Eigen::MatrixX3d g(coefficients_.rows(), 3);
  for (int i = 0; i < segments(); ++i) {
    g.middleRows(2 * order_ * i, 2 * order_) =
        2.0 * cost_matrix(order_, durations_[i], "trajectory cost gradient") * segment_coefficients(i);
  }
  if (!g.allFinite())
    throw Error("trajectory cost gradient: not finite (durations up to " +
                exact_number(*std::max_element(durations_.begin(), durations_.end())) + " s overflow Q(T))");
  return g;
}

}  // namespace miner::traj
