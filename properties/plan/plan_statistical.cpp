// Statistical properties of the front end (label `statistical`): fixed seeds, budgets in
// iterations, pass thresholds from an exact binomial calculation (REQ-HARNESS-005).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bench/frontend_bench.hpp"
#include "bench/ompl_planners.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/testing/binomial.hpp"
#include "miner/testing/door_maps.hpp"
#include "miner/world/map.hpp"
#include "miner/world/map_generator.hpp"

using miner::plan::HeuristicRegion;
using miner::plan::PlannerKind;
using miner::plan::PlannerOptions;
using miner::plan::PlanningProblem;
using miner::plan::PlanResult;
using miner::testing::BinomialTest;
using miner::testing::kFalseFailRate;
using miner::testing::min_successes;
using miner::testing::seed_for_set;
using miner::testing::seed_set;
using miner::testing::size_binomial_test;
using V = Eigen::Vector3d;
using I = Eigen::Vector3i;

namespace {

using miner::testing::wall_with_door_map;
const V kStart(1, 1, 0.5), kGoal(9, 1, 0.5);

/// The optimum of wall_with_door_map() (door y in [7.5, 9], z in [0, 1.5]) for a point
/// robot from kStart to kGoal. A path must cross the planes x = 4 and x = 5 inside the
/// door; projecting it onto z = 0.5 (where both ends lie, inside the door's z range)
/// shortens no segment, so its length is at least
/// min over y1, y2 in [7.5, 9] of |(3, y1 - 1)| + |(1, y2 - y1)| + |(4, y2 - 1)|, which
/// increases in y1 and y2 there: the bound is attained at y1 = y2 = 7.5 (the door's
/// corner edge), so it is the optimum c* itself.
double door_optimum() { return std::hypot(3.0, 6.5) + 1.0 + std::hypot(4.0, 6.5); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

/// An adversarial H on wall_with_door_map(): the start's side of the wall away from the
/// door (x in [0, 4), y in [0, 5)); it holds no path to the goal.
HeuristicRegion adversarial_door_region(const miner::world::Map& map) {
  std::vector<double> p(10 * 10 * 3, 0.0);
  const HeuristicRegion grid(map.bounds(), I(10, 10, 3), p, 0.5);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 4; ++i) p[grid.index(i, j, k)] = 1.0;
  return HeuristicRegion(map.bounds(), I(10, 10, 3), p, 0.5, "adversarial");
}

/// The test sized by power for H0 "success rate >= p0" against H1 "<= p1" (false fail <= 1e-6,
/// miss <= 1e-3, exact binomial), reported with the test's outcome.
BinomialTest sized(double p0, double p1) {
  const BinomialTest t = size_binomial_test(p0, p1);
  UNSCOPED_INFO("H0: rate >= " << p0 << ", H1: rate <= " << p1 << ": n " << t.n << ", pass at >= " << t.k
                               << " (false fail " << t.false_fail << ", miss " << t.miss << "), seed set "
                               << seed_set());
  return t;
}

}  // namespace

TEST_CASE("Lemma 1: miner with a region that holds no path still solves within K iterations", "[REQ-PLAN-012]") {
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  // Adversarial H: no path to the goal, yet mu_2 = 0.9 sends up to 90 % of samples there.
  const HeuristicRegion region = adversarial_door_region(map);
  REQUIRE_FALSE(region.contains(V(4.5, 8, 0.5)));  // not the door
  REQUIRE_FALSE(region.contains(kGoal));

  // Calibration (2000 trials, seed 12345, streams 0..1999, no budget limit): first
  // solution after median 940, p99 6024, p99.9 11824, max 12177 iterations, no failure.
  // The tail decays ~10x per 5800 iterations, so at K = 20000 the failure rate is
  // ~1e-4 and H0 (p0 = 0.999) is conservative. H1: a planner that solves only 90 % of the
  // queries within K (e.g. mu_2 = 1, never uniform) must fail: n = 143, k = 139.
  const BinomialTest test = sized(0.999, 0.9);
  const int n = test.n, k = test.k;
  const std::size_t K = 20000;
  int solved = 0;
  std::vector<double> iterations;
  for (int trial = 0; trial < n; ++trial) {
    PlannerOptions o;
    o.planner = PlannerKind::kMiner;
    o.seed = seed_for_set(20261122, seed_set());
    o.stream = static_cast<std::uint64_t>(trial);
    o.max_iterations = K;
    o.stop_at_first = true;
    const PlanResult r = miner::plan::plan(problem, o, &region);
    solved += r.solved;
    if (r.first) iterations.push_back(static_cast<double>(r.first->iteration));
  }
  INFO("solved " << solved << " of " << n << " (need " << k << "), median first iteration "
                 << (iterations.empty() ? 0.0 : median(iterations)));
  CHECK(solved >= k);
}

