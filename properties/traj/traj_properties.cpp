// Properties of the back end (spec/traj.md): MINCO's optimality conditions, agreement
// with independent solvers (dense pivoted LU of A c = b, and Ceres minimising the
// effort by quadrature), gradients against finite differences, the time-scaling law,
// and the trapezoidal allocation. Random problems are built from a generated seed.
#include <cmath>
#include <vector>

// Boost.Multiprecision's rationals (the exact waypoint miss): GCC's -Wmaybe-uninitialized
// misreads a static zero inside cpp_int (a false positive of the optimiser in a system header).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/multiprecision/cpp_int.hpp>
#pragma GCC diagnostic pop
#include <ceres/ceres.h>
// Ceres brings glog, whose CHECK aborts the process; Catch's CHECK (a counted, reported
// assertion that lets the test go on) must be the one this file uses.
#undef CHECK
#include <catch2/catch.hpp>
#include <Eigen/LU>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/testing/property.hpp"
#include "miner/traj/baselines.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/optimality_system.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

using namespace miner::traj;
using miner::Rng;
using miner::testing::property;

namespace {

struct RandomProblemOptions {
  double min_duration = 0.2, max_duration = 5.0;
  bool rest = false;
};

MincoProblem random_problem(std::uint64_t seed, RandomProblemOptions o = {}) {
  Rng rng(seed);
  const int s = rng.uniform01() < 0.5 ? 3 : 4;
  const int M = 1 + static_cast<int>(rng.uniform_index(12));
  Eigen::MatrixX3d pts(M + 1, 3);
  for (int i = 0; i <= M; ++i) pts.row(i) << rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(0, 5);
  std::vector<double> T(M);
  for (auto& t : T) t = rng.uniform(o.min_duration, o.max_duration);
  MincoProblem p = rest_to_rest(s, pts, T);
  if (!o.rest) {
    for (int k = 1; k < s; ++k) {
      p.head.row(k) << rng.normal(), rng.normal(), rng.normal();
      p.tail.row(k) << rng.normal(), rng.normal(), rng.normal();
    }
  }
  return p;
}

/// The 2s x 2s map from monomial coefficients to Hermite data on [0, T], built and
/// inverted here with a full-pivot LU, independently of the solver's closed forms.
Eigen::MatrixXd endpoint_matrix(int s, double T) {
  const int n = 2 * s;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < s; ++k)
    for (int a = k; a < n; ++a) {
      double f = 1.0;
      for (int i = 0; i < k; ++i) f *= a - i;
      if (a == k) E(k, a) = f;
      E(s + k, a) = f * std::pow(T, a - k);
    }
  return E;
}

/// Size of the trajectory's k-th derivative values, for relative tolerances.
double scale_of(const PolynomialTrajectory& t, int k) {
  double m = 1.0;
  for (int i = 0; i < t.segments(); ++i) {
    m = std::max(m, t.evaluate_segment(i, 0.0, k).norm());
    m = std::max(m, t.evaluate_segment(i, t.durations()[i], k).norm());
  }
  return m;
}

/// Relative agreement of values computed by two routes, for durations within a factor
/// 4 of each other: MINCO's derivatives were measured within 5e-11 of a long-double
/// dense solve there (dense double LU: 1e-12). With a 25x spread of durations the error
/// grows to ~1e-7 (docs/traj.md, a known weakness), so properties that compare values
/// draw durations from [0.5, 2] s.
constexpr double kRelative = 1e-9;

