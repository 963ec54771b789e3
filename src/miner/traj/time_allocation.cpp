#include "miner/traj/time_allocation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <tuple>

#include <ceres/ceres.h>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::traj {

void scale_time(PolynomialTrajectory& t, double k) {
  if (!(k > 0.0) || !std::isfinite(k)) throw Error("scale_time: k must be positive and finite");
  // The scaled durations stay finite (tenth campaign L17: k = 1e300 made infinite ones).
  for (const double d : t.durations())
    if (!(std::isfinite(d * k) && d * k > 0.0)) throw Error("scale_time: k = " + short_number(k) + " makes a duration infinite or zero");
  // Every coefficient must survive its division by k^j: k = 1e300 underflowed them to 0 (peaks
  // of 0, a NaN cost) and 1e-300 overflowed them (thirteenth campaign L2).
  auto c = t.coefficients();
  const int n = 2 * t.order();
  for (int i = 0; i < t.segments(); ++i) {
    double kj = 1.0;
    for (int j = 0; j < n; ++j, kj *= k)
      for (int a = 0; a < 3; ++a) {
        double& x = c(n * i + j, a);
        const double scaled = x / kj;
        if (!std::isfinite(scaled) || (x != 0.0 && scaled == 0.0) || !std::isfinite(kj) || kj == 0.0)
          throw Error("scale_time: k = " + short_number(k) + " puts coefficient " + std::to_string(j) + " of segment " +
                      std::to_string(i) + " outside double precision");
        x = scaled;
      }
  }
  t.mutable_coefficients() = c;
  for (double& d : t.mutable_durations()) d *= k;
}

namespace {

/// Coefficients of a polynomial in u on [0, 1], lowest degree first (degree <= kMaxPeakDegree).
using PeakPolynomial = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPeakDegree + 1, 1>;

/// Sign changes of the Bernstein coefficients b (exact zeros skipped): by Descartes' rule for
/// the Bernstein basis it bounds the roots in the open interval and has their parity.
int sign_variations(const PeakPolynomial& b) {
  int changes = 0;
  double last = 0.0;
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    if (b[i] == 0.0) continue;
    if (last != 0.0 && (b[i] > 0.0) != (last > 0.0)) ++changes;
    last = b[i];
  }
  return changes;
}

/// A root located to within this in u is close enough: |p^(k)|^2 is flat at its extremum, so
/// its value there is off by ~|d2/du2 |p^(k)|^2| kRootStep^2 / 2, far below a double's rounding.
constexpr double kRootStep = 1e-12;
/// The hull bound is computed with rounding (a few ulps of d's largest term); a segment is
/// passed over only when its bound is below the peak found by more than that.
constexpr double kHullRounding = 1e-12;

/// The one root of g (power basis in u) in [lo, hi], where g changes sign: Newton steps kept
/// inside the shrinking bracket, bisection where a step would leave it.
double bracketed_root(const PeakPolynomial& g, double lo, double hi) {
  const auto value = [&](double u) {
    double v = g[g.size() - 1], dv = 0.0;
    for (Eigen::Index q = g.size() - 2; q >= 0; --q) dv = dv * u + v, v = v * u + g[q];
    return std::pair{v, dv};
  };
  const bool rising = value(lo).first < 0.0;  // g(lo) < 0 < g(hi), or the other way round
  double u = 0.5 * (lo + hi);
  for (int it = 0; it < kMaxRootIterations && lo < hi; ++it) {
    const auto [v, dv] = value(u);
    if (v == 0.0) return u;
    if ((v < 0.0) == rising) lo = u;
    else hi = u;
    const double newton = u - v / dv;
    const double next = (dv != 0.0 && newton > lo && newton < hi) ? newton : 0.5 * (lo + hi);
    if (std::abs(next - u) <= kRootStep) return next;
    u = next;
  }
  return u;
}

