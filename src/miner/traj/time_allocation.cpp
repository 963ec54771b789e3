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
    if (!std::isfinite(d * k)) throw Error("scale_time: k = " + short_number(k) + " makes a duration infinite");
  auto& c = t.mutable_coefficients();
  const int n = 2 * t.order();
  for (int i = 0; i < t.segments(); ++i) {
    double kj = 1.0;
    for (int j = 0; j < n; ++j, kj *= k) c.row(n * i + j) /= kj;
  }
  for (double& d : t.mutable_durations()) d *= k;
}

std::pair<double, double> sampled_extremes(const PolynomialTrajectory& t, int samples) {
  // Tenth campaign L13: INT_MAX samples ran for ever, 0 and -1 answered garbage (a peak speed
  // of 241 m/s on a 4.6 m/s trajectory).
  if (samples < 1 || samples > kMaxSamplesPerSegment)
    throw Error("samples: must be in [1, " + std::to_string(kMaxSamplesPerSegment) + "] per segment, got " + std::to_string(samples));
  check_order(t.order(), "sampled_extremes");
  const int n = 2 * t.order();
  double v2 = 0.0, a2 = 0.0;
  Eigen::Matrix<double, 8, 3> dv, da;  // velocity and acceleration coefficients (n <= 8)
  for (int i = 0; i < t.segments(); ++i) {
    const auto c = t.segment_coefficients(i);
    for (int j = 0; j + 1 < n; ++j) dv.row(j) = (j + 1) * c.row(j + 1);
    for (int j = 0; j + 2 < n; ++j) da.row(j) = (j + 2) * (j + 1) * c.row(j + 2);
    // |p^(k)(tau)|^2 by Horner on the derivative's coefficients.
    const auto norm2 = [](const Eigen::Matrix<double, 8, 3>& d, int m, double tau) {
      Eigen::RowVector3d x = d.row(m - 1);
      for (int j = m - 2; j >= 0; --j) x = x * tau + d.row(j);
      return x.squaredNorm();
    };
    const double T = t.durations()[static_cast<std::size_t>(i)];
    const double h = T / samples;
    for (auto [d, m, best] : {std::tuple{&dv, n - 1, &v2}, std::tuple{&da, n - 2, &a2}}) {
      int arg = 0;
      double top = -1.0;
      for (int k = 0; k <= samples; ++k) {
        const double x = norm2(*d, m, k * h);
        if (x > top) top = x, arg = k;
      }
      // The samples bracket the segment's largest peak within one step either side; a
      // golden-section search there finds it to 1e-9 of the step (a polynomial of degree
      // <= 14 is unimodal that close to its maximum for the orders used here).
      double lo = std::max(0.0, (arg - 1) * h), hi = std::min(T, (arg + 1) * h);
      constexpr double kGolden = 0.6180339887498949;
      double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
      double f1 = norm2(*d, m, x1), f2 = norm2(*d, m, x2);
      for (int it = 0; it < 45; ++it) {
        if (f1 < f2) lo = x1, x1 = x2, f1 = f2, x2 = lo + kGolden * (hi - lo), f2 = norm2(*d, m, x2);
        else hi = x2, x2 = x1, f2 = f1, x1 = hi - kGolden * (hi - lo), f1 = norm2(*d, m, x1);
      }
      *best = std::max({*best, top, f1, f2});
    }
  }
  return {std::sqrt(v2), std::sqrt(a2)};
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

/// Solves at T, stretches until the sampled peaks are within the limits, and evaluates F.
bool evaluate(const MincoProblem& base, const std::vector<double>& T, const AllocationOptions& o, MincoSolver& solver,
              Evaluation& e) {
  e.problem = base;
  e.problem.durations = T;
  e.k = 1.0;
  for (int round = 0;; ++round) {
    solver.solve(e.problem, e.trajectory);
    if (!e.trajectory.coefficients().allFinite()) return false;
    std::tie(e.v, e.a) = sampled_extremes(e.trajectory, o.samples_per_segment);
    const double need = std::max({1.0, e.v / o.limits.v_max, std::sqrt(e.a / o.limits.a_max)});
    if (need <= 1.0) break;
    if (round == kMaxStretchRounds) return false;
    // Rest to rest, one stretch lands on the limit (the optimum for k T is the stretched
    // curve); the next round only absorbs rounding.
    const double k = need * (1.0 + kStretchSlack);
    e.k *= k;
    for (double& d : e.problem.durations) d *= k;
  }
  e.J = solver.cost_and_gradients(e.problem, nullptr);
  e.total = 0.0;
  for (double d : e.problem.durations) e.total += d;
  e.F = e.J + o.rho * e.total;
  return std::isfinite(e.F);
}

/// F(tau) for Ceres, tau_i = log T_i.
class AllocationObjective : public ceres::FirstOrderFunction {
 public:
  AllocationObjective(const MincoProblem& base, const AllocationOptions& o, std::vector<double> start)
      : base_(base), o_(o), start_(std::move(start)) {}
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
    *cost = e.F;
    if (!gradient) return true;
    if (e.k == 1.0) {
      MincoGradients g;
      solver_.cost_and_gradients(e.problem, &g);
      for (std::size_t i = 0; i < M; ++i) gradient[i] = (g.durations[static_cast<Eigen::Index>(i)] + o_.rho) * T[i];
      return true;
    }
    // A limit is active: F = J(k T) + rho k sum T with k depending on T; forward differences
    // (M evaluations: F is kinked there anyway, and the pattern search finishes).
    for (std::size_t i = 0; i < M; ++i) {
      Evaluation plus;
      std::vector<double> Tp = T;
      Tp[i] = std::exp(tau[i] + kDifferenceStep);
      if (!evaluate(base_, Tp, o_, solver_, plus)) return false;
      gradient[i] = (plus.F - e.F) / kDifferenceStep;
    }
    return true;
  }

 private:
  const MincoProblem& base_;
  const AllocationOptions& o_;
  std::vector<double> start_;
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
  if (!std::isfinite(o.rho) || !(o.rho > 0.0)) throw Error("rho: must be positive and finite, got " + short_number(o.rho));
  if (o.samples_per_segment < 2 || o.samples_per_segment > kMaxSamplesPerSegment)
    throw Error("samples per segment: must be in [2, " + std::to_string(kMaxSamplesPerSegment) + "], got " +
                std::to_string(o.samples_per_segment));
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

  const std::size_t M = base.durations.size();
  std::vector<double> tau(M);
  for (std::size_t i = 0; i < M; ++i) tau[i] = std::log(base.durations[i]);
  ceres::GradientProblem gp(new AllocationObjective(base, o, base.durations));
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
  Evaluation best = start;
  ceres::GradientProblemSolver::Summary summary;
  int ceres_iterations = 0, polish = 0;
  const auto log_of = [&](const Evaluation& e) {
    for (std::size_t i = 0; i < M; ++i) tau[i] = std::log(e.problem.durations[i]);
  };
  std::vector<double> T(M);
  for (int round = 0; round < kRounds; ++round) {
    const double before = best.F;
    log_of(best);
    ceres::Solve(options, gp, tau.data(), &summary);
    ceres_iterations += static_cast<int>(summary.iterations.size());
    // The objective or its gradient not finite where Ceres starts: the problem lies outside
    // what double precision can optimise (issue 20, fifth campaign: rho 1e9 with limits 1e6
    // gave an 81 s segment, "Initial cost and jacobian evaluation failed", and exit 0).
    // The legs' lengths are named too: a 1e6 m leg was blamed on rho and the limits alone
    // (seventh campaign C9).
    if (summary.termination_type == ceres::FAILURE &&
        summary.message.rfind("Initial cost and jacobian evaluation failed", 0) == 0) {
      double longest = 0.0;
      for (Eigen::Index i = 0; i + 1 < problem.points.rows(); ++i)
        longest = std::max(longest, (problem.points.row(i + 1) - problem.points.row(i)).norm());
      throw Error("allocation: the optimiser could not evaluate the objective J + rho sum T or its gradient at the "
                  "start (Ceres: " + summary.message + "): rho " + short_number(o.rho) + ", the limits (v_max " +
                  short_number(o.limits.v_max) + ", a_max " + short_number(o.limits.a_max) + ") and legs up to " +
                  short_number(longest) + " m long put it beyond double precision; use a smaller rho, tighter limits "
                  "or shorter legs, or give durations");
    }
    for (std::size_t i = 0; i < M; ++i) T[i] = std::exp(tau[i]);
    Evaluation e;
    if (evaluate(base, T, o, solver, e) && e.F < best.F) best = std::move(e);  // never worse than before
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
            if (std::abs(trial[i] - std::log(base.durations[i])) > std::log(kMaxDurationRatio)) continue;
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

  AllocationResult r;
  r.durations = best.problem.durations;
  r.trajectory = best.trajectory;
  polish_waypoints(best.problem, r.trajectory);
  check_answer(best.problem, r.trajectory);
  r.objective = best.F;
  r.cost = best.J;
  r.total_time = best.total;
  r.start_objective = start.F;
  r.start_scale = start.k;
  r.max_speed = best.v;
  r.max_acceleration = best.a;
  r.iterations = ceres_iterations;
  r.polish_evaluations = polish;
  r.termination = summary.message;
  r.solve_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return r;
}

std::pair<double, double> trajectory_extremes(const traj::PolynomialTrajectory& t, double step) {
  // Tenth campaign L13: a step of 0, -1, NaN or 1e-300 was silently replaced by one sample per
  // segment; the count is bounded before any evaluation.
  if (!(std::isfinite(step) && step > 0.0)) throw Error("step: must be a positive finite time in s, got " + short_number(step));
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