/// Effort of one segment by s-point Gauss-Legendre quadrature (exact for the degree
/// 2s - 2 integrand), as residuals r_q = sqrt(w_q T / 2) p^{(s)}(t_q): Ceres minimises
/// sum r^2 over the interior derivatives, an independent route to the optimum.
class SegmentEffort : public ceres::CostFunction {
 public:
  SegmentEffort(int s, double T, Eigen::MatrixXd known, bool free_start, bool free_end)
      : s_(s), T_(T), known_(std::move(known)), free_start_(free_start), free_end_(free_end) {
    const Eigen::MatrixXd Einv = endpoint_matrix(s, T).fullPivLu().inverse();
    static const double x3[] = {-0.7745966692414834, 0.0, 0.7745966692414834};
    static const double w3[] = {0.5555555555555556, 0.8888888888888888, 0.5555555555555556};
    static const double x4[] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double w4[] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    R_ = Eigen::MatrixXd::Zero(s, 2 * s);
    for (int q = 0; q < s; ++q) {
      const double xq = s == 3 ? x3[q] : x4[q], wq = s == 3 ? w3[q] : w4[q];
      const double t = 0.5 * T * (xq + 1.0);
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(2 * s);
      for (int a = s; a < 2 * s; ++a) {
        double f = 1.0;
        for (int i = 0; i < s; ++i) f *= a - i;
        row(a) = f * std::pow(t, a - s);
      }
      R_.row(q) = std::sqrt(0.5 * wq * T) * row * Einv;  // residual per unit Hermite data
    }
    set_num_residuals(3 * s);
    if (free_start_) mutable_parameter_block_sizes()->push_back(3 * (s - 1));
    if (free_end_) mutable_parameter_block_sizes()->push_back(3 * (s - 1));
  }

  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    Eigen::MatrixXd x = known_;  // 2s x 3 Hermite data
    int b = 0;
    const auto fill = [&](int row0, const double* z) {
      for (int k = 0; k < s_ - 1; ++k)
        for (int ax = 0; ax < 3; ++ax) x(row0 + k, ax) = z[3 * k + ax];
    };
    if (free_start_) fill(1, params[b++]);
    if (free_end_) fill(s_ + 1, params[b++]);
    const Eigen::MatrixXd r = R_ * x;  // s x 3
    for (int q = 0; q < s_; ++q)
      for (int ax = 0; ax < 3; ++ax) residuals[3 * q + ax] = r(q, ax);
    if (jacobians) {
      b = 0;
      for (const auto& [used, row0] : {std::pair<bool, int>{free_start_, 1}, {free_end_, s_ + 1}}) {
        if (!used) continue;
        if (double* J = jacobians[b++]) {
          const int cols = 3 * (s_ - 1);
          for (int q = 0; q < s_; ++q)
            for (int ax = 0; ax < 3; ++ax)
              for (int k = 0; k < s_ - 1; ++k)
                for (int ax2 = 0; ax2 < 3; ++ax2)
                  J[(3 * q + ax) * cols + 3 * k + ax2] = ax == ax2 ? R_(q, row0 + k) : 0.0;
        }
      }
    }
    return true;
  }

 private:
  int s_;
  double T_;
  Eigen::MatrixXd known_;
  bool free_start_, free_end_;
  Eigen::MatrixXd R_;
};

/// Minimises the effort over the interior derivatives with Ceres; returns the Hermite
/// derivatives 1..s-1 at every waypoint (rows), axes in columns.
std::vector<Eigen::MatrixXd> ceres_optimum(const MincoProblem& p) {
  const int s = p.order, M = static_cast<int>(p.durations.size());
  std::vector<std::vector<double>> z(M + 1, std::vector<double>(3 * (s - 1), 0.0));
  ceres::Problem problem;
  for (int i = 0; i < M; ++i) {
    Eigen::MatrixXd known = Eigen::MatrixXd::Zero(2 * s, 3);
    known.row(0) = p.points.row(i);
    known.row(s) = p.points.row(i + 1);
    if (i == 0) known.middleRows(1, s - 1) = p.head.middleRows(1, s - 1);
    if (i == M - 1) known.middleRows(s + 1, s - 1) = p.tail.middleRows(1, s - 1);
    const bool fs = i > 0, fe = i < M - 1;
    std::vector<double*> blocks;
    if (fs) blocks.push_back(z[i].data());
    if (fe) blocks.push_back(z[i + 1].data());
    if (!blocks.empty()) problem.AddResidualBlock(new SegmentEffort(s, p.durations[i], known, fs, fe), nullptr, blocks);
  }
  std::vector<Eigen::MatrixXd> out(M + 1, Eigen::MatrixXd::Zero(s - 1, 3));
  if (M > 1) {
    ceres::Solver::Options opt;
    opt.linear_solver_type = ceres::DENSE_QR;
    opt.max_num_consecutive_invalid_steps = 100;  // steps below rounding are "invalid"; keep going
    opt.function_tolerance = 1e-16;
    opt.gradient_tolerance = 1e-16;
    opt.parameter_tolerance = 1e-16;
    opt.max_num_iterations = 500;
    ceres::Solver::Summary summary;
    ceres::Solve(opt, &problem, &summary);
    if (summary.termination_type != ceres::CONVERGENCE) throw std::runtime_error("Ceres: " + summary.message);
  }
  for (int j = 1; j < M; ++j)
    for (int k = 0; k < s - 1; ++k)
      for (int ax = 0; ax < 3; ++ax) out[j](k, ax) = z[j][3 * k + ax];
  return out;
}

}  // namespace

