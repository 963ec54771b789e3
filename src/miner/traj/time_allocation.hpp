#pragma once
/// \file
/// Optimised time allocation (REQ-TRAJ-011): the segment durations T that minimise
///   F(T) = J*(T) + rho * sum_i T_i        subject to  max |v| <= v_max, max |a| <= a_max,
/// J* the MINCO optimum for those durations (paper Eq. (minco1)), solved with Ceres' line
/// search (L-BFGS) over tau_i = log T_i (so T stays positive), from the trapezoidal
/// allocation. The limits are kept by construction: every T the solver tries is first made
/// feasible by the time scale k(T) = max(1, v_peak / v_max, sqrt(a_peak / a_max)) (stretching
/// time by k divides speeds by k and accelerations by k^2 and keeps the MINCO optimum of a
/// rest-to-rest problem), and F is evaluated at k T. Rest-to-rest problems only: with moving
/// ends a longer trajectory can need more speed (a head acceleration held longer), so
/// stretching is no way to the limits; such problems are refused. Where k = 1 the gradient is
/// MINCO's own dJ*/dT (envelope theorem, MincoSolver::cost_and_gradients):
///   dF/dtau_i = (dJ*/dT_i + rho) T_i;
/// where a limit is active (k > 1) it is taken by central differences of F in tau, and since F
/// has kinks there (the binding peak jumps from one segment or instant to another) a coordinate pattern search in
/// tau finishes: at the answer no single duration scaled by exp(+-1e-3) lowers F. The answer
/// is never worse than the start: Ceres and the search accept only decreasing steps, and a
/// guard keeps the (feasible) trapezoid otherwise.

#include <string>
#include <utility>
#include <vector>

#include "miner/traj/minco.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

namespace miner::traj {

/// Re-times t to run k times slower: p'(t) = p(t / k), so durations scale by k, velocities by
/// 1/k and accelerations by 1/k^2 (coefficient j divided by k^j). For a rest-to-rest MINCO
/// solution this is again the optimum for the scaled durations.
void scale_time(PolynomialTrajectory& t, double k);

/// The most instants trajectory_extremes evaluates (10^7: ~1 s; a 1000 s flight at the
/// pipeline's 1 ms step is 10^6).
inline constexpr double kMaxExtremeSamples = 1e7;

/// Largest speed and acceleration of t exactly (to rounding): per segment, in u = t / T, the
/// larger of |p^(k)(u)|^2 at u = 0, u = 1 and at every root in (0, 1) of
/// g(u) = d/du |p^(k)(u)|^2 (degree 2(2s - k) - 3 <= 11 for order s <= 4). The roots are
/// isolated on g's Bernstein coefficients (their sign changes bound the roots in an interval:
/// none, exactly one, or halve it by de Casteljau) and each found by Newton steps inside its
/// bracket (to 1e-12 in u, where the value is flat). Every segment's ends are read first, and
/// a segment whose Bernstein hull bound (the largest |b_r| of p^(k)'s Bernstein coefficients)
/// is not above the peak found so far is passed over. The optimiser's limit check: samples
/// step over narrow peaks (twelfth campaign L1: 2.0009 m/s under v_max 2 between two of 33
/// samples) and a search around the largest sample misses an interior peak above an end sample
/// (tenth held-out audit: 3.0 for a true 3.322).
std::pair<double, double> exact_extremes(const PolynomialTrajectory& t);
/// Degree of g above for order 4 and k = 1: 2 * 7 - 3.
inline constexpr int kMaxPeakDegree = 11;
/// Halvings of [0, 1] before an interval whose g still shows two or more sign changes is taken
/// as one root at its midpoint (a double root of g: an inflection of |p^(k)|, 2^-40 wide).
inline constexpr int kMaxPeakBisections = 40;
/// Newton / bisection steps for one bracketed root (bisection alone needs 53 to reach rounding).
inline constexpr int kMaxRootIterations = 64;
/// Maximum speed and acceleration of a trajectory, sampled every `step` seconds and at every
/// segment end (the flight envelope's dense check). Throws miner::Error for a step that is not
/// positive and finite or that needs more than kMaxExtremeSamples instants.
std::pair<double, double> trajectory_extremes(const PolynomialTrajectory& t, double step);

struct AllocationOptions {
  double rho = 1.0;           ///< weight of the total time in F (cost units per second)
  Limits limits;
  int max_iterations = 100;   ///< Ceres line-search iterations per round, in [1, kMaxAllocationIterations]
};

/// The most Ceres iterations a round may take: each is a MINCO solve and an exact limit check,
/// and the default converges in tens; INT_MAX was accepted and bounded only by convergence
/// (tenth campaign recheck).
inline constexpr int kMaxAllocationIterations = 10000;

struct AllocationResult {
  std::vector<double> durations;          ///< the optimised, feasible durations
  PolynomialTrajectory trajectory;        ///< MINCO for them
  double objective = 0.0;                 ///< F at the answer
  double cost = 0.0, total_time = 0.0;    ///< J* and sum T there
  double start_objective = 0.0;           ///< F at the (feasible) trapezoid, where Ceres starts
  double start_scale = 1.0;               ///< k the trapezoid needed to meet the limits
  double max_speed = 0.0, max_acceleration = 0.0;  ///< exact (exact_extremes), at the answer
  int iterations = 0;                     ///< Ceres iterations
  int polish_evaluations = 0;             ///< objective evaluations of the pattern search
  std::string termination;                ///< Ceres' message
  double solve_ms = 0.0;
};

/// The most segments optimise_allocation() takes: its pattern search costs O(M) MINCO solves
/// of O(M) each per sweep, so work grows as M^2 (100 segments: ~7 s, 400: > 5 min here;
/// issue 20; with exact peaks and two passes, 24-64 segments take 3-15 s on a shared 2-core VM,
/// thirteenth campaign C4). Planner paths have 10-30 segments; longer ones keep the trapezoid
/// or are split.
inline constexpr int kMaxOptimisedSegments = 64;

/// Throws miner::Error for a bad problem (validate()), moving ends, bad limits, rho <= 0 or
/// not finite, or more than kMaxOptimisedSegments segments. `problem.durations` are ignored: the start is the
/// trapezoid.
AllocationResult optimise_allocation(const MincoProblem& problem, const AllocationOptions& options);

/// F at durations T made feasible, as the optimiser sees it (exposed for tests):
/// (F, the time scale k applied).
std::pair<double, double> feasible_objective(const MincoProblem& problem, const std::vector<double>& durations,
                                             const AllocationOptions& options);

/// F and its gradient in the variables Ceres sees, tau_i = log T_i, exactly as
/// optimise_allocation()'s objective hands them to Ceres (exposed for tests): F at exp(tau)
/// made feasible, and dF/dtau_i = (dJ*/dT_i + rho) T_i where no limit is active (forward
/// differences where one is). Throws miner::Error for bad options or where the objective
/// tells Ceres the point cannot be evaluated.
std::pair<double, std::vector<double>> log_time_objective(const MincoProblem& problem, const std::vector<double>& tau,
                                                          const AllocationOptions& options);

}  // namespace miner::traj