/// Every root of g in [lo, hi], given g's Bernstein coefficients b on that interval: none where
/// b has no sign change, the one root where it has one, else the two halves (de Casteljau at
/// the midpoint, which is itself a candidate), down to kMaxPeakBisections halvings (a double
/// root there: its midpoint). A candidate that is no root only adds a value below the peak.
void isolate_roots(const PeakPolynomial& g, const PeakPolynomial& b, double lo, double hi, int depth,
                   std::vector<double>& roots) {
  const int changes = sign_variations(b);
  if (changes == 0) return;
  if (changes == 1) {
    roots.push_back(bracketed_root(g, lo, hi));
    return;
  }
  if (depth == kMaxPeakBisections) {
    roots.push_back(0.5 * (lo + hi));
    return;
  }
  // de Casteljau at 1/2: the left half's coefficients are the triangle's first column, the
  // right half's its last row, read backwards.
  const Eigen::Index n = b.size();
  PeakPolynomial work = b, left(n), right(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    left[r] = work[0];
    right[n - 1 - r] = work[n - 1 - r];
    for (Eigen::Index i = 0; i + 1 < n - r; ++i) work[i] = 0.5 * (work[i] + work[i + 1]);
  }
  // The split point itself: a root exactly there (the speed peak of a symmetric segment at
  // u = 1/2) is an exact zero at the end of both halves, which sign_variations skips
  // (thirteenth campaign L1: a straight rest-to-rest leg's peak was missed, 1e-14 reported).
  const double mid = 0.5 * (lo + hi);
  roots.push_back(mid);
  isolate_roots(g, left, lo, mid, depth + 1, roots);
  isolate_roots(g, right, mid, hi, depth + 1, roots);
}

}  // namespace

std::pair<double, double> exact_extremes(const PolynomialTrajectory& t) {
  t.check_consistent("exact_extremes");
  if (!t.coefficients().allFinite()) throw Error("exact_extremes: the trajectory's coefficients must be finite numbers");
  const int n = 2 * t.order();
  // The k-th derivative of segment i at t = u T, u in [0, 1]: sum_j d_j u^j with
  // d_j = (j+1)...(j+k) c_{j+k} T^j (m = 2s - k terms).
  const auto derivative = [&](int i, int k, Eigen::Matrix<double, 8, 3>& d) {
    const auto c = t.segment_coefficients(i);
    const double T = t.durations()[static_cast<std::size_t>(i)];
    const int m = n - k;
    double Tj = 1.0;
    for (int j = 0; j < m; ++j, Tj *= T) {
      double f = 1.0;
      for (int q = 1; q <= k; ++q) f *= j + q;
      d.row(j) = f * Tj * c.row(j + k);
    }
    return m;
  };
  const auto norm2 = [](const Eigen::Matrix<double, 8, 3>& d, int m, double u) {
    Eigen::RowVector3d x = d.row(m - 1);
    for (int j = m - 2; j >= 0; --j) x = x * u + d.row(j);
    return x.squaredNorm();
  };
  // First every segment's ends, so that the bound below can pass over segments whose interior
  // cannot beat them.
  double peak2[2] = {0.0, 0.0};  // squared peak speed, acceleration
  Eigen::Matrix<double, 8, 3> d;
  for (int i = 0; i < t.segments(); ++i)
    for (const int k : {1, 2}) {
      const int m = derivative(i, k, d);
      peak2[k - 1] = std::max({peak2[k - 1], norm2(d, m, 0.0), norm2(d, m, 1.0)});
    }
  std::vector<double> roots;
  for (int i = 0; i < t.segments(); ++i)
    for (const int k : {1, 2}) {
      const int m = derivative(i, k, d);
      // A Bernstein polynomial lies in the convex hull of its coefficients, so |p^(k)| on the
      // segment is at most the largest |b_r| of d's Bernstein coefficients on [0, 1]
      // (b_r = sum_{j <= r} C(r, j) / C(m - 1, j) d_j): no root search where that is no higher
      // than the peak already found.
      double bound2 = 0.0;
      for (int r = 0; r < m; ++r) {
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        double ratio = 1.0;  // C(r, j) / C(m - 1, j), from j = 0
        for (int j = 0; j <= r; ++j) {
          sum += ratio * d.row(j);
          ratio *= static_cast<double>(r - j) / static_cast<double>(m - 1 - j);
        }
        bound2 = std::max(bound2, sum.squaredNorm());
      }
      if (bound2 * (1.0 + kHullRounding) <= peak2[k - 1]) continue;
      // |d(u)|^2 = sum_q f_q u^q (degree 2m - 2); its interior extrema are the roots of
      // g = d/du |d|^2 (degree 2m - 3 <= kMaxPeakDegree).
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPeakDegree + 2, 1> f =
          Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPeakDegree + 2, 1>::Zero(2 * m - 1);
      for (int p = 0; p < m; ++p)
        for (int q = 0; q < m; ++q) f[p + q] += d.row(p).dot(d.row(q));
      const Eigen::Index degree = f.size() - 2;
      PeakPolynomial g(degree + 1), b(degree + 1);
      for (Eigen::Index q = 0; q <= degree; ++q) g[q] = static_cast<double>(q + 1) * f[q + 1];
      // Bernstein coefficients on [0, 1]: b_r = sum_{q <= r} C(r, q) / C(degree, q) g_q.
      for (Eigen::Index r = 0; r <= degree; ++r) {
        double sum = 0.0, ratio = 1.0;  // C(r, q) / C(degree, q), from q = 0
        for (Eigen::Index q = 0; q <= r; ++q) {
          sum += ratio * g[q];
          ratio *= static_cast<double>(r - q) / static_cast<double>(degree - q);
        }
        b[r] = sum;
      }
      roots.clear();
      isolate_roots(g, b, 0.0, 1.0, 0, roots);
      for (const double u : roots) peak2[k - 1] = std::max(peak2[k - 1], norm2(d, m, u));
    }
  return {std::sqrt(peak2[0]), std::sqrt(peak2[1])};
}