TEST_CASE("MINCO interpolates the waypoints and meets the head and tail states", "[REQ-TRAJ-002]") {
  property("p(t_i) = points_i and boundary derivatives hold", [](std::uint64_t seed) {
    const MincoProblem p = random_problem(seed, {0.5, 2.0, false});
    const auto t = solve_minco(p);
    const int M = t.segments();
    for (int i = 0; i <= M; ++i) {
      const Eigen::Vector3d at = i < M ? t.evaluate_segment(i, 0.0) : t.evaluate_segment(M - 1, p.durations[M - 1]);
      RC_ASSERT((at - p.points.row(i).transpose()).norm() <= kRelative * scale_of(t, 0));
    }
    for (int k = 0; k < p.order; ++k) {
      RC_ASSERT((t.evaluate_segment(0, 0.0, k) - p.head.row(k).transpose()).norm() <= kRelative * scale_of(t, k));
      RC_ASSERT((t.evaluate_segment(M - 1, p.durations[M - 1], k) - p.tail.row(k).transpose()).norm() <=
                kRelative * scale_of(t, k));
    }
  });
}

TEST_CASE("Evaluation agrees with finite differences on every axis at random times, up to order 2s", "[REQ-TRAJ-004]") {
  // Random trajectories (durations over a 25x spread), random times inside a segment, every
  // axis: the k-th derivative equals the central difference of the (k-1)-th, for k = 1 .. 2s
  // (snap and beyond; 2s - 1 is the last nonzero one), and the global and per-segment
  // evaluations agree. The Richardson-extrapolated central difference errs by O(h^4) (h = 1e-3
  // T_i; a plain one erred by up to 1e-2 of the scale on 0.2 s segments of degree 7) plus the
  // rounding of monomial sums divided by h; kFiniteDifference of the derivatives' scale covers
  // both, while a wrong derivative factor is off by O(1).
  constexpr double kFiniteDifference = 1e-4;
  property("d^k p / dt^k = central difference of d^(k-1) p, all axes", [](std::uint64_t seed) {
    const MincoProblem p = random_problem(seed);  // durations 0.2-5 s, a 25x spread
    const auto t = solve_minco(p);
    Rng rng(seed ^ 0x5eedULL);
    for (int draw = 0; draw < 8; ++draw) {
      const int i = static_cast<int>(rng.uniform_index(static_cast<std::uint64_t>(t.segments())));
      const double T = t.durations()[static_cast<std::size_t>(i)], h = 1e-3 * T;
      const double tau = rng.uniform(2 * h, T - 2 * h);
      double start = 0.0;
      for (int j = 0; j < i; ++j) start += t.durations()[static_cast<std::size_t>(j)];
      for (int k = 1; k <= 2 * p.order; ++k) {
        const Eigen::Vector3d d = t.evaluate_segment(i, tau, k);
        // Central differences at h and h / 2, Richardson-extrapolated: error O(h^4).
        const auto central = [&](double step) {
          return Eigen::Vector3d((t.evaluate_segment(i, tau + step, k - 1) - t.evaluate_segment(i, tau - step, k - 1)) /
                                 (2 * step));
        };
        const Eigen::Vector3d fd = (4.0 * central(h / 2) - central(h)) / 3.0;
        RC_ASSERT((d - fd).cwiseAbs().maxCoeff() <= kFiniteDifference * (scale_of(t, k) + scale_of(t, k - 1) / T));
        RC_ASSERT((t.evaluate(start + tau, k) - d).norm() <= 1e-6 * scale_of(t, k));
      }
      RC_ASSERT(t.evaluate_segment(i, tau, 2 * p.order).norm() == 0.0);  // degree 2s - 1
    }
  });
}