TEST_CASE("MINER samples H with probability mu_2 before the first solution and mu_1 after it", "[REQ-PLAN-004]") {
  // Alg. 1 with the paper's fixed mu (safeguard off): each iteration samples x_goal with
  // probability goal_bias, else H with probability mu_2 before the first solution and mu_1
  // after it, so the counts of H samples are Binomial(iterations, (1 - goal_bias) mu). The
  // adversarial region keeps the first solution ~1000 iterations away; common random numbers
  // (same seed and stream) make the run to K extend the run to the first solution. Each count
  // must lie inside its two-sided binomial interval (false fail <= 1e-6 each); swapping mu_1
  // and mu_2 moves both rates by 0.38, hundreds of standard deviations at these counts.
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  const HeuristicRegion region = adversarial_door_region(map);
  PlannerOptions base;
  base.planner = PlannerKind::kMiner;
  base.safeguard = false;
  base.seed = seed_for_set(4242, seed_set());
  const std::size_t after_first = 3000;
  long before_iterations = 0, before_h = 0, after_iterations = 0, after_h = 0;
  for (int trial = 0; trial < 20; ++trial) {
    PlannerOptions o = base;
    o.stream = static_cast<std::uint64_t>(trial);
    o.stop_at_first = true;
    const PlanResult a = miner::plan::plan(problem, o, &region);
    REQUIRE(a.first);
    o.stop_at_first = false;
    o.max_iterations = a.iterations + after_first;
    const PlanResult b = miner::plan::plan(problem, o, &region);
    REQUIRE(b.first);
    REQUIRE(b.first->iteration == a.first->iteration);  // the same run up to the first solution
    before_iterations += static_cast<long>(a.iterations);
    before_h += static_cast<long>(a.region_samples);
    after_iterations += static_cast<long>(b.iterations - a.iterations);
    after_h += static_cast<long>(b.region_samples - a.region_samples);
  }
  const double q = 1.0 - base.goal_bias;
  const auto before = miner::testing::binomial_interval(static_cast<int>(before_iterations), q * base.mu_2);
  const auto after = miner::testing::binomial_interval(static_cast<int>(after_iterations), q * base.mu_1);
  INFO("before the first solution: " << before_h << " of " << before_iterations << " in [" << before.lo << ", "
                                     << before.hi << "]; after: " << after_h << " of " << after_iterations << " in ["
                                     << after.lo << ", " << after.hi << "]");
  CHECK(before_h >= before.lo);
  CHECK(before_h <= before.hi);
  CHECK(after_h >= after.lo);
  CHECK(after_h <= after.hi);
}

TEST_CASE("Guided RRT* samples a beacon's local subsets with its fraction after the first solution", "[REQ-PLAN-003]") {
  // After the first solution each iteration samples x_goal with probability goal_bias, else a
  // beacon's local subsets with probability guided_local_fraction (the solution on the door map
  // always has interior vertices, so beacons exist), else the informed set; before it, never.
  // Common random numbers make the run to K extend the run to the first solution, so the local
  // samples of the extension are Binomial(iterations after, (1 - goal_bias) f): inside the
  // exact interval (false fail <= 1e-6). Dropping the local sampler (0), or taking f as the
  // informed share, moves the rate by 0.45 of thousands of draws.
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  PlannerOptions base;
  base.planner = PlannerKind::kGuided;
  base.seed = seed_for_set(5151, seed_set());
  const std::size_t after_first = 2000;
  long after_iterations = 0, local = 0;
  for (int trial = 0; trial < 10; ++trial) {
    PlannerOptions o = base;
    o.stream = static_cast<std::uint64_t>(trial);
    o.stop_at_first = true;
    const PlanResult a = miner::plan::plan(problem, o, nullptr);
    REQUIRE(a.first);
    CHECK(a.guided_local_samples == 0);  // none before the first solution
    o.stop_at_first = false;
    o.max_iterations = a.iterations + after_first;
    const PlanResult b = miner::plan::plan(problem, o, nullptr);
    REQUIRE(b.first->iteration == a.first->iteration);
    after_iterations += static_cast<long>(b.iterations - a.iterations);
    local += static_cast<long>(b.guided_local_samples);
  }
  const double p = (1.0 - base.goal_bias) * base.guided_local_fraction;
  const auto interval = miner::testing::binomial_interval(static_cast<int>(after_iterations), p);
  INFO("local samples " << local << " of " << after_iterations << " in [" << interval.lo << ", " << interval.hi << "]");
  CHECK(local >= interval.lo);
  CHECK(local <= interval.hi);
}