namespace {

using Clock = std::chrono::steady_clock;

/// A stretch that lands exactly on a limit can exceed it by rounding; stretch this much more.
constexpr double kStretchSlack = 1e-9;
/// A stretch lands on the limit up to rounding; a few rounds absorb that.
constexpr int kMaxStretchRounds = 8;
/// The optimiser stays within this factor of the trapezoid's durations (either way): beyond
/// it the answer check would refuse the spread anyway (REQ-TRAJ-010).
constexpr double kMaxDurationRatio = 1e3;
/// Step of the forward differences in tau = log T where a limit is active.
constexpr double kDifferenceStep = 1e-7;
/// Where a limit is active F has kinks (the peak moves from one sample to another), where
/// L-BFGS can stop short; a coordinate pattern search in tau then finishes, with these
/// steps, so that at the answer no single duration scaled by exp(+-kPolishSteps.back())
/// lowers F: the first-order condition of a piecewise smooth F along the coordinates.
constexpr double kPolishSteps[] = {0.1, 0.03, 0.01, 3e-3, 1e-3};
/// Rounds of Ceres + pattern search (each from the previous round's answer).
constexpr int kRounds = 8;
/// Sweeps of the pattern search per step size (each sweep M x 2 evaluations).
constexpr int kPolishSweeps = 50;

struct Evaluation {
  double F = 0.0, k = 1.0, J = 0.0, total = 0.0;
  double v = 0.0, a = 0.0;
  MincoProblem problem;  ///< with the feasible durations
  PolynomialTrajectory trajectory;
};

/// Solves at T, stretches until the exact peaks (exact_extremes) are within the limits, and
/// evaluates F.
bool evaluate_or_throw(const MincoProblem& base, const std::vector<double>& T, const AllocationOptions& o,
                       MincoSolver& solver, Evaluation& e);

/// evaluate_or_throw, false where the curve overflows: the trajectory's values and cost throw
/// rather than return inf (seventeenth campaign F16), and no exception may cross Ceres, which
/// calls this for every trial point.
bool evaluate(const MincoProblem& base, const std::vector<double>& T, const AllocationOptions& o, MincoSolver& solver,
              Evaluation& e) {
  try {
    return evaluate_or_throw(base, T, o, solver, e);
  } catch (const Error&) {
    return false;
  }
}

bool evaluate_or_throw(const MincoProblem& base, const std::vector<double>& T, const AllocationOptions& o,
                       MincoSolver& solver, Evaluation& e) {
  e.problem = base;
  e.problem.durations = T;
  e.k = 1.0;
  for (int round = 0;; ++round) {
    solver.solve(e.problem, e.trajectory);
    if (!e.trajectory.coefficients().allFinite()) return false;
    std::tie(e.v, e.a) = exact_extremes(e.trajectory);
    const double need = std::max({1.0, e.v / o.limits.v_max, std::sqrt(e.a / o.limits.a_max)});
    if (need <= 1.0) break;
    if (round == kMaxStretchRounds) return false;
    // Rest to rest, one stretch lands on the limit (the optimum for k T is the stretched
    // curve); the next round only absorbs rounding.
    const double k = need * (1.0 + kStretchSlack);
    e.k *= k;
    for (double& d : e.problem.durations) d *= k;
  }
  // J from the trajectory's own coefficients, what the answer's "cost" says: MINCO's Hermite
  // form x^T Q x cancels for short segments of order 4 (session 32: -7.0 for a true 0.075).
  e.J = e.trajectory.cost();
  if (!(e.J >= 0.0)) return false;
  e.total = 0.0;
  for (double d : e.problem.durations) e.total += d;
  e.F = e.J + o.rho * e.total;
  return std::isfinite(e.F);
}

/// F(tau) for Ceres, tau_i = log T_i.
class AllocationObjective : public ceres::FirstOrderFunction {
 public:
  /// `scale` multiplies F and its gradient: optimise_allocation() hands Ceres F / F(start), so
  /// its first step in tau is O(1) whatever J's magnitude (session 32: with J ~ 3e5 the first
  /// L-BFGS step moved tau by ~1e5 and the line search settled 100x past the optimum).
  AllocationObjective(const MincoProblem& base, const AllocationOptions& o, std::vector<double> start, double scale = 1.0)
      : base_(base), o_(o), start_(std::move(start)), scale_(scale) {}
  int NumParameters() const override { return static_cast<int>(start_.size()); }