TEST_CASE("MINCO is continuous in derivatives 0..2s-2 at interior waypoints", "[REQ-TRAJ-002]") {
  property("no jump in derivatives up to 2s-2", [](std::uint64_t seed) {
    const MincoProblem p = random_problem(seed, {0.5, 2.0, false});
    const auto t = solve_minco(p);
    for (int i = 0; i + 1 < t.segments(); ++i)
      for (int k = 0; k <= 2 * p.order - 2; ++k) {
        const Eigen::Vector3d left = t.evaluate_segment(i, p.durations[i], k);
        const Eigen::Vector3d right = t.evaluate_segment(i + 1, 0.0, k);
        RC_ASSERT((left - right).norm() <= kRelative * scale_of(t, k));
      }
  });
}

TEST_CASE("No feasible perturbation lowers the MINCO cost and the first-order condition holds", "[REQ-TRAJ-002]") {
  property("J(c + eps d) >= J(c) and dJ/deps = 0", [](std::uint64_t seed) {
    MincoProblem p = random_problem(seed);
    RC_PRE(p.durations.size() >= 2);
    const auto t = solve_minco(p);
    Rng rng(seed, 1);
    const int s = p.order, n = 2 * s;
    // Perturb derivative k (1..s-1) at interior waypoint j: segment j-1 changes its end
    // datum, segment j its start datum; positions and derivatives 0..s-1 stay matched,
    // so every constraint of the problem still holds.
    const int j = 1 + static_cast<int>(rng.uniform_index(p.durations.size() - 1));
    const int k = 1 + static_cast<int>(rng.uniform_index(static_cast<std::uint64_t>(s - 1)));
    const Eigen::Vector3d dir(rng.normal(), rng.normal(), rng.normal());
    Eigen::MatrixX3d d = Eigen::MatrixX3d::Zero(t.coefficients().rows(), 3);
    Eigen::MatrixXd hermite = Eigen::MatrixXd::Zero(n, 3);
    hermite.row(s + k) = dir.transpose();
    d.middleRows(n * (j - 1), n) = endpoint_matrix(s, p.durations[j - 1]).fullPivLu().solve(hermite);
    hermite.setZero();
    hermite.row(k) = dir.transpose();
    d.middleRows(n * j, n) = endpoint_matrix(s, p.durations[j]).fullPivLu().solve(hermite);
    const PolynomialTrajectory dt(s, p.durations, d);
    const double J0 = t.cost();
    const double slope = (t.cost_gradient_coefficients().array() * d.array()).sum();
    const double curvature = dt.cost();
    RC_ASSERT(std::fabs(slope) <= 1e-7 * std::sqrt(J0 * curvature) + 1e-12);
    for (double eps : {1e-3, -1e-2, 0.1, -1.0}) {
      const PolynomialTrajectory moved(s, p.durations, t.coefficients() + eps * d);
      RC_ASSERT(moved.cost() >= J0 - 1e-9 * J0);
    }
  });
}