TEST_CASE("Under common random numbers, solved after K1 iterations implies solved after K2", "[REQ-PLAN-013]") {
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  const auto ref = miner::plan::astar_reference(problem);
  const HeuristicRegion region = miner::plan::astar_dilated_region(problem, ref, I(10, 10, 3), 1);
  const std::size_t K1 = 150, K2 = 600;
  int solved_k1 = 0, solved_k2 = 0;
  for (PlannerKind kind : miner::plan::all_planners()) {
    for (int trial = 0; trial < 25; ++trial) {
      PlannerOptions o;
      o.planner = kind;
      o.seed = seed_for_set(7, seed_set());
      o.stream = static_cast<std::uint64_t>(trial);
      o.max_iterations = K1;
      const PlanResult a = miner::plan::plan(problem, o, &region);
      o.max_iterations = K2;
      const PlanResult b = miner::plan::plan(problem, o, &region);
      INFO(miner::plan::planner_name(kind) << " trial " << trial);
      solved_k1 += a.solved;
      solved_k2 += b.solved;
      if (a.solved) {
        REQUIRE(b.solved);
        CHECK(b.first->iteration == a.first->iteration);
        CHECK(b.first->cost == a.first->cost);
        CHECK(b.cost <= a.cost);
      }
    }
  }
  // The budgets are chosen so that the implication is exercised both ways.
  INFO("solved at K1: " << solved_k1 << ", at K2: " << solved_k2 << " of 100");
  CHECK(solved_k1 > 0);
  CHECK(solved_k2 > solved_k1);
}

TEST_CASE("Lemma 2: the median cost falls toward the optimum and never below it", "[REQ-PLAN-014]") {
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  const auto ref = miner::plan::astar_reference(problem);
  const HeuristicRegion region = miner::plan::astar_dilated_region(problem, ref, I(10, 10, 3), 1);
  const double c_star = door_optimum();
  REQUIRE(ref.cost > c_star);
  const std::vector<std::size_t> budgets{250, 1000, 4000};
  // The last budget beats the A* grid path in almost every trial. H0: rate >= 0.999; H1: a
  // planner that stays above it in 20 % of the trials (n = 61, k = 58).
  const BinomialTest test = sized(0.999, 0.8);
  const int n = test.n;
  for (PlannerKind kind : {PlannerKind::kRrtStar, PlannerKind::kMiner}) {
    std::vector<std::vector<double>> costs(budgets.size());
    int below_reference = 0;
    for (int trial = 0; trial < n; ++trial) {
      double previous = INFINITY;
      for (std::size_t b = 0; b < budgets.size(); ++b) {
        PlannerOptions o;
        o.planner = kind;
        o.seed = seed_for_set(99, seed_set());
        o.stream = static_cast<std::uint64_t>(trial);
        o.max_iterations = budgets[b];
        const PlanResult r = miner::plan::plan(problem, o, &region);
        const double c = r.solved ? r.cost : INFINITY;
        INFO(miner::plan::planner_name(kind) << " trial " << trial << " budget " << budgets[b]);
        CHECK(c >= c_star - 1e-9);  // never below the optimum
        CHECK(c <= previous);       // per trial, more iterations never cost more
        previous = c;
        costs[b].push_back(c);
      }
      below_reference += previous <= ref.cost;
    }
    const double m0 = median(costs.front()), m1 = median(costs[1]), m2 = median(costs.back());
    INFO(miner::plan::planner_name(kind) << ": c* " << c_star << ", A* " << ref.cost << ", medians " << m0 << " "
                                         << m1 << " " << m2 << ", below A* " << below_reference << "/" << n);
    CHECK(m1 <= m0);
    CHECK(m2 <= m1);
    // The gap to c* at least halves from the first to the last budget (measured with
    // these seeds: 5.4 -> 1.0 m for rrtstar, 2.8 -> 0.66 m for miner).
    CHECK(m2 - c_star <= 0.5 * (m0 - c_star));
    // ... and the last budget beats the A* grid path in (almost) every trial.
    CHECK(below_reference >= test.k);
  }
}

