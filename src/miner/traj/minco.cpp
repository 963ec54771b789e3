#include "miner/traj/minco.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/LU>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::traj {

namespace {

/// Constant matrices of the unit interval for order S (computed once).
template <int S>
struct UnitHermite {
  static constexpr int N = 2 * S;
  Eigen::Matrix<double, N, N> K;  ///< stiffness: x^T K x = int_0^1 |q^{(S)}|^2 for Hermite data x
  Eigen::Matrix<double, N, N> G;  ///< monomial coefficients of q = G x on [0, 1]

  UnitHermite() {
    // E maps monomial coefficients a to Hermite data: rows k (at 0) and S + k (at 1).
    Eigen::Matrix<double, N, N> E = Eigen::Matrix<double, N, N>::Zero();
    for (int k = 0; k < S; ++k) {
      for (int j = k; j < N; ++j) {
        double f = 1.0;
        for (int i = 0; i < k; ++i) f *= j - i;
        if (j == k) E(k, j) = f;
        E(S + k, j) = f;
      }
    }
    G = E.fullPivLu().inverse();
    Eigen::Matrix<double, N, N> Qm = Eigen::Matrix<double, N, N>::Zero();
    for (int a = S; a < N; ++a)
      for (int b = S; b < N; ++b) {
        double fa = 1.0, fb = 1.0;
        for (int i = 0; i < S; ++i) {
          fa *= a - i;
          fb *= b - i;
        }
        Qm(a, b) = fa * fb / (a + b - 2 * S + 1);
      }
    K = G.transpose() * Qm * G;
    K = 0.5 * (K + K.transpose()).eval();
  }
  static const UnitHermite& get() {
    static const UnitHermite h;
    return h;
  }
};

template <int S>
using SegmentMatrix = Eigen::Matrix<double, 2 * S, 2 * S>;

/// d_r = T^{k(r)} (k(r) = r mod S) and the factor T^{1-2S} of Q(T) = T^{1-2S} (d d^T) o K.
template <int S>
double cost_scaling(double T, Eigen::Matrix<double, 2 * S, 1>& d) {
  d[0] = d[S] = 1.0;
  for (int k = 1; k < S; ++k) d[k] = d[S + k] = d[k - 1] * T;
  const double inv = 1.0 / T;
  double scale = inv;  // T^{1-2S}
  for (int k = 1; k < 2 * S - 1; ++k) scale *= inv;
  return scale;
}

/// Q(T)_{ab} = K_ab T^{1 - 2S + k(a) + k(b)}, k(r) = r mod S (derivative order of row r),
/// i.e. Q = T^{1-2S} (d d^T) o K with d_r = T^{k(r)}.
template <int S>
void segment_cost_matrix(double T, SegmentMatrix<S>& Q) {
  const auto& K = UnitHermite<S>::get().K;
  Eigen::Matrix<double, 2 * S, 1> d;
  const double scale = cost_scaling<S>(T, d);
  Q.noalias() = (scale * d * d.transpose()).cwiseProduct(K);
}

/// The columns of Q(T) the reduced system reads: those of the free derivatives 1..S-1 at
/// either end (rows 0 and S, the positions, are read through the symmetry Q_ab = Q_ba, exact
/// since d_0 = d_S = 1); each entry rounded as segment_cost_matrix rounds it.
template <int S>
void segment_cost_columns(double T, SegmentMatrix<S>& Q) {
  const auto& K = UnitHermite<S>::get().K;
  Eigen::Matrix<double, 2 * S, 1> d;
  const Eigen::Matrix<double, 2 * S, 1> sd = cost_scaling<S>(T, d) * d;
  for (int k = 1; k < S; ++k) {
    Q.col(k) = (sd * d[k]).cwiseProduct(K.col(k));
    Q.col(S + k) = (sd * d[S + k]).cwiseProduct(K.col(S + k));
  }
}

/// dQ/dT: exponent times Q / T.
template <int S>
void segment_cost_matrix_derivative(double T, SegmentMatrix<S>& dQ) {
  segment_cost_matrix<S>(T, dQ);
  for (int a = 0; a < 2 * S; ++a)
    for (int b = 0; b < 2 * S; ++b) dQ(a, b) *= (1.0 - 2 * S + a % S + b % S) / T;
}

/// Cholesky factor L (lower, diagonal stored as 1 / L_jj) of a small SPD matrix, written out: for (s-1) x (s-1)
/// blocks Eigen's general triangular kernels (packing, blocking) cost more than the math.
template <int F>
Eigen::Matrix<double, F, F> small_cholesky(const Eigen::Matrix<double, F, F>& A) {
  Eigen::Matrix<double, F, F> L = Eigen::Matrix<double, F, F>::Zero();
  for (int j = 0; j < F; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    const double inv = 1.0 / std::sqrt(d);
    L(j, j) = inv;  // stored inverted: the solves multiply instead of divide
    for (int i = j + 1; i < F; ++i) {
      double v = A(i, j);
      for (int k = 0; k < j; ++k) v -= L(i, k) * L(j, k);
      L(i, j) = v * inv;
    }
  }
  return L;
}

/// X <- L^{-1} X (forward substitution; L's diagonal stored inverted).
template <int F, int C>
void forward_solve(const Eigen::Matrix<double, F, F>& L, Eigen::Matrix<double, F, C>& X) {
  for (int i = 0; i < F; ++i) {
    for (int k = 0; k < i; ++k) X.row(i) -= L(i, k) * X.row(k);
    X.row(i) *= L(i, i);
  }
}

/// X <- L^{-T} X (back substitution).
template <int F, int C>
void back_solve(const Eigen::Matrix<double, F, F>& L, Eigen::Matrix<double, F, C>& X) {
  for (int i = F - 1; i >= 0; --i) {
    for (int k = i + 1; k < F; ++k) X.row(i) -= L(k, i) * X.row(k);
    X.row(i) *= L(i, i);
  }
}

/// Storage of one order, every block at its true size.
template <int S>
struct OrderWorkspace {
  static constexpr int F = S - 1;
  std::vector<Eigen::Matrix<double, F, F>> L;  // Cholesky factors of the Schur complements
  std::vector<Eigen::Matrix<double, F, F>> Y;  // L_{j-1}^{-1} B_j^T: the block L_{j,j-1} = Y_j^T of the factor
  std::vector<Eigen::Matrix<double, F, 3>> r;  // forward-substituted right-hand sides u_j
  std::vector<Eigen::Matrix<double, F, 3>> z;  // derivatives 1..S-1 per waypoint (rows) per axis, normalised time
  double tau = 1.0;  // the time unit z is in (the mean duration of the last solve)
  int solved = 0;    // segments of the last solve (cost_and_gradients reads its z)
};

}  // namespace