TEST_CASE("MINCO agrees with the dense pivoted LU solve, the KKT QP and Ceres", "[REQ-TRAJ-003][REQ-TRAJ-009]") {
  property("three routes, one optimum", [](std::uint64_t seed) {
    // Durations within a factor 4 of each other, as trapezoidal allocation gives for
    // segments within a factor 16 in length: the conditioning of the effort grows like
    // (T_max / T_min)^(2s-1), and Ceres' QR solve is held to 1e-8 below.
    const MincoProblem p = random_problem(seed, {0.5, 2.0, false});
    const auto t = solve_minco(p);
    const auto sys = optimality_system(p);
    const Eigen::MatrixX3d dense = sys.A.partialPivLu().solve(sys.b);
    RC_ASSERT((t.coefficients() - dense).norm() <= 1e-8 * dense.norm());
    // The Mellinger QP through its KKT system: an independent optimiser, 1e-8 in states.
    const PolynomialTrajectory qp(p.order, p.durations, solve_kkt_qp(p));
    for (int i = 0; i < t.segments(); ++i)
      for (int k = 0; k < p.order; ++k) {
        const double tau = 0.37 * p.durations[i];
        RC_ASSERT((t.evaluate_segment(i, tau, k) - qp.evaluate_segment(i, tau, k)).norm() <= 1e-8 * scale_of(t, k));
      }
    const auto z = ceres_optimum(p);
    const int s = p.order;
    for (int j = 1; j < t.segments(); ++j)
      for (int k = 1; k < s; ++k) {
        const Eigen::Vector3d minco = t.evaluate_segment(j, 0.0, k);
        const Eigen::Vector3d ceres = z[j].row(k - 1).transpose();
        // Ceres stops on relative cost decrease; near the optimum the cost is quadratic,
        // so its parameters are known to about sqrt(1e-16) = 1e-8 relative (measured up
        // to 1.06e-8): 1e-6 bounds that. The dense LU above is the 1e-8 check.
        RC_ASSERT((minco - ceres).norm() <= 1e-6 * scale_of(t, k));
      }
  });
}

TEST_CASE("The relative residual of A c = b stays below 1e-12 for durations from 1e-3 s to 1e3 s", "[REQ-TRAJ-003]") {
  property("residual < 1e-12", [](std::uint64_t seed) {
    Rng rng(seed, 2);
    const double scale = std::pow(10.0, rng.uniform(-3.0, 3.0));
    // Durations within a factor 2 of the scale; with a 4x spread and s = 4 the residual
    // was measured up to 2e-12 (docs/traj.md), the dense LU's at 1e-17.
    const MincoProblem p = random_problem(seed, {scale, 2.0 * scale, false});
    // The solver alone (a 1e3 s problem with unit head accelerations swings ~1e8 m, which the
    // answer check refuses: REQ-TRAJ-010); this property measures the solve's residual.
    PolynomialTrajectory t;
    MincoSolver().solve(p, t);
    RC_ASSERT(relative_residual(optimality_system(p), t.coefficients()) < 1e-12);
  });
}

namespace {
/// A random problem whose durations spread over exactly `spread`: log-uniform over
/// [T0, spread T0], the first and last segments at the two ends.
MincoProblem spread_problem(std::uint64_t seed, double spread) {
  MincoProblem p = random_problem(seed);
  Rng rng(seed, 3);
  const double T0 = std::pow(10.0, rng.uniform(-1.0, 1.0));
  for (auto& T : p.durations) T = T0 * std::pow(spread, rng.uniform01());
  if (p.durations.size() >= 2) {
    p.durations.front() = T0;
    p.durations.back() = spread * T0;
  }
  return p;
}
/// The exact largest distance (max norm, over the axes and both ends of every segment) of the
/// answer's segment ends from their waypoints, relative to L: the stored doubles evaluated in
/// rational arithmetic (Boost.Multiprecision), independent of the check's compensated Horner.
double exact_waypoint_miss(const MincoProblem& p, const PolynomialTrajectory& t) {
  using Q = boost::multiprecision::cpp_rational;
  const double L = std::max(p.points.cwiseAbs().maxCoeff(),
                            (p.points.colwise().maxCoeff() - p.points.colwise().minCoeff()).maxCoeff());
  Q worst = 0;
  for (int i = 0; i < t.segments(); ++i) {
    const auto c = t.segment_coefficients(i);
    const Q T = Q(p.durations[static_cast<std::size_t>(i)]);
    for (int a = 0; a < 3; ++a) {
      Q end = 0;
      for (Eigen::Index j = c.rows() - 1; j >= 0; --j) end = end * T + Q(c(j, a));
      const Q start_miss = abs(Q(c(0, a)) - Q(p.points(i, a))), end_miss = abs(end - Q(p.points(i + 1, a)));
      worst = std::max(worst, std::max(start_miss, end_miss));
    }
  }
  return static_cast<double>(worst) / L;
}

/// The 200 fixed problems of spread 1e3 the answer-check tests share, each with the solver's
/// raw answer (no polish, no check).
struct RawAnswer {
  MincoProblem problem;
  PolynomialTrajectory raw;
};
std::vector<RawAnswer> raw_spread_answers() {
  std::vector<RawAnswer> out(200);
  for (std::size_t seed = 0; seed < out.size(); ++seed) {
    out[seed].problem = spread_problem(seed, 1e3);
    MincoSolver().solve(out[seed].problem, out[seed].raw);
  }
  return out;
}
}  // namespace

