#include "miner/traj/optimality_system.hpp"

#include <cmath>

#include "miner/core/error.hpp"
#include "miner/traj/polynomial_trajectory.hpp"

namespace miner::traj {


void validate_dense(const MincoProblem& p) {
  validate(p);
  if (p.durations.size() > static_cast<std::size_t>(kMaxDenseSegments))
    throw Error("durations: " + std::to_string(p.durations.size()) + " segments, more than the " +
                std::to_string(kMaxDenseSegments) + " a dense solver takes ((2s M)^2 doubles); MINCO takes any number");
}

LinearSystem optimality_system(const MincoProblem& p) {
  validate_dense(p);
  const int s = p.order, n = 2 * s;
  const int M = static_cast<int>(p.durations.size());
  LinearSystem sys{Eigen::MatrixXd::Zero(n * M, n * M), Eigen::MatrixX3d::Zero(n * M, 3)};
  int row = 0;
  for (int k = 0; k < s; ++k, ++row) {
    sys.A.block(row, 0, 1, n) = monomial_derivative_row(n, k, 0.0);
    sys.b.row(row) = p.head.row(k);
  }
  for (int i = 0; i + 1 < M; ++i) {
    const double T = p.durations[i];
    sys.A.block(row, n * i, 1, n) = monomial_derivative_row(n, 0, T);
    sys.b.row(row++) = p.points.row(i + 1);
    for (int k = 0; k <= 2 * s - 2; ++k, ++row) {
      sys.A.block(row, n * i, 1, n) = monomial_derivative_row(n, k, T);
      sys.A.block(row, n * (i + 1), 1, n) = -monomial_derivative_row(n, k, 0.0);
    }
  }
  for (int k = 0; k < s; ++k, ++row) {
    sys.A.block(row, n * (M - 1), 1, n) = monomial_derivative_row(n, k, p.durations[M - 1]);
    sys.b.row(row) = p.tail.row(k);
  }
  return sys;
}

double relative_residual(const LinearSystem& sys, const Eigen::MatrixX3d& c) {
  if (c.rows() != sys.A.cols())
    throw Error("relative_residual: " + std::to_string(c.rows()) + " coefficient rows for a system of " +
                std::to_string(sys.A.cols()) + " unknowns");
  return (sys.A * c - sys.b).norm() / (sys.A.norm() * c.norm() + sys.b.norm());
}

}  // namespace miner::traj