struct MincoSolver::Workspace {
  OrderWorkspace<3> jerk;
  OrderWorkspace<4> snap;
  /// The problem the last solve() solved (copies reuse their storage): cost_and_gradients
  /// answers only for it (thirteenth campaign L4: another problem of the same size got the
  /// solved one's cost, 16 910 for a true 272.5).
  MincoProblem last;
  template <int S>
  OrderWorkspace<S>& get() {
    if constexpr (S == 3) return jerk; else return snap;
  }
};

MincoSolver::MincoSolver() : ws_(std::make_unique<Workspace>()) {}
MincoSolver::~MincoSolver() = default;
MincoSolver::MincoSolver(MincoSolver&&) noexcept = default;
MincoSolver& MincoSolver::operator=(MincoSolver&&) noexcept = default;

namespace {

/// The reduced system of the interior derivatives, unknowns z_j for j = 1..M-1:
///   B_j z_{j-1} + A_j z_j + B_{j+1}^T z_{j+1} = r_j  (block tridiagonal SPD),
/// by block Cholesky: the factor has diagonal blocks L_j (Cholesky of the Schur complement
/// S_j = A_j - Y_j^T Y_j) and sub-diagonal blocks Y_j^T with Y_j = L_{j-1}^{-1} B_j^T. The
/// forward sweep u_j = L_j^{-1} (r_j - Y_j^T u_{j-1}) runs in solve_order() as each block is
/// assembled (forward_step); the back sweep z_j = L_j^{-T} (u_j - Y_{j+1} z_{j+1}) here.
template <int S>
void forward_step(OrderWorkspace<S>& w, int j, Eigen::Matrix<double, S - 1, S - 1> Sj,
                  const Eigen::Matrix<double, S - 1, S - 1>& Bj, Eigen::Matrix<double, S - 1, 3> r) {
  constexpr int F = S - 1;
  if (j > 1) {
    Eigen::Matrix<double, F, F>& Y = w.Y[j];
    Y = Bj.transpose();
    forward_solve<F, F>(w.L[j - 1], Y);
    Sj.noalias() -= Y.transpose() * Y;
    r.noalias() -= Y.transpose() * w.r[j - 1];
  }
  w.L[j] = small_cholesky<F>(Sj);
  forward_solve<F, 3>(w.L[j], r);
  w.r[j] = r;
}

template <int S>
void back_sweep(OrderWorkspace<S>& w, int M) {
  constexpr int F = S - 1;
  for (int j = M - 1; j >= 1; --j) {
    Eigen::Matrix<double, F, 3> v = w.r[j];
    if (j < M - 1) v.noalias() -= w.Y[j + 1] * w.z[j + 1];
    back_solve<F, 3>(w.L[j], v);
    w.z[j] = v;
  }
}

/// The Hermite data of segment i (derivatives 0..S-1 at both ends) from the junction
/// derivatives z of the last solve (normalised time), the k-th derivative times f^k: f = 1/tau
/// gives real time, f = T_i/tau the unit interval. Forced inline: left to GCC it was called
/// out of solve_order's conversion loop, +6 % instructions per solve (callgrind, M = 15).
template <int S>
[[gnu::always_inline]] inline void hermite_data(const MincoProblem& p, const OrderWorkspace<S>& ws, int i, double f,
                                               Eigen::Matrix<double, 2 * S, 3>& x) {
  x.row(0) = p.points.row(i);
  x.row(S) = p.points.row(i + 1);
  double fk = 1.0;
  for (int k = 1; k < S; ++k) {
    fk *= f;
    x.row(k) = ws.z[static_cast<std::size_t>(i)].row(k - 1) * fk;
    x.row(S + k) = ws.z[static_cast<std::size_t>(i) + 1].row(k - 1) * fk;
  }
}

template <int S>
void solve_order(const MincoProblem& p, OrderWorkspace<S>& ws, PolynomialTrajectory& out) {
  constexpr int F = S - 1;  // free derivatives per waypoint
  constexpr int N = 2 * S;
  const int M = static_cast<int>(p.durations.size());
  ws.L.resize(M + 1);
  ws.Y.resize(M + 1);
  ws.r.resize(M + 1);
  ws.z.resize(M + 1);

  // Work in normalised time t / tau with tau the mean duration: by the time-scaling
  // law the optimum is the same curve, and the blocks no longer carry factors
  // T^{1-2s} (1e21 for s = 4, T = 1e-3).
  double tau = 0.0;
  for (double T : p.durations) tau += T;
  tau /= M;
  const double inv_tau = 1.0 / tau;
  double tau_pow[S], taylor[S];  // tau^k, 1 / (k! tau^k)
  tau_pow[0] = taylor[0] = 1.0;
  for (int k = 1; k < S; ++k) {
    tau_pow[k] = tau_pow[k - 1] * tau;
    taylor[k] = taylor[k - 1] * inv_tau / k;
  }
  // Known derivatives at the ends, in normalised time: d^k/ds^k = tau^k d^k/dt^k.
  for (int k = 1; k < S; ++k) {
    ws.z[0].row(k - 1) = p.head.row(k) * tau_pow[k];
    ws.z[M].row(k - 1) = p.tail.row(k) * tau_pow[k];
  }

  // Equation of interior waypoint j (segment j-1 ends and segment j starts there):
  //   dJ/dz_j = 0  <=>  B_j z_{j-1} + A_j z_j + B_{j+1}^T z_{j+1} = r_j.
  // Q of the two segments is computed once each, rolling along the path (two buffers that
  // swap roles: the segment starting at waypoint j becomes the one ending at j + 1).
  SegmentMatrix<S> Q0, Q1;
  SegmentMatrix<S>* pa = &Q0;
  SegmentMatrix<S>* pb = &Q1;
  segment_cost_columns<S>(p.durations[0] * inv_tau, Q0);
  for (int j = 1; j < M; ++j) {
    segment_cost_columns<S>(p.durations[static_cast<std::size_t>(j)] * inv_tau, *pb);
    const SegmentMatrix<S>& Qa = *pa;
    const SegmentMatrix<S>& Qb = *pb;
    const Eigen::Matrix<double, F, F> A = Qa.template block<F, F>(S + 1, S + 1) + Qb.template block<F, F>(1, 1);
    const Eigen::Matrix<double, F, F> B = Qa.template block<F, F>(S + 1, 1);
    Eigen::Matrix<double, F, 3> r =
        -(Qa.template block<1, F>(0, S + 1).transpose() * p.points.row(j - 1) +
          (Qa.template block<1, F>(S, S + 1).transpose() + Qb.template block<1, F>(0, 1).transpose()) * p.points.row(j) +
          Qb.template block<1, F>(S, 1).transpose() * p.points.row(j + 1));
    if (j == 1) r.noalias() -= B * ws.z[0];
    if (j == M - 1) r.noalias() -= Qb.template block<F, F>(1, S + 1) * ws.z[M];
    forward_step<S>(ws, j, A, B, r);
    std::swap(pa, pb);
  }
  back_sweep<S>(ws, M);
  ws.tau = tau;
  ws.solved = M;

  // Coefficients c_i(j, :) = sum_r G(j, r) T^{k(r) - j} x_i(r, :).
  const auto& G = UnitHermite<S>::get().G;
  Eigen::MatrixX3d& c = out.mutable_coefficients();
  c.resize(N * M, 3);
  out.mutable_durations() = p.durations;
  for (int i = 0; i < M; ++i) {
    const double inv_T = 1.0 / p.durations[static_cast<std::size_t>(i)];
    double inv_tp = 1.0;
    for (int j = 1; j < S; ++j) inv_tp *= inv_T;  // T^-(S-1)
    // Hermite data on the unit interval: d^k/du^k = Tn^k d^k/ds^k, Tn = T_i / tau.
    Eigen::Matrix<double, N, 3> unit;
    hermite_data<S>(p, ws, i, p.durations[static_cast<std::size_t>(i)] / tau, unit);
    // Rows j < S of G are the Taylor terms q^{(j)}(0) / j!; only rows S..2S-1 mix the ends.
    auto ci = c.template middleRows<N>(N * i);
    ci.row(0) = p.points.row(i);
    for (int j = 1; j < S; ++j) ci.row(j) = ws.z[static_cast<std::size_t>(i)].row(j - 1) * taylor[j];
    ci.template bottomRows<S>().noalias() = G.template bottomRows<S>() * unit;
    for (int j = S; j < N; ++j) ci.row(j) *= (inv_tp *= inv_T);
  }
}

/// Minimum jerk (s = 3) written out in scalars (issue 21: 2.5x fewer ns per solve than
/// solve_order<3>, whose Eigen blocks of 2 x 2 and 2 x 3 cost more than their arithmetic): the
/// same reduced system as solve_order<3>, with
/// the exact unit-interval constants (K and G of UnitHermite<3> are small integers and halves)
/// and the structure they give:
///  - Q(t) of a segment (t = T / tau, u = 1 / t) needs only u..u^4 times constants: the entries
///    the system reads are 192 u^3, 36 u^2, 9 u (derivatives at one end), 168 u^3, 24 u^2, 3 u
///    (coupling of the two ends) and 360 u^4, 60 u^3 (positions);
///  - row 3 of K is minus row 0 (a translation costs nothing), so the right-hand side needs only
///    the segment vectors d = p_{i+1} - p_i;
///  - the 2 x 2 blocks are solved by block Thomas with explicit inverses of the symmetric Schur
///    complements, H_j = S_{j-1}^{-1} B_j^T, S_j = A_j - B_j H_j, y_j = S_j^{-1} (r_j - B_j y_{j-1}),
///    z_j = y_j - H_{j+1} z_{j+1}: one division per waypoint and no square roots;
///  - the high coefficients c_3..c_5 are the rows of G times the Hermite data with the powers
///    of T and tau folded into the weights, computed two at a time: (c_2, c_3) and (c_4, c_5).
/// Against a long double solve, its coefficients are as accurate as solve_order<3>'s or better
/// (durations spread up to 1e4). The Cholesky factors ws.L are not used.
/// ws.Y[j] holds H_j, ws.r[j] holds y_j; ws.z as in solve_order (cost_and_gradients reads it).
void solve_jerk(const MincoProblem& p, OrderWorkspace<3>& ws, PolynomialTrajectory& out) {
  const int M = static_cast<int>(p.durations.size());
  ws.Y.resize(M + 1);
  ws.r.resize(M + 1);
  ws.z.resize(M + 1);
  const double* T = p.durations.data();
  double tau = 0.0;
  for (int i = 0; i < M; ++i) tau += T[i];
  tau /= M;
  const double inv_tau = 1.0 / tau;
  ws.z[0].row(0) = p.head.row(1) * tau;
  ws.z[0].row(1) = p.head.row(2) * (tau * tau);
  ws.z[M].row(0) = p.tail.row(1) * tau;
  ws.z[M].row(1) = p.tail.row(2) * (tau * tau);

  const Eigen::Index np = p.points.rows();
  const double* P = p.points.data();  // P[ax * np + i]
  // Segment a (ends at waypoint j) rolls into segment b (starts at j).
  double ua = 1.0 / (T[0] * inv_tau);
  double ua2 = ua * ua, ua3 = ua2 * ua, ua4 = ua3 * ua;
  double da[3] = {P[1] - P[0], P[np + 1] - P[np], P[2 * np + 1] - P[2 * np]};
  double s00 = 0.0, s01 = 0.0, s11 = 0.0;  // S_{j-1}^{-1} (symmetric)
  for (int j = 1; j < M; ++j) {
    const double ub = 1.0 / (T[j] * inv_tau);
    const double ub2 = ub * ub, ub3 = ub2 * ub, ub4 = ub3 * ub;
    double db[3];
    for (int ax = 0; ax < 3; ++ax) db[ax] = P[ax * np + j + 1] - P[ax * np + j];
    // A_j = Q_a(4:5, 4:5) + Q_b(1:2, 1:2); B_j = Q_a(4:5, 1:2); r_j = Q_a(0, 4:5) d_a + Q_b(0, 1:2) d_b.
    double a00 = 192.0 * (ua3 + ub3), a01 = 36.0 * (ub2 - ua2), a11 = 9.0 * (ua + ub);
    const double b00 = 168.0 * ua3, b01 = 24.0 * ua2, b10 = -24.0 * ua2, b11 = -3.0 * ua;
    const double qa0 = 360.0 * ua4, qa1 = -60.0 * ua3, qb0 = 360.0 * ub4, qb1 = 60.0 * ub3;
    Eigen::Matrix<double, 2, 3>& y = ws.r[j];
    for (int ax = 0; ax < 3; ++ax) {
      y(0, ax) = qa0 * da[ax] + qb0 * db[ax];
      y(1, ax) = qa1 * da[ax] + qb1 * db[ax];
    }
    if (j == 1) {
      const auto& z0 = ws.z[0];
      for (int ax = 0; ax < 3; ++ax) {
        y(0, ax) -= b00 * z0(0, ax) + b01 * z0(1, ax);
        y(1, ax) -= b10 * z0(0, ax) + b11 * z0(1, ax);
      }
    } else {
      // H = S_{j-1}^{-1} B^T, S_j = A - B H, r -= B y_{j-1}.
      Eigen::Matrix2d& H = ws.Y[j];
      H(0, 0) = s00 * b00 + s01 * b01;
      H(0, 1) = s00 * b10 + s01 * b11;
      H(1, 0) = s01 * b00 + s11 * b01;
      H(1, 1) = s01 * b10 + s11 * b11;
      a00 -= b00 * H(0, 0) + b01 * H(1, 0);
      a01 -= b00 * H(0, 1) + b01 * H(1, 1);
      a11 -= b10 * H(0, 1) + b11 * H(1, 1);
      const auto& yp = ws.r[j - 1];
      for (int ax = 0; ax < 3; ++ax) {
        y(0, ax) -= b00 * yp(0, ax) + b01 * yp(1, ax);
        y(1, ax) -= b10 * yp(0, ax) + b11 * yp(1, ax);
      }
    }
    if (j == M - 1) {  // Q_b(1:2, 4:5) z_M, the tail
      const auto& zM = ws.z[M];
      const double c00 = 168.0 * ub3, c01 = -24.0 * ub2, c10 = 24.0 * ub2, c11 = -3.0 * ub;
      for (int ax = 0; ax < 3; ++ax) {
        y(0, ax) -= c00 * zM(0, ax) + c01 * zM(1, ax);
        y(1, ax) -= c10 * zM(0, ax) + c11 * zM(1, ax);
      }
    }
    const double inv_det = 1.0 / (a00 * a11 - a01 * a01);
    s00 = a11 * inv_det;
    s01 = -a01 * inv_det;
    s11 = a00 * inv_det;
    for (int ax = 0; ax < 3; ++ax) {
      const double g0 = y(0, ax), g1 = y(1, ax);
      y(0, ax) = s00 * g0 + s01 * g1;
      y(1, ax) = s01 * g0 + s11 * g1;
    }
    ua = ub;
    ua2 = ub2;
    ua3 = ub3;
    ua4 = ub4;
    for (int ax = 0; ax < 3; ++ax) da[ax] = db[ax];
  }
  if (M > 1) ws.z[M - 1] = ws.r[M - 1];
  for (int j = M - 2; j >= 1; --j) {
    const Eigen::Matrix2d& H = ws.Y[j + 1];
    const auto& zn = ws.z[j + 1];
    auto& z = ws.z[j];
    const auto& y = ws.r[j];
    for (int ax = 0; ax < 3; ++ax) {
      z(0, ax) = y(0, ax) - (H(0, 0) * zn(0, ax) + H(0, 1) * zn(1, ax));
      z(1, ax) = y(1, ax) - (H(1, 0) * zn(0, ax) + H(1, 1) * zn(1, ax));
    }
  }
  ws.tau = tau;
  ws.solved = M;

  // c_0 = p_i, c_1 = v_0, c_2 = a_0 / 2 (real time); c_3..c_5 = rows 3..5 of G times the unit
  // Hermite data, divided by T^3..T^5:
  //   c_3 = (10 d - 6 v0 - 4 v1 - 1.5 a0 + 0.5 a1) / T^3,
  //   c_4 = (-15 d + 8 v0 + 7 v1 + 1.5 a0 - a1) / T^4,
  //   c_5 = (6 d - 3 v0 - 3 v1 - 0.5 a0 + 0.5 a1) / T^5,
  // with v, a the unit-interval derivatives (normalised z times (T / tau)^k).
  Eigen::MatrixX3d& c = out.mutable_coefficients();
  c.resize(6 * M, 3);
  out.mutable_durations() = p.durations;
  const Eigen::Index nc = 6 * M;
  double* C = c.data();
  const double t1 = inv_tau, t2 = 0.5 * inv_tau * inv_tau;
  using Pair = Eigen::Array2d;  // (c_2, c_3) and (c_4, c_5): one SSE2 register each
  for (int i = 0; i < M; ++i) {
    const double e = 1.0 / T[i];
    const double e2 = e * e;
    const double w = e2 * e, wv = e2 * inv_tau, wa = e * t2;  // wa: halved
    const double ew = e * w, ewv = e * wv, ewa = e * wa;
    const double e2w = e2 * w, e2wv = e2 * wv, e2wa = e2 * wa;
    // (c_2, c_3) and (c_4, c_5) = kd d + kv0 v0 + kv1 v1 + ka0 a0 + ka1 a1 (normalised v, a).
    const Pair k23d(0.0, 10.0 * w), k23v0(0.0, -6.0 * wv), k23v1(0.0, -4.0 * wv), k23a0(t2, -3.0 * wa), k23a1(0.0, wa);
    const Pair k45d(-15.0 * ew, 6.0 * e2w), k45v0(8.0 * ewv, -3.0 * e2wv), k45v1(7.0 * ewv, -3.0 * e2wv),
        k45a0(3.0 * ewa, -e2wa), k45a1(-2.0 * ewa, e2wa);
    const auto& z0 = ws.z[i];
    const auto& z1 = ws.z[i + 1];
    for (int ax = 0; ax < 3; ++ax) {
      const double d = P[ax * np + i + 1] - P[ax * np + i];
      const double v0 = z0(0, ax), a0 = z0(1, ax), v1 = z1(0, ax), a1 = z1(1, ax);
      double* ci = C + ax * nc + 6 * i;
      ci[0] = P[ax * np + i];
      ci[1] = v0 * t1;
      Eigen::Map<Pair>(ci + 2) = k23d * d + k23v0 * v0 + k23v1 * v1 + k23a0 * a0 + k23a1 * a1;
      Eigen::Map<Pair>(ci + 4) = k45d * d + k45v0 * v0 + k45v1 * v1 + k45a0 * a0 + k45a1 * a1;
    }
  }
}

template <int S>
double cost_order(const MincoProblem& p, const OrderWorkspace<S>& ws, MincoGradients* g) {
  constexpr int N = 2 * S;
  const int M = static_cast<int>(p.durations.size());
  double J = 0.0;
  if (g) {
    g->points = Eigen::MatrixX3d::Zero(M + 1, 3);
    g->durations = Eigen::VectorXd::Zero(M);
  }
  for (int i = 0; i < M; ++i) {
    SegmentMatrix<S> Q;
    segment_cost_matrix<S>(p.durations[i], Q);
    Eigen::Matrix<double, N, 3> x;
    hermite_data<S>(p, ws, i, 1.0 / ws.tau, x);  // real time
    const Eigen::Matrix<double, N, 3> Qx = Q * x;
    J += (x.transpose() * Qx).trace();
    if (g) {
      SegmentMatrix<S> dQ;
      segment_cost_matrix_derivative<S>(p.durations[i], dQ);
      g->durations[i] = (x.transpose() * dQ * x).trace();
      g->points.row(i) += 2.0 * Qx.row(0);
      g->points.row(i + 1) += 2.0 * Qx.row(S);
    }
  }
  return J;
}

std::string row_text(const Eigen::MatrixX3d& m, Eigen::Index r) {
  return format_point(Eigen::Vector3d(m.row(r).transpose()));
}

}  // namespace

