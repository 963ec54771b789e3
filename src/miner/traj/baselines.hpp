#pragma once
/// \file
/// The back-end baselines of paper Table II, each solving the same MincoProblem into
/// the same monomial coefficients (2s M x 3), for `miner bench backend` and as
/// independent checks of MINCO (REQ-TRAJ-009):
///  - dense LU: the paper's A c = b (optimality_system) by partial-pivot LU, O(M^3);
///  - closed form (Bry et al. 2015, Richter et al. 2016): unconstrained QP in the end
///    derivatives, d_P* = -R_PP^{-1} R_FP^T d_F with R = C^T A^{-T} Q A^{-1} C, using
///    dense inversions as the paper's re-implementation did;
///  - KKT QP (Mellinger & Kumar 2011): min c^T Q c subject to the head/tail states,
///    waypoint positions and continuity of derivatives 0..s-1, solved through its dense
///    KKT system [2Q A^T; A 0] by partial-pivot LU.

#include <Eigen/Core>

#include "miner/traj/minco.hpp"
#include "miner/traj/optimality_system.hpp"

namespace miner::traj {

/// Each validates its problem (validate_dense: tenth campaign L16, a NaN duration gave NaN
/// coefficients, order 7 a 56-row answer).
Eigen::MatrixX3d solve_dense_lu(const MincoProblem& problem);
Eigen::MatrixX3d solve_closed_form(const MincoProblem& problem);
Eigen::MatrixX3d solve_kkt_qp(const MincoProblem& problem);

}  // namespace miner::traj