TEST_CASE("Durations spread over 1e3: an answer meets its waypoints to 1e-9 or is refused, never wrong", "[REQ-TRAJ-010]") {
  property("solve_minco returns only answers that meet the bounds", [](std::uint64_t seed) {
    const MincoProblem p = spread_problem(seed, 1e3);
    PolynomialTrajectory t;
    try {
      t = solve_minco(p);
    } catch (const miner::Error& e) {
      RC_ASSERT(std::string(e.what()).find("cannot be trusted") != std::string::npos);
      return;  // refused, naming the cause
    }
    RC_ASSERT(exact_waypoint_miss(p, t) <= kAnswerInterpolation);
    const auto c = measure_answer(p, t);
    RC_ASSERT(c.constraint <= kAnswerConstraint);
    RC_ASSERT(c.optimality <= kAnswerOptimality);
  });
}

TEST_CASE("Durations spread over 1e3: the check refuses exactly the answers that miss", "[REQ-TRAJ-010]") {
  // The solver's raw answers (no polish), 200 fixed problems: about half of them miss a
  // waypoint by more than 1e-9 L (docs/traj.md). Judged against the exact miss: every answer
  // the check accepts meets the bound, every answer that misses it is refused, and every
  // answer within half the bound is accepted (the compensated evaluation is tight; a check
  // that refused everything, or accepted everything, fails here).
  int accepted = 0, missed = 0, seed = 0;
  for (const auto& [p, t] : raw_spread_answers()) {
    const double exact = exact_waypoint_miss(p, t);
    const auto c = measure_answer(p, t);
    INFO("seed " << seed++ << ": exact miss " << exact << " L, check's bound " << c.interpolation << " L");
    CHECK(c.interpolation >= exact);                   // an upper bound ...
    CHECK(c.interpolation <= exact + 1e-20);           // ... and a tight one
    bool ok = true;
    try {
      check_answer(p, t);
    } catch (const miner::Error&) {
      ok = false;
    }
    if (exact > kAnswerInterpolation) CHECK_FALSE(ok);
    if (exact <= 0.5 * kAnswerInterpolation && c.constraint <= kAnswerConstraint && c.optimality <= kAnswerOptimality)
      CHECK(ok);
    accepted += ok;
    missed += exact > kAnswerInterpolation;
  }
  CHECK(missed >= 40);  // the raw solve misses often enough for the check to be exercised
  CHECK(accepted >= 60);
}

