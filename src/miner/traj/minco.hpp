#pragma once
/// \file
/// MINCO: the minimum-control-effort trajectory of paper Eq. (minco1)-(minco5)
/// (Wang et al. 2022), for s = 3 (minimum jerk) and s = 4 (minimum snap), solved in
/// O(M) time and memory (REQ-TRAJ-002, REQ-TRAJ-003).
///
/// Method. Parametrise segment i by its Hermite data x_i = (p(0), ..., p^{(s-1)}(0),
/// p(T_i), ..., p^{(s-1)}(T_i)). With tau = t / T_i the control effort of a segment is
///   J_i = T_i^{1-2s} x_i^T D(T_i) K D(T_i) x_i,   D(T) = diag(T^k) (k = derivative order),
/// K the constant 2s x 2s Hermite stiffness on [0, 1]. Positions are fixed at every
/// waypoint and the head/tail states are given, so the only unknowns are the
/// derivatives 1..s-1 at the M - 1 interior waypoints. dJ/dz_j = 0 couples z_j only
/// with z_{j-1} and z_{j+1}: a symmetric positive definite block-tridiagonal system with
/// (s-1) x (s-1) blocks, solved by block Cholesky (s = 4) or block Thomas with explicit 2 x 2
/// inverses (s = 3, written out in scalars) in O(M (s-1)^3).
/// Stationarity in z_j is exactly continuity of derivatives s..2s-2 at waypoint j, so
/// the result satisfies the optimality condition of the paper (A c = b) with
/// derivatives 0..2s-2 continuous; the coefficients follow as c_i = diag(T^-j) G D x_i
/// with G the inverse of the unit-interval endpoint matrix.

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "miner/traj/polynomial_trajectory.hpp"

namespace miner::traj {

/// The trajectory problem of `miner traj solve` (../shared/design.md).
struct MincoProblem {
  int order = 3;                 ///< s: 3 minimum jerk, 4 minimum snap
  Eigen::MatrixX3d points;       ///< M + 1 rows: start, M - 1 waypoints, end
  std::vector<double> durations; ///< M positive durations T_i
  Eigen::MatrixX3d head;         ///< s rows: derivatives 0..s-1 at the start
  Eigen::MatrixX3d tail;         ///< s rows: derivatives 0..s-1 at the end
};

/// A problem at rest at both ends: head = (points[0], 0, ...), tail likewise.
MincoProblem rest_to_rest(int order, const Eigen::MatrixX3d& points, std::vector<double> durations);

/// Throws miner::Error naming the field: order not 3 or 4, fewer than 2 points, wrong
/// number of durations, a duration that is not positive and finite, a non-finite
/// value, coinciding consecutive points, head/tail with the wrong number of rows or a
/// head/tail position different from the first/last point.
void validate(const MincoProblem& problem);

/// Gradients of the optimal cost J*(points, durations) (envelope theorem: the
/// interior derivatives are at their optimum).
struct MincoGradients {
  Eigen::MatrixX3d points;  ///< dJ*/dp_j, M + 1 rows (rows 0 and M: the head/tail positions)
  Eigen::VectorXd durations;  ///< dJ*/dT_i
};

/// Reusable solver: keeps its workspace, so repeated solves of the same size do not
/// allocate (what the benchmark times).
class MincoSolver {
 public:
  MincoSolver();
  ~MincoSolver();
  MincoSolver(MincoSolver&&) noexcept;
  MincoSolver& operator=(MincoSolver&&) noexcept;

  /// Solves a validated problem into `out` (resized as needed).
  void solve(const MincoProblem& problem, PolynomialTrajectory& out);
  /// The optimal cost and, if `gradients` is given, its gradients; needs a solve() of
  /// the same problem just before.
  double cost_and_gradients(const MincoProblem& problem, MincoGradients* gradients) const;

 private:
 public:
  struct Workspace;  // fixed-size blocks reused across solves (minco.cpp)

 private:
  std::unique_ptr<Workspace> ws_;
};

/// The a-posteriori check of an answer (REQ-TRAJ-010), in O(M). Residuals of the conditions
/// of A c = b, each for derivative k relative to its segment's own scale
/// S_ik = sum_j |c_ij| j!/(j-k)! T_i^(j-k) (per-segment scaling), split in two:
///  - constraint: head and tail derivatives 0..s-1, both ends of every segment at its
///    waypoints, continuity of derivatives 0..s-1 at interior waypoints (what flight uses);
///  - optimality: continuity of derivatives s..2s-2 (the optimality conditions);
/// and interpolation: an upper bound on the largest distance (max norm) of a segment end from
/// its waypoint in exact arithmetic (the miss by the compensated Horner scheme plus its error
/// bound, ~1e-37 of the terms' size), relative to the problem's position scale
/// L = max(largest |coordinate|, extent of the points): what a user of the waypoints sees.
struct AnswerCheck {
  bool finite = true;
  double constraint = 0.0;
  double optimality = 0.0;
  double interpolation = 0.0;
  int worst_segment = -1;        ///< segment of the largest interpolation error
  double position_scale = 0.0;   ///< L (m)
  double term_scale = 0.0;       ///< largest S_i0 (m): how far the trajectory swings
};
AnswerCheck measure_answer(const MincoProblem& problem, const PolynomialTrajectory& answer);

/// Bounds of check_answer(). kAnswerConstraint: a stable evaluation leaves a few eps of S_ik;
/// 1e-9 keeps a margin for long sums and refuses any wrong answer (those are O(1)).
/// kAnswerOptimality: the jumps of derivatives s..2s-2 carry the solve's own error, which
/// grows with the spread of the durations (docs/traj.md); 1e-6 of S_ik changes the cost by
/// ~1e-12 relative. kAnswerInterpolation: issue 21's "waypoints met to 1e-9 relative".
inline constexpr double kAnswerConstraint = 1e-9;
inline constexpr double kAnswerOptimality = 1e-6;
inline constexpr double kAnswerInterpolation = 1e-9;

/// Throws miner::Error naming the cause when the answer cannot be trusted: a non-finite
/// coefficient, a residual above its bound, or a waypoint missed by more than
/// kAnswerInterpolation x L (the usual cause: a short segment between long ones, so the
/// optimum swings far between waypoints and double precision cannot carry it).
void check_answer(const MincoProblem& problem, const PolynomialTrajectory& answer);

/// Waypoint polish (REQ-TRAJ-010): moves each segment's end onto its waypoint as far as the
/// stored doubles allow. Per segment and axis, the exact miss r = p_{i+1} - q_i(T_i) (compensated
/// Horner) is added to the coefficient c_j that the rounding touches least (smallest
/// |c_j| T_i^j, j >= 1), c_j += r / T_i^j, among those whose change moves every derivative k
/// (1..2s-2) by at most kPolishDamage of the scale check_answer() measures it against; kept
/// only when the miss shrinks (two passes). Why: a solve leaves each end off by ~eps x the
/// terms' size sum_j |c_j| T^j, which for a short segment between long ones is 1e7-1e10 x the
/// waypoints' spacing; the optimum is not representable better than that in general, but its
/// end points are: after the polish the miss is ~eps x the smallest term.
void polish_waypoints(const MincoProblem& problem, PolynomialTrajectory& answer);
/// The polish changes a derivative by at most 1e-12 of its scale: 1000x below
/// kAnswerConstraint, so it never brings a constraint residual near its bound.
inline constexpr double kPolishDamage = 1e-12;

/// validate() + MincoSolver().solve() + polish_waypoints() + check_answer().
PolynomialTrajectory solve_minco(const MincoProblem& problem);

}  // namespace miner::traj