TEST_CASE("Shared contract: every planner solves the fixture queries", "[REQ-PLAN-015]") {
  // Each planner, ours and OMPL's, on the same small fixture maps with the same checker;
  // budgets in iterations (OMPL: evaluations of the termination condition, once per
  // iteration of its main loop), never seconds.
  // H0: each planner solves >= 99.9 % of the queries within the budget; H1: a planner that
  // fails one in five (n = 61 over both maps, k = 58; it was 16 trials needing 14, which an
  // 80 % planner passed 35 % of the time).
  const BinomialTest test = sized(0.999, 0.8);
  const int n = (test.n + 1) / 2;  // per map
  const int k_needed = min_successes(2 * n, 0.999, kFalseFailRate);
  std::vector<std::string> planners;
  for (PlannerKind kind : miner::plan::all_planners()) planners.push_back(miner::plan::planner_name(kind));
  for (const auto& name : miner::bench::ompl_planner_names()) planners.push_back(name);
  miner::bench::init_ompl();
  std::vector<miner::world::Map> maps;
  for (const char* name : {"indoor-1.json", "indoor-2.json"}) {
    maps.push_back(miner::world::Map::load(std::string(MINER_SOURCE_DIR) + "/fixtures/maps/" + name));
  }
  for (const std::string& planner : planners) {
    int solved = 0;
    for (const auto& map : maps) {
      const auto& q = *map.query();
      const auto problem = PlanningProblem::make(map, q.start, q.goal, q.robot_radius);
      const auto ref = miner::plan::astar_reference(problem);
      const HeuristicRegion region = miner::plan::astar_dilated_region(problem, ref, I(32, 32, 16), 1);
      for (int trial = 0; trial < n; ++trial) {
        PlanResult r;
        if (miner::bench::is_ompl_planner(planner)) {
          miner::bench::OmplRunOptions o;
          o.planner = planner;
          o.steer_step = miner::plan::resolved_steer_step(PlannerOptions{}, map);
          o.goal_radius = miner::plan::resolved_goal_radius(PlannerOptions{}, map);
          o.max_condition_checks = 20000;
          o.time_limit_s = 1e9;  // the condition-check budget decides
          o.stop_at_first = true;
          o.seed = miner::bench::ompl_run_seed(seed_for_set(20261122, seed_set()), trial);
          r = miner::bench::run_ompl(problem, o);
        } else {
          PlannerOptions o;
          o.planner = miner::plan::planner_from_name(planner);
          o.seed = seed_for_set(5, seed_set());
          o.stream = static_cast<std::uint64_t>(trial);
          o.max_iterations = 20000;
          o.stop_at_first = true;
          r = miner::plan::plan(problem, o, &region);
        }
        INFO(planner << " trial " << trial);
        if (!r.solved) continue;
        ++solved;
        CHECK(r.path.front() == problem.start);
        CHECK((r.path.back() - problem.goal).norm() <= 2 * map.resolution());
        for (std::size_t i = 1; i < r.path.size(); ++i) {
          CHECK(map.segment_free(r.path[i - 1], r.path[i], problem.robot_radius));
        }
      }
    }
    INFO(planner << ": solved " << solved << " of " << 2 * n << " (need " << k_needed << ")");
    CHECK(solved >= k_needed);
  }
}

namespace {

/// Iterations to the target cost (+inf on a miss within the budget).
double iterations_to_target(const PlanningProblem& problem, PlannerKind kind, bool safeguard, std::uint64_t stream,
                            double target, std::size_t budget, const HeuristicRegion* region) {
  PlannerOptions o;
  o.planner = kind;
  o.seed = seed_for_set(20261123, seed_set());
  o.stream = stream;
  o.max_iterations = budget;
  o.target_cost = target;
  o.safeguard = safeguard;
  const PlanResult r = miner::plan::plan(problem, o, region);
  return r.target ? static_cast<double>(r.target->iteration) : INFINITY;
}

}  // namespace