  bool Evaluate(const double* tau, double* cost, double* gradient) const override {
    const std::size_t M = start_.size();
    std::vector<double> T(M);
    for (std::size_t i = 0; i < M; ++i) {
      T[i] = std::exp(tau[i]);
      const double ratio = T[i] / start_[i];
      if (!(ratio <= kMaxDurationRatio && ratio >= 1.0 / kMaxDurationRatio)) return false;
    }
    Evaluation e;
    if (!evaluate(base_, T, o_, solver_, e)) return false;
    *cost = e.F * scale_;
    if (!gradient) return true;
    if (e.k == 1.0) {
      MincoGradients g;
      solver_.cost_and_gradients(e.problem, &g);
      for (std::size_t i = 0; i < M; ++i)
        gradient[i] = (g.durations[static_cast<Eigen::Index>(i)] + o_.rho) * T[i] * scale_;
      return true;
    }
    // A limit is active: F = J(k T) + rho k sum T with k depending on T; forward differences
    // (M evaluations: F is kinked there anyway, and the pattern search finishes).
    for (std::size_t i = 0; i < M; ++i) {
      Evaluation plus;
      std::vector<double> Tp = T;
      Tp[i] = std::exp(tau[i] + kDifferenceStep);
      if (!evaluate(base_, Tp, o_, solver_, plus)) return false;
      gradient[i] = (plus.F - e.F) / kDifferenceStep * scale_;
    }
    return true;
  }