void MincoSolver::solve(const MincoProblem& p, PolynomialTrajectory& out) {
  if (!ws_) throw Error("MincoSolver: used after being moved from");  // tenth campaign L21
  out.set_order(p.order);
  if (p.order == 3) {
    solve_jerk(p, ws_->jerk, out);
  } else if (p.order == 4) {
    solve_order<4>(p, ws_->snap, out);
  } else {
    throw Error("order: must be 3 (minimum jerk) or 4 (minimum snap), got " + std::to_string(p.order));
  }
  ws_->last.order = p.order;
  ws_->last.points = p.points;
  ws_->last.durations = p.durations;
  ws_->last.head = p.head;
  ws_->last.tail = p.tail;
}

double MincoSolver::cost_and_gradients(const MincoProblem& p, MincoGradients* gradients) const {
  if (!ws_) throw Error("MincoSolver: used after being moved from");
  const int solved = p.order == 3 ? ws_->jerk.solved : ws_->snap.solved;
  if (solved != static_cast<int>(p.durations.size())) throw Error("MincoSolver: cost_and_gradients needs a solve() first");
  const MincoProblem& last = ws_->last;
  const auto same = [](const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) { return a.rows() == b.rows() && a == b; };
  if (last.order != p.order || last.durations != p.durations || !same(last.points, p.points) || !same(last.head, p.head) ||
      !same(last.tail, p.tail))
    throw Error("MincoSolver: cost_and_gradients is for the problem the last solve() solved, and this is another");
  return p.order == 3 ? cost_order<3>(p, ws_->jerk, gradients) : cost_order<4>(p, ws_->snap, gradients);
}