TEST_CASE("Durations spread over 1e3: the waypoint polish meets the waypoints the raw solve misses", "[REQ-TRAJ-010]") {
  // Same 200 problems. The polish never moves an end away from its waypoint, never moves a
  // constraint residual by more than its damage bound (two passes), keeps the optimality
  // conditions, and brings most raw misses under the bound (measured: 103 raw answers
  // within 1e-9 L, 192 polished).
  int raw_within = 0, polished_within = 0, seed = 0;
  for (const auto& [p, raw] : raw_spread_answers()) {
    PolynomialTrajectory polished = raw;
    polish_waypoints(p, polished);
    const double before = exact_waypoint_miss(p, raw), after = exact_waypoint_miss(p, polished);
    const auto c0 = measure_answer(p, raw), c1 = measure_answer(p, polished);
    INFO("seed " << seed++ << ": exact miss " << before << " -> " << after << " L");
    CHECK(after <= before);
    // The damage bound of spec REQ-TRAJ-010 (1e-12 of each derivative's scale, fixed here
    // so that the product's constant cannot loosen it), per pass, two passes, both sides of
    // a junction: 4e-12.
    CHECK(c1.constraint <= c0.constraint + 4e-12);
    CHECK(c1.optimality <= c0.optimality + 4e-12);
    raw_within += before <= kAnswerInterpolation;
    polished_within += after <= kAnswerInterpolation;
  }
  CHECK(polished_within >= 180);
  CHECK(polished_within >= raw_within + 60);
}

TEST_CASE("Analytic gradients of the optimal cost match central differences", "[REQ-TRAJ-005]") {
  property("dJ*/dT and dJ*/dp", [](std::uint64_t seed) {
    const MincoProblem p = random_problem(seed);
    MincoSolver solver;
    PolynomialTrajectory t;
    solver.solve(p, t);
    MincoGradients g;
    solver.cost_and_gradients(p, &g);
    const auto J = [&](const MincoProblem& q) {
      PolynomialTrajectory out;
      MincoSolver sv;
      sv.solve(q, out);
      return sv.cost_and_gradients(q, nullptr);
    };
    Rng rng(seed, 3);
    const int i = static_cast<int>(rng.uniform_index(p.durations.size()));
    // Fourth-order central difference: truncation O(h^4) ~ 1e-12, rounding ~1e-8 J / T.
    const double h = 1e-3 * p.durations[i];
    const auto J_at = [&](double dT) {
      MincoProblem q = p;
      q.durations[i] += dT;
      return J(q);
    };
    const double fd_T = (8 * (J_at(h) - J_at(-h)) - (J_at(2 * h) - J_at(-2 * h))) / (12 * h);
    MincoProblem up = p, down = p;
    RC_ASSERT(std::fabs(fd_T - g.durations[i]) <= 1e-5 * (std::fabs(g.durations[i]) + J(p) / p.durations[i]));
    const int j = static_cast<int>(rng.uniform_index(static_cast<std::uint64_t>(p.points.rows())));
    const int ax = static_cast<int>(rng.uniform_index(3));
    const double hp = 1e-2;  // J* is quadratic in the points: central differences are exact
    up = p;
    down = p;
    up.points(j, ax) += hp;
    down.points(j, ax) -= hp;
    if (j == 0) { up.head(0, ax) += hp; down.head(0, ax) -= hp; }
    if (j == p.points.rows() - 1) { up.tail(0, ax) += hp; down.tail(0, ax) -= hp; }
    const double fd_p = (J(up) - J(down)) / (2 * hp);
    RC_ASSERT(std::fabs(fd_p - g.points(j, ax)) <= 1e-5 * (std::fabs(g.points(j, ax)) + J(p) / 10.0 + 1e-9));
    // And the coefficient gradient: dJ/dc along a random direction.
    const Eigen::MatrixX3d dir = Eigen::MatrixX3d::Random(t.coefficients().rows(), 3);
    const double hc = 1e-6;
    const double fd_c = (PolynomialTrajectory(p.order, p.durations, t.coefficients() + hc * dir).cost() -
                         PolynomialTrajectory(p.order, p.durations, t.coefficients() - hc * dir).cost()) / (2 * hc);
    const double an_c = (t.cost_gradient_coefficients().array() * dir.array()).sum();
    RC_ASSERT(std::fabs(fd_c - an_c) <= 1e-5 * (std::fabs(an_c) + t.cost() + 1e-9));
  });
}