 private:
  const MincoProblem& base_;
  const AllocationOptions& o_;
  std::vector<double> start_;
  double scale_;
  mutable MincoSolver solver_;
};

/// A number as %g writes it (std::to_string would print 1e-300 as 0.000000).
std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void validate(const AllocationOptions& o) {
  validate(o.limits);
  if (!std::isfinite(o.rho) || !(o.rho > 0.0)) throw Error("rho: must be positive and finite, got " + exact_number(o.rho));
  if (o.max_iterations < 1 || o.max_iterations > kMaxAllocationIterations)
    throw Error("allocation iterations: must be in [1, " + std::to_string(kMaxAllocationIterations) + "], got " +
                std::to_string(o.max_iterations));
}

}  // namespace

std::pair<double, double> feasible_objective(const MincoProblem& problem, const std::vector<double>& durations,
                                             const AllocationOptions& options) {
  validate(options);
  {  // the problem with these durations is a valid one (tenth campaign L17: 1 for 2 segments)
    MincoProblem with = problem;
    with.durations = durations;
    validate(with);
  }
  MincoSolver solver;
  Evaluation e;
  if (!evaluate(problem, durations, options, solver, e))
    throw Error("allocation: the objective is not finite for these durations");
  return {e.F, e.k};
}

std::pair<double, std::vector<double>> log_time_objective(const MincoProblem& problem, const std::vector<double>& tau,
                                                          const AllocationOptions& options) {
  validate(options);
  std::vector<double> start(tau.size());
  for (std::size_t i = 0; i < tau.size(); ++i) start[i] = std::exp(tau[i]);
  {  // durations exp(tau) of a valid problem (tenth campaign L17: 3 for 2 segments)
    MincoProblem with = problem;
    with.durations = start;
    validate(with);
  }
  const AllocationObjective objective(problem, options, start);
  double F = 0.0;
  std::vector<double> gradient(tau.size());
  if (!objective.Evaluate(tau.data(), &F, gradient.data()))
    throw Error("allocation: the objective is not finite for these durations");
  return {F, gradient};
}

