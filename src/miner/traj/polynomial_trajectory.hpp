#pragma once
/// \file
/// A piecewise polynomial trajectory in flat output space (paper Eq. for p_i(t)):
///   p_i(t) = c_i^T rho(t),  rho(t) = (1, t, ..., t^{2s-1})^T,  t in [0, T_i] (local time),
/// c_i in R^{2s x 3}. Evaluation of position and derivatives up to snap, the control
/// effort J = sum_i int_0^{T_i} |p_i^{(s)}(t)|^2 dt (no 1/2 factor) and its gradient with
/// respect to the coefficients (REQ-TRAJ-004, REQ-TRAJ-005).

#include <string>
#include <vector>

#include <Eigen/Core>

namespace miner::traj {

/// The most coefficients per segment and axis (2s) a trajectory may have: s <= 4 (MINCO solves
/// s = 3 and 4; the time allocation's samplers hold at most 8 rows).
inline constexpr int kMaxCoefficientRows = 8;
/// Throws miner::Error "<who>: order must be in [1, kMaxCoefficientRows / 2], got <order>".
void check_order(int order, const std::string& who);

class PolynomialTrajectory {
 public:
  PolynomialTrajectory() = default;
  /// `coefficients` stacks the M blocks c_i (2s rows each) into a (2s M) x 3 matrix. Throws
  /// miner::Error for an order outside [1, kMaxCoefficientRows / 2], a duration that is not
  /// positive and finite, a non-finite coefficient or a row count other than 2s M.
  PolynomialTrajectory(int order, std::vector<double> durations, Eigen::MatrixX3d coefficients);

  int order() const { return order_; }  ///< s
  int segments() const { return static_cast<int>(durations_.size()); }
  const std::vector<double>& durations() const { return durations_; }
  /// Sum of the durations; throws miner::Error naming one that is not positive and finite
  /// (mutable_durations() may have changed it), or when the sum is not finite.
  double total_duration() const;
  const Eigen::MatrixX3d& coefficients() const { return coefficients_; }
  /// c_i, 2s x 3 (segment index i from 0).
  Eigen::Block<const Eigen::MatrixX3d, Eigen::Dynamic, 3> segment_coefficients(int i) const {
    return coefficients_.middleRows(2 * order_ * i, 2 * order_);
  }
  /// For solvers refilling a trajectory in place (keeps the allocations). What they leave is
  /// checked where it is read: cost(), cost_gradient_coefficients(), evaluate() and the peak
  /// finders call check_consistent() (twelfth campaign L7: a duration pushed without its
  /// coefficients made cost() read past the matrix, a negative one was evaluated).
  Eigen::MatrixX3d& mutable_coefficients() { return coefficients_; }
  /// Throws miner::Error for an order outside [1, kMaxCoefficientRows / 2].
  void set_order(int order);
  std::vector<double>& mutable_durations() { return durations_; }
  /// The constructor's checks on the object as it is now (durations positive and finite, 2s
  /// coefficient rows per duration, the order in range; coefficients not rescanned for NaN):
  /// throws miner::Error naming `who` and the fault.
  void check_consistent(const std::string& who) const;

  /// The k-th derivative (k = 0 position ... 4 snap, any k >= 0) of segment i at local
  /// time tau (Horner's rule on the differentiated coefficients). Throws miner::Error for a
  /// segment index outside [0, segments()), k < 0, a tau that is not finite, or a value that
  /// is not (finite coefficients overflow at a huge tau).
  Eigen::Vector3d evaluate_segment(int i, double tau, int k = 0) const;
  /// The k-th derivative at global time t, clamped to [0, total_duration()]; at a
  /// junction the later segment is used. Throws miner::Error for a t that is not finite.
  Eigen::Vector3d evaluate(double t, int k = 0) const;

  /// J = sum_i c_i^T Q(T_i) c_i (summed over axes), Q_ab = int_0^T (d^s t^a)(d^s t^b) dt.
  /// Throws miner::Error when J is not finite (Q(T) overflows for huge durations), never NaN.
  double cost() const;
  /// dJ/dc_i = 2 Q(T_i) c_i, stacked like coefficients(); throws miner::Error when not finite.
  Eigen::MatrixX3d cost_gradient_coefficients() const;

 private:
  int order_ = 3;
  std::vector<double> durations_;
  Eigen::MatrixX3d coefficients_;
};

/// a! / (a - k)!: the factor of t^{a-k} in the k-th derivative of t^a. Throws miner::Error
/// for k < 0 or a result past a double's range.
double falling_factorial(int a, int k);

/// The row d^k/dt^k (1, t, ..., t^{n-1}) = (a!/(a-k)! t^{a-k})_a, zero for a < k. Throws
/// miner::Error for a non-finite t or an entry that overflows.
Eigen::RowVectorXd monomial_derivative_row(int n, int k, double t);

/// Q(T) of the control effort in the monomial basis of degree 2s - 1:
/// Q_ab = a!/(a-s)! b!/(b-s)! T^{a+b-2s+1} / (a+b-2s+1) for a, b >= s, else 0. Throws
/// miner::Error for a duration that is negative, not finite, or overflows an entry.
Eigen::MatrixXd monomial_cost_matrix(int order, double duration);

}  // namespace miner::traj
