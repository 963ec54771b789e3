#pragma once
/// \file
/// The paper's optimality condition written out as the dense linear system A c = b
/// (Eq. (coeff), Alg. 2 lines 3-7), A in R^{2Ms x 2Ms}, b in R^{2Ms x 3}:
///   F_0 c_1 = head (s rows: derivatives 0..s-1 at the start),
///   at each interior waypoint i: p_i(T_i) = point_i (1 row) and
///     p_i^{(k)}(T_i) - p_{i+1}^{(k)}(0) = 0, k = 0..2s-2 (2s - 1 rows),
///   E_M c_M = tail (s rows).
/// Used by the baselines (dense pivoted LU) and by tests as an independent check of
/// MINCO (REQ-TRAJ-003).

#include <Eigen/Core>

#include "miner/traj/minco.hpp"

namespace miner::traj {

struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::MatrixX3d b;
};

/// The most segments a dense baseline or optimality_system() takes: their matrices hold
/// (2s M)^2 doubles (500 segments of snap: 128 MB; 5000 asked 12.8 GB and ended in bad_alloc,
/// issue 20, tenth campaign L16b). MINCO itself takes any M in O(M).
inline constexpr int kMaxDenseSegments = 500;
/// validate(problem), then at most kMaxDenseSegments segments; throws miner::Error.
void validate_dense(const MincoProblem& problem);

/// Validates the problem (validate_dense) and writes the system.
LinearSystem optimality_system(const MincoProblem& problem);

/// ||A c - b||_F / (||A||_F ||c||_F + ||b||_F): the normwise relative residual. Throws
/// miner::Error when c's rows are not the system's unknowns.
double relative_residual(const LinearSystem& system, const Eigen::MatrixX3d& c);

}  // namespace miner::traj