AllocationResult optimise_allocation(const MincoProblem& problem, const AllocationOptions& o) {
  validate(o);
  const auto segments = problem.points.rows() - 1;
  if (segments > kMaxOptimisedSegments)
    throw Error("allocation: \"optimise\" takes at most " + std::to_string(kMaxOptimisedSegments) +
                " segments (its work grows as the square of the count), this problem has " + std::to_string(segments) +
                ": use \"trapezoid\" or split the path");
  if (!problem.head.bottomRows(problem.order - 1).isZero(0.0) || !problem.tail.bottomRows(problem.order - 1).isZero(0.0))
    throw Error("allocation: \"optimise\" needs a problem at rest at both ends (head and tail derivatives 1..s-1 "
                "zero): the limits are kept by stretching time, and with moving ends a longer trajectory can need "
                "more speed, not less; give \"durations\" instead");
  const auto t0 = Clock::now();
  MincoProblem base = problem;
  base.durations = trapezoidal_allocation(problem.points, o.limits);
  validate(base);
  MincoSolver solver;
  Evaluation start;
  if (!evaluate(base, base.durations, o, solver, start))
    throw Error("allocation: the trapezoidal durations cannot be stretched to meet the limits (v_max " +
                short_number(o.limits.v_max) + " m/s, a_max " + short_number(o.limits.a_max) +
                " m/s^2): the trajectory is beyond double precision at these limits");

  // A second start, the trapezoid stretched in time to F's minimum along that ray: J(k T) =
  // J(T) / k^(2s-1) for a rest-to-rest curve, so F(k) = J / k^(2s-1) + rho k sum T is least at
  // k^(2s) = (2s-1) J / (rho sum T). Only a stretch (k > 1: peaks fall, limits hold). Where the
  // limits are loose and the legs short the trapezoid is orders of magnitude too fast, its J
  // beyond what Ceres can start from (seventeenth campaign F23: waypoints 1 mm apart at v_max =
  // a_max = 1e6 returned F = 1.8e6 where uniform 0.5 s durations give 7.5). The search then
  // runs around whichever start has the lower F.
  Evaluation origin = start;
  {
    const int s = problem.order;
    const double k = std::pow((2.0 * s - 1.0) * start.J / (o.rho * start.total), 1.0 / (2.0 * s));
    if (std::isfinite(k) && k > 1.0) {
      std::vector<double> stretched = start.problem.durations;
      for (double& d : stretched) d *= k;
      Evaluation e;
      if (evaluate(base, stretched, o, solver, e) && e.F < start.F) {
        origin = std::move(e);
        base.durations = origin.problem.durations;  // the search's box is centred there
      }
    }
  }

  const std::size_t M = base.durations.size();
  std::vector<double> tau(M);
  for (std::size_t i = 0; i < M; ++i) tau[i] = std::log(base.durations[i]);
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  options.max_num_iterations = o.max_iterations;
  options.logging_type = ceres::SILENT;
  // Tight: F is cheap (microseconds), and the answer should be stationary to the gradient's
  // own precision where no limit is active (REQ-TRAJ-011), not to Ceres' default 1e-6.
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-14;
  options.minimizer_progress_to_stdout = false;
  // Ceres, then the pattern search, in rounds: where a limit is active F is flat along the
  // stretch and has kinks, and L-BFGS can settle in a valley the search's coarser steps leave;
  // Ceres then converges from where the search got to. Stop when a round gains nothing.
  ceres::GradientProblemSolver::Summary summary;
  int ceres_iterations = 0, polish = 0;
  const auto log_of = [&](const Evaluation& e) {
    for (std::size_t i = 0; i < M; ++i) tau[i] = std::log(e.problem.durations[i]);
  };
  std::vector<double> T(M);
  // Two passes from the trapezoid, the better answer kept: F as it is, and F / F(start)
  // (session 32: where J is large the raw F's first L-BFGS step leapt ~1e5 in tau and the search
  // settled at 100x the optimum's F; the normalised F can stop short of a limit-active optimum).
  Evaluation overall = origin;
  for (const double scale : {1.0, 1.0 / origin.F}) {
  ceres::GradientProblem gp(new AllocationObjective(base, o, base.durations, scale));
  Evaluation best = origin;
  for (int round = 0; round < kRounds; ++round) {
    const double before = best.F;
    log_of(best);
    ceres::Solve(options, gp, tau.data(), &summary);
    ceres_iterations += static_cast<int>(summary.iterations.size());
    // Ceres cannot start where its objective declines the point: a best answer whose stretched
    // durations lie past kMaxDurationRatio of the trapezoid, or a start whose forward-difference
    // gradient fails at a huge stretch (thirteenth campaign C3: a 1 m leg then a 1 km leg,
    // stretch 7441, was refused as "beyond double precision"). The start itself evaluated (else
    // the refusal above), so the pattern search, which needs no gradient, goes on from the best
    // point; nothing is refused here.
    const bool no_start = summary.termination_type == ceres::FAILURE &&
                          summary.message.rfind("Initial cost and jacobian evaluation failed", 0) == 0;
    if (!no_start) {
      for (std::size_t i = 0; i < M; ++i) T[i] = std::exp(tau[i]);
      Evaluation e;
      if (evaluate(base, T, o, solver, e) && e.F < best.F) best = std::move(e);  // never worse than before
    }
    // Pattern search (see kPolishSteps) over the feasible durations themselves: after each
    // accepted step tau is the log of the stretched durations, so the answer is a point
    // where F's own coordinate steps were tried.
    log_of(best);
    for (const double h : kPolishSteps)
      for (int sweep = 0; sweep < kPolishSweeps; ++sweep) {
        bool improved = false;
        for (std::size_t i = 0; i < M; ++i)
          for (const double step : {h, -h}) {
            std::vector<double> trial = tau;
            trial[i] += step;
            // Within kMaxDurationRatio of the trapezoid, or back toward it: a stretched answer
            // may lie past the box, and a step inward is tried (thirteenth campaign C2: an
            // answer 1193x its trapezoid was never shortened, and shortening lowered F).
            const double out = std::abs(trial[i] - std::log(base.durations[i])) - std::log(kMaxDurationRatio);
            if (out > 0.0 && out >= std::abs(tau[i] - std::log(base.durations[i])) - std::log(kMaxDurationRatio)) continue;
            for (std::size_t j = 0; j < M; ++j) T[j] = std::exp(trial[j]);
            Evaluation p;
            ++polish;
            if (evaluate(base, T, o, solver, p) && p.F < best.F) {
              best = std::move(p);
              log_of(best);
              improved = true;
            }
          }
        if (!improved) break;
      }
    if (!(best.F < before)) break;
  }
  if (best.F < overall.F) overall = std::move(best);
  }
  Evaluation& best = overall;

  AllocationResult r;
  r.durations = best.problem.durations;
  r.trajectory = best.trajectory;
  polish_waypoints(best.problem, r.trajectory);
  check_answer(best.problem, r.trajectory);
  // What the answer says of itself is measured on the polished curve it returns: its cost is
  // the answer file's "cost" (the polish moves J by up to ~1e-6 of it on ill-conditioned
  // problems), its peaks are the ones a reader would find.
  r.cost = r.trajectory.cost();
  r.total_time = best.total;
  r.objective = r.cost + o.rho * r.total_time;
  r.start_objective = start.F;
  r.start_scale = start.k;
  std::tie(r.max_speed, r.max_acceleration) = exact_extremes(r.trajectory);
  if (!(r.cost >= 0.0 && std::isfinite(r.objective) && r.max_speed <= o.limits.v_max && r.max_acceleration <= o.limits.a_max))
    throw Error("allocation: the answer's polished curve has cost " + short_number(r.cost) + " and peaks " +
                short_number(r.max_speed) + " m/s, " + short_number(r.max_acceleration) +
                " m/s^2 against the limits (v_max " + short_number(o.limits.v_max) + ", a_max " +
                short_number(o.limits.a_max) + "): not answered");
  r.iterations = ceres_iterations;
  r.polish_evaluations = polish;
  r.termination = summary.message;
  r.solve_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return r;
}