TEST_CASE("Scaling all durations by k scales the rest-to-rest cost by k^(1-2s)", "[REQ-TRAJ-005]") {
  property("time-scaling law", [](std::uint64_t seed) {
    const MincoProblem p = random_problem(seed, {0.2, 5.0, true});
    Rng rng(seed, 4);
    const double k = rng.uniform(0.1, 10.0);
    MincoProblem q = p;
    for (auto& d : q.durations) d *= k;
    const double expected = std::pow(k, 1 - 2 * p.order) * solve_minco(p).cost();
    RC_ASSERT(std::fabs(solve_minco(q).cost() - expected) <= 1e-9 * expected);
  });
}

TEST_CASE("Optimised allocation is never above the trapezoid's objective, holds the limits and is locally optimal", "[REQ-TRAJ-011]") {
  // 30 drawn problems rather than rapidcheck's 100: one optimisation costs ~1 s under the
  // sanitizer build (Ceres + pattern search), and 100 of them took 269 s of CI's 600.
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    INFO("problem seed " << seed);
    Rng rng(seed, 4);
    // Paths of 1..5 segments from 0.5 m to 20 m (maps from a room to a 100 m sim map), rest
    // to rest, limits and rho over two orders of magnitude.
    MincoProblem p = random_problem(seed, {0.5, 2.0, true});  // rest to rest (REQ-TRAJ-011)
    const int M = std::min<int>(static_cast<int>(p.durations.size()), 5);
    p.points.conservativeResize(M + 1, 3);
    p.durations.resize(static_cast<std::size_t>(M));
    for (int i = 1; i <= M; ++i) {
      Eigen::Vector3d d(rng.normal(), rng.normal(), rng.normal());
      p.points.row(i) = p.points.row(i - 1) + (rng.uniform(0.5, 20.0) / d.norm()) * d.transpose();
    }
    p.head.row(0) = p.points.row(0);
    p.tail.row(0) = p.points.row(M);
    AllocationOptions o;
    o.limits = Limits{rng.uniform(0.5, 5.0), rng.uniform(0.5, 5.0)};
    o.rho = std::pow(10.0, rng.uniform(-1.0, 1.0));
    AllocationResult r;
    REQUIRE_NOTHROW(r = optimise_allocation(p, o));
    CHECK(r.objective <= r.start_objective);
    CHECK(r.max_speed <= o.limits.v_max);
    CHECK(r.max_acceleration <= o.limits.a_max);
    CHECK(std::abs(r.objective - feasible_objective(p, r.durations, o).first) <= 1e-9 * r.objective);
    for (std::size_t i = 0; i < r.durations.size(); ++i)
      for (double h : {1e-3, -1e-3}) {
        auto T = r.durations;
        T[i] *= std::exp(h);
        CHECK(feasible_objective(p, T, o).first >= r.objective * (1.0 - 1e-9));
      }
  }
}

TEST_CASE("Trapezoidal allocation is continuous, increasing and within the limits", "[REQ-TRAJ-001]") {
  property("profile properties", [](std::uint64_t seed) {
    Rng rng(seed);
    const Limits lim{rng.uniform(0.1, 10.0), rng.uniform(0.1, 10.0)};
    const double d_a = lim.v_max * lim.v_max / (2 * lim.a_max);
    // Continuity at the switch point 2 d_a.
    const double below = trapezoidal_duration(2 * d_a * (1 - 1e-12), lim);
    const double at = trapezoidal_duration(2 * d_a, lim);
    RC_ASSERT(std::fabs(below - at) <= 1e-9 * at);
    const double d1 = rng.uniform(0.0, 10 * d_a), d2 = d1 + rng.uniform(1e-6, 10 * d_a);
    RC_ASSERT(trapezoidal_duration(d1, lim) < trapezoidal_duration(d2, lim));
    // The profile with duration T covers d with peak speed <= v_max and accel a_max.
    const double T = trapezoidal_duration(d1, lim);
    const double t_acc = std::min(T / 2, lim.v_max / lim.a_max);
    const double v_peak = lim.a_max * t_acc;
    RC_ASSERT(v_peak <= lim.v_max * (1 + 1e-12));
    const double covered = v_peak * t_acc + v_peak * (T - 2 * t_acc);
    RC_ASSERT(std::fabs(covered - d1) <= 1e-9 * (d1 + d_a));
  });
}
