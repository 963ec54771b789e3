#pragma once
/// \file
/// OMPL's planners on the project's world model (REQ-PLAN-011): the same map, query,
/// collision checker (Map::is_free / Map::segment_free, exact, with the robot radius),
/// goal region, steering range and rewiring factor as the project's planners, so a
/// benchmark compares planners and nothing else.

#include <cstddef>
#include <cstdint>
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
  double goal_radius = 0.0;    ///< the project's goal ball (reported; OMPL's goal is x_goal exactly)
  double goal_bias = 0.05;
  double rewire_factor = 1.1;
  std::optional<double> target_cost;  ///< PathLengthOptimizationObjective cost threshold
  /// A budget that is not wall-clock: stop after this many evaluations of the termination
  /// condition (one per iteration of the planner's main loop). For tests.
  std::optional<std::size_t> max_condition_checks;
  bool stop_at_first = false;  ///< stop as soon as an exact solution exists
  /// Seed of OMPL's generator for this run (REQ-PLAN-017): OMPL's seed generator is reseeded
  /// with it before the run builds anything, so the run's records depend on this seed alone,
  /// not on which planners or runs came before it in the process. 0: leave OMPL's state.
  std::uint32_t seed = 0;
};

/// The OMPL seed of run `run` of a campaign seeded `campaign_seed`: drawn from the
/// project's Rng (its own stream per run), never 0. Every OMPL planner gets the same
/// seed in the same run (common random numbers, as the project's planners).
std::uint32_t ompl_run_seed(std::uint64_t campaign_seed, int run);

/// A stage counter OMPL does not report (e.g. RRTstar's vertex count mid-run).
inline constexpr std::size_t kUnknownCount = static_cast<std::size_t>(-1);

/// Runs one OMPL planner once. `iterations` / `nodes` of the stage records are the
/// planner's own counters where it reports them (kUnknownCount otherwise).
/// One goal rule for every planner (REQ-PLAN-018): a solution ends exactly at x_goal and
/// its cost is its whole length. OMPL's goal is the state x_goal itself (not the goal ball,
/// where OMPL's cost would stop up to goal_radius short); the project's planners reach
/// x_goal by a free leg from a vertex in the goal ball, which that leg's length pays for.
plan::PlanResult run_ompl(const plan::PlanningProblem& problem, const OmplRunOptions& options);

/// Silences OMPL's console log (seeding is per run: OmplRunOptions::seed).
void init_ompl();

}  // namespace miner::bench
