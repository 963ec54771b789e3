#include "bench/ompl_planners.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "miner/core/error.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/world/map.hpp"

#include "miner/core/rng.hpp"

#if MINER_WITH_OMPL
#include <ompl/base/PlannerData.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/informedtrees/ABITstar.h>
#include <ompl/geometric/planners/informedtrees/AITstar.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>
#endif

namespace miner::bench {

std::uint32_t ompl_run_seed(std::uint64_t campaign_seed, int run) {
  // Stream 2^40 + run: far from the project planners' streams (the run number itself).
  Rng rng(campaign_seed, streams::kOmplRunBase + static_cast<std::uint64_t>(run));
  const auto s = static_cast<std::uint32_t>(rng.next_u64() >> 33);  // [0, 2^31)
  return s == 0 ? 1u : s;
}

#if MINER_WITH_OMPL

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

using Clock = std::chrono::steady_clock;

/// Goal threshold of OMPL's GoalState: x_goal itself (a steered state that lands on the
/// goal sample is the goal to the last bit; 1e-9 m absorbs an interpolation's rounding).
constexpr double kExactGoal = 1e-9;

Eigen::Vector3d to_vec(const ob::State* s) {
  const auto* r = s->as<ob::RealVectorStateSpace::StateType>();
  return {r->values[0], r->values[1], r->values[2]};
}

/// checkMotion through the exact segment test of the world model.
class MapMotionValidator : public ob::MotionValidator {
 public:
  MapMotionValidator(const ob::SpaceInformationPtr& si, const world::Map& map, double radius)
      : ob::MotionValidator(si), map_(map), radius_(radius) {}
  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = map_.segment_free(to_vec(s1), to_vec(s2), radius_);
    if (ok) ++valid_;
    else ++invalid_;
    return ok;
  }
  /// The last valid state is found by bisection on the segment to 1e-3 of its length
  /// (only used by planners that extend partially; the answer to "valid?" is exact).
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last) const override {
    if (checkMotion(s1, s2)) return true;
    const Eigen::Vector3d a = to_vec(s1), b = to_vec(s2);
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 10; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (map_.segment_free(a, a + mid * (b - a), radius_)) lo = mid;
      else hi = mid;
    }
    if (last.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, lo, last.first);
    last.second = lo;
    return false;
  }

 private:
  const world::Map& map_;
  double radius_;
};

/// The state space's default projection, registered here instead of OMPL's random linear
/// projection (whose Eigen storage libompl frees in a way AddressSanitizer rejects). None
/// of the benchmarked planners uses projections; OMPL only requires one to exist.
class XyzProjection : public ob::ProjectionEvaluator {
 public:
  explicit XyzProjection(const ob::StateSpace* space) : ob::ProjectionEvaluator(space) {}
  unsigned int getDimension() const override { return 3; }
  void defaultCellSizes() override { cellSizes_.assign(3, 1.0); }
  void project(const ob::State* state, Eigen::Ref<Eigen::VectorXd> projection) const override {
    const auto* r = state->as<ob::RealVectorStateSpace::StateType>();
    for (int a = 0; a < 3; ++a) projection[a] = r->values[a];
  }
};

class MapStateSpace : public ob::RealVectorStateSpace {
 public:
  MapStateSpace() : ob::RealVectorStateSpace(3) {}
  void registerProjections() override {
    registerDefaultProjection(std::make_shared<XyzProjection>(this));
  }
};

ob::PlannerPtr make_planner(const std::string& name, const ob::SpaceInformationPtr& si, const OmplRunOptions& o) {
  if (name == "ompl:RRTstar" || name == "ompl:InformedRRTstar") {
    std::shared_ptr<og::RRTstar> p;
    if (name == "ompl:RRTstar") p = std::make_shared<og::RRTstar>(si);
    else p = std::make_shared<og::InformedRRTstar>(si);
    p->setRange(o.steer_step);
    p->setGoalBias(o.goal_bias);
    p->setRewireFactor(o.rewire_factor);
    p->setKNearest(false);  // the radius rule, as the project's RRT*
    return p;
  }
  if (name == "ompl:BITstar") return std::make_shared<og::BITstar>(si);
  if (name == "ompl:ABITstar") return std::make_shared<og::ABITstar>(si);
  if (name == "ompl:AITstar") return std::make_shared<og::AITstar>(si);
  if (name == "ompl:RRTConnect") {
    auto p = std::make_shared<og::RRTConnect>(si);
    p->setRange(o.steer_step);
    return p;
  }
  throw Error("unknown OMPL planner \"" + name + "\"");
}