TEST_CASE("Safeguard: with a region that holds no path, miner needs at most 2x RRT*'s iterations", "[REQ-PLAN-020]") {
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  const double target = miner::plan::astar_reference(problem).cost;
  const HeuristicRegion region = adversarial_door_region(map);
  // Calibration (200 trials, this seed): miner within 2x RRT*'s iterations to the target
  // in 147/200 trials with the safeguard (median ratio 1.36), in 17/200 with the paper's
  // fixed mu (median ratio 5.7). H0: within 2x in >= 60 % of the trials; H1: <= 30 %, over
  // 3x what the paper's mu achieved (n = 163, k = 68).
  const BinomialTest test = sized(0.6, 0.3);
  const int n = test.n, k = test.k;
  const std::size_t budget = 40000;
  int within = 0;
  std::vector<double> ratio;
  for (int trial = 0; trial < n; ++trial) {
    const auto stream = static_cast<std::uint64_t>(trial);
    const double y = iterations_to_target(problem, PlannerKind::kRrtStar, true, stream, target, budget, nullptr);
    const double x = iterations_to_target(problem, PlannerKind::kMiner, true, stream, target, budget, &region);
    within += x <= 2.0 * y;
    ratio.push_back(x / y);
  }
  INFO("within 2x: " << within << " of " << n << " (need " << k << "), median ratio " << median(ratio));
  CHECK(within >= k);
}

TEST_CASE("Safeguard: with the A*-dilated region, miner keeps the paper's speed", "[REQ-PLAN-020]") {
  const auto map = wall_with_door_map();
  const auto problem = PlanningProblem::make(map, kStart, kGoal, 0.0);
  const auto ref = miner::plan::astar_reference(problem);
  const HeuristicRegion region = miner::plan::astar_dilated_region(problem, ref, I(10, 10, 3), 1);
  // Calibration (200 trials): 199/200 within 1.25x of the paper's fixed mu, 195 identical.
  // A safeguard that distrusts a good region (tau = 1/2 throughout) is within 1.25x in
  // well under half the trials. H0: >= 97 %; H1: <= 50 % (n = 35, k = 27).
  const BinomialTest test = sized(0.97, 0.5);
  const int n = test.n, k = test.k;
  int within = 0, identical = 0;
  for (int trial = 0; trial < n; ++trial) {
    const auto stream = static_cast<std::uint64_t>(trial);
    const double x = iterations_to_target(problem, PlannerKind::kMiner, true, stream, ref.cost, 40000, &region);
    const double y = iterations_to_target(problem, PlannerKind::kMiner, false, stream, ref.cost, 40000, &region);
    within += x <= 1.25 * y;
    identical += x == y;
  }
  INFO("within 1.25x: " << within << " of " << n << " (need " << k << "), identical " << identical);
  CHECK(within >= k);
}

TEST_CASE("On a dense map our rrtstar and informed need no more iterations than OMPL's to the target", "[REQ-PLAN-021]") {
  // 20 x 20 x 10 m, 150 boxes: 52 % of the map within the robot radius of an obstacle,
  // where the rewiring constant's measure matters most. Fixed seeds (OMPL's too, REQ-PLAN-017)
  // make the campaign's iterations the same bytes on every run.
  miner::world::GeneratorOverrides over;
  over.size = V(20, 20, 10);
  over.obstacles = 150;
  over.resolution = 0.25;
  const auto map = miner::world::generate_map(miner::world::generator_preset("cluttered"), 4, over);
  const auto& q = *map.query();
  miner::bench::FrontendBenchOptions o;
  o.planners = {"rrtstar", "informed", "ompl:RRTstar", "ompl:InformedRRTstar"};
  o.runs = 15;
  o.seed = 1;
  o.target_factor = 1.05;
  o.max_iterations = 60000;
  o.time_limit_s = 1e9;  // the iteration budget decides, never the clock
  o.throughput_iterations = 0;
  const auto r = miner::bench::run_frontend_bench(map, "dense", q.start, q.goal, q.robot_radius, o, nullptr);
  const auto target = [&](const std::string& planner) {
    for (const auto& s : r.summaries)
      if (s.planner == planner) return s.target_iterations;
    return std::numeric_limits<double>::quiet_NaN();
  };
  // Measured (these seeds): rrtstar 4875 vs 5242, informed 4116 vs 4222 median iterations;
  // with the M(X_free) constant (planted) 10280 and 7822: 1.96x and 1.85x OMPL's.
  for (const auto& [ours, theirs] : {std::pair<std::string, std::string>{"rrtstar", "ompl:RRTstar"},
                                     {"informed", "ompl:InformedRRTstar"}}) {
    INFO(ours << " median " << target(ours) << " vs " << theirs << " " << target(theirs));
    REQUIRE(std::isfinite(target(ours)));
    REQUIRE(std::isfinite(target(theirs)));
    CHECK(target(ours) <= 1.25 * target(theirs));
  }
}