MincoProblem rest_to_rest(int order, const Eigen::MatrixX3d& points, std::vector<double> durations) {
  MincoProblem p;
  p.order = order;
  p.points = points;
  p.durations = std::move(durations);
  const int s = order > 0 ? order : 1;
  p.head = Eigen::MatrixX3d::Zero(s, 3);
  p.tail = Eigen::MatrixX3d::Zero(s, 3);
  if (points.rows() > 0) {
    p.head.row(0) = points.row(0);
    p.tail.row(0) = points.row(points.rows() - 1);
  }
  return p;
}

void validate(const MincoProblem& p) {
  if (p.order != 3 && p.order != 4) {
    throw Error("order: must be 3 (minimum jerk) or 4 (minimum snap), got " + std::to_string(p.order));
  }
  const Eigen::Index n = p.points.rows();
  if (n < 2) throw Error("points: need at least 2 points (start and end), got " + std::to_string(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    require_finite(Eigen::Vector3d(p.points.row(i).transpose()), "points[" + std::to_string(i) + "]");
  }
  for (Eigen::Index i = 1; i < n; ++i) {
    if (p.points.row(i) == p.points.row(i - 1)) {
      throw Error("points[" + std::to_string(i - 1) + "] and points[" + std::to_string(i) +
                  "] coincide at " + row_text(p.points, i) +
                  ": remove the duplicate waypoint (a segment needs two distinct ends)");
    }
  }
  const auto M = static_cast<std::size_t>(n - 1);
  if (p.durations.size() != M) {
    throw Error("durations: expected " + std::to_string(M) + " values (one per segment), got " +
                std::to_string(p.durations.size()));
  }
  for (std::size_t i = 0; i < M; ++i) {
    if (!std::isfinite(p.durations[i]) || !(p.durations[i] > 0.0)) {
      std::ostringstream os;
      os << "durations[" << i << "]: must be positive and finite, got " << exact_number(p.durations[i]);
      throw Error(os.str());
    }
  }
  for (const auto& [m, name] : {std::pair<const Eigen::MatrixX3d*, const char*>{&p.head, "head"}, {&p.tail, "tail"}}) {
    if (m->rows() != p.order) {
      throw Error(std::string(name) + ": expected " + std::to_string(p.order) +
                  " rows (derivatives 0.." + std::to_string(p.order - 1) + " for order " +
                  std::to_string(p.order) + "), got " + std::to_string(m->rows()));
    }
    for (Eigen::Index r = 0; r < m->rows(); ++r) {
      require_finite(Eigen::Vector3d(m->row(r).transpose()), std::string(name) + "[" + std::to_string(r) + "]");
    }
  }
  // The head/tail positions are the first/last point; a mismatch is a contradiction.
  constexpr double kSamePoint = 1e-9;  // m: JSON round-off only
  if ((p.head.row(0) - p.points.row(0)).norm() > kSamePoint) {
    throw Error("head[0]: must equal points[0] " + row_text(p.points, 0) + ", got " + row_text(p.head, 0));
  }
  if ((p.tail.row(0) - p.points.row(n - 1)).norm() > kSamePoint) {
    throw Error("tail[0]: must equal the last point " + row_text(p.points, n - 1) + ", got " + row_text(p.tail, 0));
  }
}

namespace {

std::string sci(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

// Error-free transformations in long double (Knuth's TwoSum; Dekker's TwoProduct with
// Veltkamp's split, 2^32 + 1 for the 64-bit significand): a + b = sum + err and
// a b = product + err exactly, barring overflow.
using ld = long double;
void two_sum(ld a, ld b, ld& sum, ld& err) {
  sum = a + b;
  const ld z = sum - a;
  err = (a - (sum - z)) + (b - z);
}
void split(ld a, ld& hi, ld& lo) {
  const ld c = 4294967297.0L * a;  // 2^32 + 1
  hi = c - (c - a);
  lo = a - hi;
}
void two_product(ld a, ld b, ld& product, ld& err) {
  product = a * b;
  ld ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  err = ((ah * bh - product) + ah * bl + al * bh) + al * bl;
}

/// q(T) - target for q = sum_j c_j T^j (one axis of one segment's coefficients), by the
/// compensated Horner scheme (Graillat, Langlois, Louvet, "Compensated Horner scheme", 2005):
/// as accurate as Horner's rule in twice long double's precision,
///   |value - exact| <= u |exact| + gamma_2n^2 sum_j |c_j| T^j,  gamma_k = k u / (1 - k u),
/// u = 2^-64, n the degree. `bound` returns that right-hand side (with |value| for |exact|,
/// doubled for the rounding of the bound itself): an upper bound on the exact difference is
/// |value| + bound. Used where the miss must be known far below double's rounding of the
/// terms: an optimum that swings 1e10 L between waypoints still meets them to ~1e-30 L.
struct Compensated {
  ld value;
  ld bound;
};
template <class Column>
Compensated compensated_miss(const Column& c, int N, double T, double target) {
  const ld t = T;
  ld s = c(N - 1), corr = 0.0L, terms = std::abs(static_cast<ld>(c(N - 1)));
  for (int j = N - 2; j >= 0; --j) {
    ld p, pi, sigma;
    two_product(s, t, p, pi);
    ld a = c(j), a_err = 0.0L;
    if (j == 0) two_sum(a, -static_cast<ld>(target), a, a_err);  // c_0 - target, exactly as a + a_err
    two_sum(p, a, s, sigma);
    corr = corr * t + (pi + sigma + a_err);
    terms = terms * t + std::abs(static_cast<ld>(c(j)));
  }
  terms += std::abs(static_cast<ld>(target));
  const ld u = std::numeric_limits<ld>::epsilon() / 2.0L;
  const ld gamma = 2.0L * (N - 1) * u / (1.0L - 2.0L * (N - 1) * u);
  const ld value = s + corr;
  return {value, 2.0L * (u * std::abs(value) + gamma * gamma * terms)};
}

}  // namespace

void polish_waypoints(const MincoProblem& p, PolynomialTrajectory& tr) {
  constexpr int kMaxN = 8;  // s <= 4 (validate())
  const int s = p.order, N = 2 * s, M = tr.segments();
  if (N > kMaxN || M != static_cast<int>(p.durations.size()) || tr.coefficients().rows() != N * M || !tr.coefficients().allFinite())
    return;  // nothing to polish; check_answer names the fault
  Eigen::MatrixX3d& C = tr.mutable_coefficients();
  for (int i = 0; i < M; ++i) {
    const double T = p.durations[static_cast<std::size_t>(i)];
    ld tp[kMaxN];  // T^j
    tp[0] = 1.0L;
    for (int j = 1; j < N; ++j) tp[j] = tp[j - 1] * T;
    for (int ax = 0; ax < 3; ++ax) {
      auto c = C.col(ax).segment(N * i, N);
      const double target = p.points(i + 1, ax);
      for (int pass = 0; pass < 2; ++pass) {
        const Compensated miss = compensated_miss(c, N, T, target);
        if (miss.value == 0.0L) break;
        // T^k S_ik of check_answer (the scale each continuity residual is measured against,
        // with the solve's rounding floor S_i0), and |c_j| T^j.
        ld term[kMaxN], scaled[kMaxN];
        for (int j = 0; j < N; ++j) term[j] = std::abs(static_cast<ld>(c(j))) * tp[j];
        for (int k = 0; k < N; ++k) {
          ld sum = 0.0L;
          for (int j = k; j < N; ++j) sum += term[j] * falling_factorial(j, k);
          scaled[k] = k == 0 ? sum : std::max(sum, scaled[0]);
        }
        const ld r = -miss.value;
        int best = -1;
        for (int j = 1; j < N; ++j) {
          ld damage = 0.0L;
          for (int k = 1; k <= std::min(j, 2 * s - 2); ++k)
            damage = std::max(damage, std::abs(r) * falling_factorial(j, k) / scaled[k]);
          if (damage <= kPolishDamage && (best < 0 || term[j] < term[best])) best = j;
        }
        if (best < 0) break;
        const ld moved = static_cast<ld>(c(best)) + r / tp[best];
        if (!std::isfinite(moved) || std::abs(moved) > std::numeric_limits<double>::max()) break;  // T^j underflowed
        const double before = c(best);
        c(best) = static_cast<double>(moved);
        if (std::abs(compensated_miss(c, N, T, target).value) >= std::abs(miss.value)) {
          c(best) = before;  // no gain: keep the solve's coefficient
          break;
        }
      }
    }
  }
}

AnswerCheck measure_answer(const MincoProblem& p, const PolynomialTrajectory& tr) {
  AnswerCheck out;
  const int s = p.order, M = static_cast<int>(p.durations.size());
  out.position_scale = std::max(p.points.cwiseAbs().maxCoeff(),
                                (p.points.colwise().maxCoeff() - p.points.colwise().minCoeff()).maxCoeff());
  if (!tr.coefficients().allFinite() || tr.segments() != M || tr.coefficients().rows() != 2 * s * M) {
    out.finite = false;
    return out;
  }
  // Per segment and derivative k, the size of the terms it is computed from,
  // S_ik = max(sum_j |c_ij| j!/(j-k)! T_i^(j-k), S_i0 / T_i^k) (largest axis): its rounding
  // error is relative to that (per-segment scaling: a residual at a junction of a 1e-6 s and a
  // 1 s segment is measured against each side's own scale, not against the other's). The
  // second term is the scale the solve's rounding gives every coefficient (c_j carries
  // ~eps S_i0 / T_i^j): a derivative that vanishes, such as the acceleration of a
  // constant-velocity segment between collinear waypoints, is rounding noise whose size is
  // set by the positions, not by its own (zero) terms (issue 20: such straight lines were
  // refused with residuals of ~1 "relative").
  const int N = 2 * s;
  std::vector<double> S(static_cast<std::size_t>(M * N), 0.0);
  for (int i = 0; i < M; ++i) {
    const double T = p.durations[static_cast<std::size_t>(i)];
    const auto c = tr.segment_coefficients(i);
    for (int k = 0; k < N; ++k) {
      Eigen::Array3d sum = Eigen::Array3d::Zero();
      double tp = 1.0;
      for (int j = k; j < N; ++j, tp *= T) sum += c.row(j).transpose().array().abs() * (falling_factorial(j, k) * tp);
      S[static_cast<std::size_t>(i * N + k)] =
          std::max(sum.maxCoeff(), S[static_cast<std::size_t>(i * N)] / std::pow(T, k));
    }
    out.term_scale = std::max(out.term_scale, S[static_cast<std::size_t>(i * N)]);
  }
  const auto scale = [&](int i, int k) { return S[static_cast<std::size_t>(i * N + k)]; };
  const auto residual = [&](const Eigen::Vector3d& r, double sc) {
    const double v = r.cwiseAbs().maxCoeff();
    return v == 0.0 ? 0.0 : sc > 0.0 ? v / sc : HUGE_VAL;
  };
  for (int k = 0; k < s; ++k) {
    const Eigen::Vector3d h = p.head.row(k).transpose(), t = p.tail.row(k).transpose();
    out.constraint = std::max(out.constraint, residual(tr.evaluate_segment(0, 0.0, k) - h, scale(0, k) + h.cwiseAbs().maxCoeff()));
    out.constraint = std::max(out.constraint, residual(tr.evaluate_segment(M - 1, p.durations.back(), k) - t,
                                                       scale(M - 1, k) + t.cwiseAbs().maxCoeff()));
  }
  for (int i = 0; i < M; ++i) {
    const Eigen::Vector3d a = p.points.row(i).transpose(), b = p.points.row(i + 1).transpose();
    const Eigen::Vector3d ea = tr.evaluate_segment(i, 0.0) - a, eb = tr.evaluate_segment(i, p.durations[i]) - b;
    out.constraint = std::max({out.constraint, residual(ea, scale(i, 0)), residual(eb, scale(i, 0))});
    // An upper bound on the exact miss of the coefficients as stored: the end by the
    // compensated Horner scheme plus its error bound (compensated_miss), the start exactly
    // (c_0 - p_i as the sum of two long doubles).
    const auto c = tr.segment_coefficients(i);
    ld miss_ld = 0.0L;
    for (int ax = 0; ax < 3; ++ax) {
      ld d, e;
      two_sum(c(0, ax), -static_cast<ld>(p.points(i, ax)), d, e);
      const Compensated end = compensated_miss(c.col(ax), N, p.durations[static_cast<std::size_t>(i)], p.points(i + 1, ax));
      miss_ld = std::max({miss_ld, std::abs(d) + std::abs(e), std::abs(end.value) + end.bound});
    }
    const double miss = static_cast<double>(miss_ld) / out.position_scale;
    if (out.worst_segment < 0 || miss > out.interpolation) {
      out.interpolation = miss;
      out.worst_segment = i;
    }
    if (i + 1 < M)
      for (int k = 0; k <= 2 * s - 2; ++k) {
        double& worst = k < s ? out.constraint : out.optimality;
        worst = std::max(worst, residual(tr.evaluate_segment(i, p.durations[i], k) - tr.evaluate_segment(i + 1, 0.0, k),
                                         std::max(scale(i, k), scale(i + 1, k))));
      }
  }
  return out;
}

void check_answer(const MincoProblem& p, const PolynomialTrajectory& tr) {
  const AnswerCheck c = measure_answer(p, tr);
  const auto [tmin, tmax] = std::minmax_element(p.durations.begin(), p.durations.end());
  // The mean speed each duration asks of its segment: durations that do not fit the
  // segment lengths are the usual cause of an answer that cannot be carried.
  double vmin = HUGE_VAL, vmax = 0.0;
  for (std::size_t i = 0; i < p.durations.size(); ++i) {
    const double v = (p.points.row(static_cast<Eigen::Index>(i) + 1) - p.points.row(static_cast<Eigen::Index>(i))).norm() /
                     p.durations[i];
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  const std::string cause = "durations span " + sci(*tmin) + " to " + sci(*tmax) + " s (ratio " +
                            sci(*tmax / *tmin) + ") and ask mean speeds of " + sci(vmin) + " to " + sci(vmax) +
                            " m/s of the segments";
  if (!c.finite)
    throw Error("traj: the answer is not finite: the problem is beyond double precision (" + cause +
                "); give durations in proportion to the segment lengths, or limits a trajectory can be flown at");
  if (!std::isfinite(tr.cost()))
    throw Error("traj: the answer's cost J is not finite (the squared derivatives overflow a double: " + cause +
                "); give waypoints and durations at flight scales");
  if (c.constraint > kAnswerConstraint)
    throw Error("traj: the answer cannot be trusted: a constraint (waypoint, head, tail or continuity of derivatives "
                "0..s-1) holds only to " + sci(c.constraint) + " relative (bound " + sci(kAnswerConstraint) + "; " +
                cause + ")");
  if (c.interpolation > kAnswerInterpolation)
    throw Error("traj: the answer cannot be trusted: segment " + std::to_string(c.worst_segment) +
                " meets its waypoints only to " + sci(c.interpolation * c.position_scale) + " m (bound " +
                sci(kAnswerInterpolation) + " x " + sci(c.position_scale) + " m): the optimal trajectory swings to " +
                sci(c.term_scale) + " m between waypoints " + sci(c.position_scale) +
                " m apart, beyond what double precision carries: the " + cause +
                ", and a short segment forces derivatives that its long neighbours must undo; give durations in proportion to "
                "the segment lengths (e.g. drop \"durations\" and give \"limits\")");
  if (c.optimality > kAnswerOptimality)
    throw Error("traj: the answer cannot be trusted: the optimality conditions (continuity of derivatives s..2s-2) "
                "hold only to " + sci(c.optimality) + " relative (bound " + sci(kAnswerOptimality) + "; " + cause +
                "); give durations closer to each other");
}

PolynomialTrajectory solve_minco(const MincoProblem& problem) {
  validate(problem);
  PolynomialTrajectory out;
  MincoSolver().solve(problem, out);
  polish_waypoints(problem, out);
  check_answer(problem, out);
  return out;
}

}  // namespace miner::traj