long progress_integer(const ob::PlannerPtr& planner, const std::string& key) {
  const auto& props = planner->getPlannerProgressProperties();
  const auto it = props.find(key);
  if (it == props.end()) return 0;
  try {
    return std::stol(it->second());
  } catch (const std::exception&) {
    return 0;
  }
}

}  // namespace

std::vector<std::string> ompl_planner_names() {
  return {"ompl:RRTstar", "ompl:InformedRRTstar", "ompl:BITstar", "ompl:ABITstar", "ompl:AITstar",
          "ompl:RRTConnect"};
}
bool ompl_available() { return true; }

void init_ompl() { ompl::msg::setLogLevel(ompl::msg::LOG_NONE); }

plan::PlanResult run_ompl(const plan::PlanningProblem& problem, const OmplRunOptions& o) {
  // Reseed OMPL's seed generator before anything of this run draws a seed: every RNG the
  // run creates (samplers, planners, nearest-neighbour structures) is seeded from it in
  // creation order, so the run is a function of o.seed (OMPL logs an error that reseeding
  // after the first seed "will not be deterministic"; it reseeds all the same, and its log
  // is off).
  if (o.seed != 0) {
    init_ompl();  // the reseeding's error log stays silent even if the caller did not call it
    ompl::RNG::setSeed(o.seed);
  }
  const world::Map& map = *problem.map;
  auto space = std::make_shared<MapStateSpace>();
  ob::RealVectorBounds bounds(3);
  for (int a = 0; a < 3; ++a) {
    bounds.setLow(static_cast<unsigned>(a), map.bounds().min[a]);
    bounds.setHigh(static_cast<unsigned>(a), map.bounds().max[a]);
  }
  space->setBounds(bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  const double radius = problem.robot_radius;
  si->setStateValidityChecker([&map, radius](const ob::State* s) { return map.is_free(to_vec(s), radius); });
  si->setMotionValidator(std::make_shared<MapMotionValidator>(si, map, radius));
  si->setup();

  ob::ScopedState<ob::RealVectorStateSpace> start(space), goal(space);
  for (int a = 0; a < 3; ++a) {
    start[static_cast<unsigned>(a)] = problem.start[a];
    goal[static_cast<unsigned>(a)] = problem.goal[a];
  }
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  // The goal rule (REQ-PLAN-018): a path ends exactly at x_goal and costs its whole length.
  // OMPL gets x_goal as an exact goal state (threshold kExactGoal; it samples x_goal with its
  // goal bias and steers onto it), so its costs need no correction; with the goal ball as
  // its goal it would stop up to goal_radius short and count that as free.
  pdef->setStartAndGoalStates(start, goal, kExactGoal);
  auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(si);
  // OMPL never stops on its own cost (which ends in the goal ball): the termination
  // condition below judges the target on the cost to x_goal.
  objective->setCostThreshold(ob::Cost(0.0));
  pdef->setOptimizationObjective(objective);

  ob::PlannerPtr planner = make_planner(o.planner, si, o);
  planner->setProblemDefinition(pdef);
  planner->setup();

  plan::PlanResult result;
  result.steer_step = o.steer_step;
  result.goal_radius = o.goal_radius;
  auto rrtstar = std::dynamic_pointer_cast<og::RRTstar>(planner);
  auto bitstar = std::dynamic_pointer_cast<og::BITstar>(planner);  // ABITstar is one too
  const auto iterations = [&]() -> std::size_t {
    if (rrtstar) return rrtstar->numIterations();
    if (bitstar) return bitstar->numIterations();
    const long n = progress_integer(planner, "iterations INTEGER");
    return n > 0 ? static_cast<std::size_t>(n) : kUnknownCount;
  };
  const auto vertices = [&]() -> std::size_t {
    const long n = progress_integer(planner, "current graph vertices INTEGER");
    return n > 0 ? static_cast<std::size_t>(n - 1) : kUnknownCount;
  };
  Clock::time_point t0;
  const auto now_ms = [&t0] { return elapsed_ms(t0); };
  double best = std::numeric_limits<double>::infinity();
  const auto record = [&](double cost) {
    if (!(cost < best)) return;
    best = cost;
    const plan::StageRecord s{iterations(), vertices(), cost, now_ms()};
    if (!result.first) result.first = s;
    result.improvements.push_back(s);
    if (o.target_cost && !result.target && cost <= *o.target_cost) result.target = s;
  };
  // Two sources of "a better solution exists": the intermediate-solution callback (RRT*,
  // BIT* family) and, for planners that do not call it (AIT*, RRTConnect), the problem
  // definition's solution list, polled by the termination condition every iteration.
  pdef->setIntermediateSolutionCallback(
      [&](const ob::Planner*, const std::vector<const ob::State*>&, const ob::Cost cost) { record(cost.value()); });
  std::size_t seen_solutions = 0;
  const auto poll_solutions = [&] {
    const std::size_t n = pdef->getSolutionCount();
    if (n == seen_solutions) return;
    seen_solutions = n;
    for (const ob::PlannerSolution& sol : pdef->getSolutions()) {
      if (!sol.approximate_) record(sol.path_->as<og::PathGeometric>()->length());
    }
  };

  const double limit_s = o.time_limit_s;
  std::size_t ptc_calls = 0;
  const std::optional<std::size_t> max_iterations = o.max_iterations;
  ob::PlannerTerminationCondition ptc([&] {
    poll_solutions();
    if (o.target_cost && best <= *o.target_cost) return true;
    if (o.stop_at_first && best < std::numeric_limits<double>::infinity()) return true;
    if (o.max_condition_checks && ptc_calls >= *o.max_condition_checks) return true;
    if (max_iterations && rrtstar && rrtstar->numIterations() >= *max_iterations) return true;
    // Reading the clock every call would dominate cheap iterations; every 64th is enough.
    return (++ptc_calls & 63u) == 0 && now_ms() > 1000.0 * limit_s;
  });
  t0 = Clock::now();
  const ob::PlannerStatus status = planner->solve(ptc);
  result.time_ms = now_ms();
  poll_solutions();

  const bool exact = status == ob::PlannerStatus::EXACT_SOLUTION;
  ob::PlannerData data(si);
  planner->getPlannerData(data);
  result.nodes = data.numVertices() > 0 ? data.numVertices() - 1 : 0;
  result.iterations = iterations();
  if (exact && pdef->hasExactSolution()) {
    const auto path = pdef->getSolutionPath()->as<og::PathGeometric>();
    for (const ob::State* s : path->getStates()) result.path.push_back(to_vec(s));
    if (!result.path.empty() && result.path.back() != problem.goal &&
        map.segment_free(result.path.back(), problem.goal, radius)) {
      result.path.push_back(problem.goal);
    }
    result.cost = plan::path_length(result.path);
    result.solved = true;
    // Planners that stop at the target: the final counters are the target's.
    if (result.target && result.target->nodes == kUnknownCount && result.improvements.back().cost == result.target->cost) {
      result.target->nodes = result.nodes;
    }
  } else {
    result.reason = "OMPL " + o.planner + ": " + status.asString() + " within " + std::to_string(limit_s) + " s";
  }
  return result;
}

#else

std::vector<std::string> ompl_planner_names() { return {}; }
bool ompl_available() { return false; }
void init_ompl() {}
plan::PlanResult run_ompl(const plan::PlanningProblem&, const OmplRunOptions& o) {
  throw Error("planner " + o.planner + ": this build has no OMPL (configure with -DMINER_WITH_OMPL=ON)");
}

#endif

}  // namespace miner::bench
