#include "miner/traj/baselines.hpp"

#include <cmath>

#include <Eigen/LU>

#include "miner/traj/optimality_system.hpp"
#include "miner/traj/polynomial_trajectory.hpp"

namespace miner::traj {

namespace {

/// Block-diagonal Q of the whole trajectory (dense, as the baselines use it).
Eigen::MatrixXd stacked_cost(const MincoProblem& p) {
  const int n = 2 * p.order, M = static_cast<int>(p.durations.size());
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n * M, n * M);
  for (int i = 0; i < M; ++i) Q.block(n * i, n * i, n, n) = monomial_cost_matrix(p.order, p.durations[i]);
  return Q;
}

}  // namespace

Eigen::MatrixX3d solve_dense_lu(const MincoProblem& p) {
  const LinearSystem sys = optimality_system(p);
  return sys.A.partialPivLu().solve(sys.b);
}

Eigen::MatrixX3d solve_closed_form(const MincoProblem& p) {
  validate_dense(p);
  const int s = p.order, n = 2 * s, M = static_cast<int>(p.durations.size());
  // A maps coefficients to the end derivatives of every segment (block diagonal).
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n * M, n * M);
  for (int i = 0; i < M; ++i)
    for (int k = 0; k < s; ++k) {
      A.block(n * i + k, n * i, 1, n) = monomial_derivative_row(n, k, 0.0);
      A.block(n * i + s + k, n * i, 1, n) = monomial_derivative_row(n, k, p.durations[i]);
    }
  // Unknown vector [d_F; d_P]: d_F = positions of all M+1 waypoints, head and tail
  // derivatives 1..s-1; d_P = derivatives 1..s-1 at the M-1 interior waypoints.
  const int nF = (M + 1) + 2 * (s - 1), nP = (M - 1) * (s - 1);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n * M, nF + nP);  // end derivatives = C [d_F; d_P]
  const auto column = [&](int waypoint, int k) {
    if (k == 0) return waypoint;
    if (waypoint == 0) return M + 1 + (k - 1);
    if (waypoint == M) return M + 1 + (s - 1) + (k - 1);
    return nF + (waypoint - 1) * (s - 1) + (k - 1);
  };
  for (int i = 0; i < M; ++i)
    for (int k = 0; k < s; ++k) {
      C(n * i + k, column(i, k)) = 1.0;
      C(n * i + s + k, column(i + 1, k)) = 1.0;
    }
  Eigen::MatrixX3d dF(nF, 3);
  for (int w = 0; w <= M; ++w) dF.row(w) = p.points.row(w);
  for (int k = 1; k < s; ++k) {
    dF.row(M + 1 + (k - 1)) = p.head.row(k);
    dF.row(M + 1 + (s - 1) + (k - 1)) = p.tail.row(k);
  }
  const Eigen::MatrixXd Ainv = A.inverse();
  const Eigen::MatrixXd AinvC = Ainv * C;
  const Eigen::MatrixXd R = AinvC.transpose() * stacked_cost(p) * AinvC;
  Eigen::MatrixX3d d(nF + nP, 3);
  d.topRows(nF) = dF;
  if (nP > 0) {
    const Eigen::MatrixXd RPPinv = R.bottomRightCorner(nP, nP).inverse();
    d.bottomRows(nP) = -RPPinv * R.topRightCorner(nF, nP).transpose() * dF;
  }
  return AinvC * d;
}

Eigen::MatrixX3d solve_kkt_qp(const MincoProblem& p) {
  validate_dense(p);
  const int s = p.order, n = 2 * s, M = static_cast<int>(p.durations.size());
  const int vars = n * M, rows = s + (M - 1) * (1 + s) + s;
  Eigen::MatrixXd Aeq = Eigen::MatrixXd::Zero(rows, vars);
  Eigen::MatrixX3d beq = Eigen::MatrixX3d::Zero(rows, 3);
  int r = 0;
  for (int k = 0; k < s; ++k, ++r) {
    Aeq.block(r, 0, 1, n) = monomial_derivative_row(n, k, 0.0);
    beq.row(r) = p.head.row(k);
  }
  for (int i = 0; i + 1 < M; ++i) {
    Aeq.block(r, n * i, 1, n) = monomial_derivative_row(n, 0, p.durations[i]);
    beq.row(r++) = p.points.row(i + 1);
    for (int k = 0; k < s; ++k, ++r) {
      Aeq.block(r, n * i, 1, n) = monomial_derivative_row(n, k, p.durations[i]);
      Aeq.block(r, n * (i + 1), 1, n) = -monomial_derivative_row(n, k, 0.0);
    }
  }
  for (int k = 0; k < s; ++k, ++r) {
    Aeq.block(r, n * (M - 1), 1, n) = monomial_derivative_row(n, k, p.durations[M - 1]);
    beq.row(r) = p.tail.row(k);
  }
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(vars + rows, vars + rows);
  K.topLeftCorner(vars, vars) = 2.0 * stacked_cost(p);
  K.topRightCorner(vars, rows) = Aeq.transpose();
  K.bottomLeftCorner(rows, vars) = Aeq;
  Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(vars + rows, 3);
  rhs.bottomRows(rows) = beq;
  return K.partialPivLu().solve(rhs).topRows(vars);
}

}  // namespace miner::traj
