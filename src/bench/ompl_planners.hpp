#pragma once
/// \file
/// OMPL's planners on the project's world model (REQ-PLAN-011): the same map, query,
/// collision checker (Map::is_free / Map::segment_free, exact, with the robot radius),
/// goal region, steering range and rewiring factor as the project's planners, so a
/// benchmark compares planners and nothing else.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "miner/plan/rrt_star.hpp"

namespace miner::bench {

/// "ompl:RRTstar", "ompl:InformedRRTstar", "ompl:BITstar", "ompl:ABITstar",
/// "ompl:AITstar", "ompl:RRTConnect" (empty when built without OMPL).
std::vector<std::string> ompl_planner_names();
bool ompl_available();
/// Whether `name` is in the OMPL namespace of planner names ("ompl:...").
inline bool is_ompl_planner(const std::string& name) { return name.rfind("ompl:", 0) == 0; }

struct OmplRunOptions {
  std::string planner;         ///< one of ompl_planner_names()
  double time_limit_s = 10.0;  ///< wall-clock cap (OMPL has no iteration budget)
  std::optional<std::size_t> max_iterations;  ///< RRTstar family: stop after this many
  double steer_step = 0.0;     ///< setRange (RRT* family, RRTConnect)
  double goal_radius = 0.0;    ///< GoalState threshold
  double goal_bias = 0.05;
  double rewire_factor = 1.1;
  std::optional<double> target_cost;  ///< PathLengthOptimizationObjective cost threshold
  /// A budget that is not wall-clock: stop after this many evaluations of the termination
  /// condition (one per iteration of the planner's main loop). For tests.
  std::optional<std::size_t> max_condition_checks;
  bool stop_at_first = false;  ///< stop as soon as an exact solution exists
};

/// A stage counter OMPL does not report (e.g. RRTstar's vertex count mid-run).
inline constexpr std::size_t kUnknownCount = static_cast<std::size_t>(-1);

/// Runs one OMPL planner once. `iterations` / `nodes` of the stage records are the
/// planner's own counters where it reports them (kUnknownCount otherwise). The cost of the result
/// adds the leg from OMPL's last state to x_goal (when collision-free) so it is
/// comparable with plan::plan's; stage costs are OMPL's.
plan::PlanResult run_ompl(const plan::PlanningProblem& problem, const OmplRunOptions& options);

/// Seeds OMPL's global RNG (effective only before OMPL draws its first number in the
/// process) and silences its console log.
void init_ompl(std::uint64_t seed);

}  // namespace miner::bench