std::pair<double, double> trajectory_extremes(const traj::PolynomialTrajectory& t, double step) {
  // Tenth campaign L13: a step of 0, -1, NaN or 1e-300 was silently replaced by one sample per
  // segment; the count is bounded before any evaluation.
  if (!(std::isfinite(step) && step > 0.0)) throw Error("step: must be a positive finite time in s, got " + exact_number(step));
  t.check_consistent("trajectory_extremes");
  if (!t.coefficients().allFinite()) throw Error("trajectory_extremes: the trajectory's coefficients must be finite numbers");
  double count = 0.0;
  for (const double T : t.durations()) count += std::ceil(T / step) + 1.0;
  if (!(count <= kMaxExtremeSamples))
    throw Error("step: " + short_number(step) + " s over " + short_number(t.total_duration()) + " s would take " +
                short_number(count) + " samples, more than the " + short_number(kMaxExtremeSamples) + " allowed: use a longer step");
  double v = 0.0, a = 0.0;
  for (int i = 0; i < t.segments(); ++i) {
    const double T = t.durations()[static_cast<std::size_t>(i)];
    const int n = std::max(1, static_cast<int>(std::ceil(T / step)));
    for (int k = 0; k <= n; ++k) {
      const double tau = T * k / n;
      v = std::max(v, t.evaluate_segment(i, tau, 1).norm());
      a = std::max(a, t.evaluate_segment(i, tau, 2).norm());
    }
  }
  return {v, a};
}

}  // namespace miner::traj
