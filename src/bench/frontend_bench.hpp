#pragma once
/// \file
/// `miner bench frontend` (REQ-PLAN-010, REQ-PLAN-011): a Monte Carlo campaign like the
/// paper's Table I on one map and query. Every planner (the project's four and OMPL's)
/// runs `runs` times with the same collision checker, goal region, steering step and
/// target cost; per planner the initial stage (iterations, nodes, cost, time to the
/// first solution) and the optimal stage (iterations, nodes, time until the cost is
/// <= target = target_factor x the A* reference cost) are summarised, and the runs can
/// be written in OMPL's benchmark log format. Benchmarks read the clock; tests never
/// assert on it.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/rrt_star.hpp"

namespace miner::world {
class Map;
}

namespace miner::bench {

struct FrontendBenchOptions {
  std::vector<std::string> planners;  ///< empty: the project's four + every OMPL planner
  int runs = 50;
  std::uint64_t seed = 1;
  double target_factor = 1.0;   ///< target cost = factor x A* reference cost
  std::size_t max_iterations = 200000;  ///< the project's planners (and OMPL's RRT*s)
  double time_limit_s = 10.0;   ///< per run of OMPL's planners (wall clock); ours stop on max_iterations
  /// > 0: OMPL's planners also stop after this many evaluations of their termination condition
  /// (one per iteration of the planner's loop), a budget that, unlike the wall clock, gives the
  /// same records on every machine and every run (sixteenth campaign F13). The CLI's
  /// --ompl-checks lifts time_limit_s to kMaxTimeLimitS so that the clock never binds.
  std::size_t ompl_checks = 0;
  plan::PlannerOptions planner_options;  ///< steer step, goal radius, mu_1, mu_2, ...
  Eigen::Vector3i region_dims = plan::HeuristicRegion::default_dims();
  int region_dilation = 1;
  std::string region_file;      ///< miner: this region instead of the A*-dilated one
  std::string weights_file;     ///< miner-sgan: these weights instead of the shipped ones
  /// Throughput check: the project's RRT* and OMPL's RRTstar both run this many
  /// iterations with no target, and iterations per second are compared. 0: skip.
  std::size_t throughput_iterations = 20000;
  /// Distributed campaigns (REQ-REPORT-006): this process runs only the runs r with
  /// r % shard_count == shard_index (and the throughput check only in shard 0);
  /// merge_frontend_shards() joins the parts into the unsharded campaign's result.
  int shard_index = 0;
  int shard_count = 1;
};

/// The ranges `bench frontend` takes for --goal-radius and --time-limit, which `bench merge`
/// checks in the parts too.
inline constexpr double kMinGoalRadius = 1e-6, kMaxGoalRadius = 1e6;
inline constexpr double kMinTimeLimitS = 1e-3, kMaxTimeLimitS = 86400.0;
/// The longest wall clock a merged part may record (a year, s): the sum of any number of parts
/// a merge takes stays finite.
inline constexpr double kMaxPartSeconds = 365.0 * 86400.0;
/// The range of --target-factor (the target cost is this times the A* reference).
inline constexpr double kMinTargetFactor = 0.01, kMaxTargetFactor = 100.0;
/// The largest --ompl-checks (bounded work: a check costs at least one planner iteration).
inline constexpr std::size_t kMaxOmplChecks = 1000000000;
/// How far past its time limit an OMPL run may find a stage, as a factor of the limit (plus
/// one second): OMPL's termination condition reads the clock every 64 calls and a planner's
/// iteration (a BIT* batch) may run on after it.
inline constexpr double kOmplOvershoot = 2.0;

/// The front-end options a campaign of campaigns (`bench paper`, `bench suite`) runs each map
/// with: its planners, runs, seed, limits and weights; no throughput check (it is Table I's).
template <class CampaignOptions>
FrontendBenchOptions frontend_options_of(const CampaignOptions& o) {
  FrontendBenchOptions fo;
  fo.planners = o.planners;
  fo.runs = o.runs;
  fo.seed = o.seed;
  fo.time_limit_s = o.time_limit_s;
  fo.max_iterations = o.max_iterations;
  fo.weights_file = o.weights;
  fo.throughput_iterations = 0;
  return fo;
}

/// MINER with the filtered sGAN region computed per run, its time included in every
/// figure (the end-to-end front end); "miner" itself uses the A*-dilated oracle region.
inline constexpr const char* kMinerSgan = "miner-sgan";
/// Empty when `name` is a planner the campaign runs (one of default_frontend_planners(): every
/// planner); else why not, listing every valid name (issue 20: the message once listed 4 of
/// 11). The CLI and the campaign both check.
std::string unknown_planner(const std::string& name);

/// One run of one planner.
struct RunRecord {
  std::string planner;
  int run = 0;
  plan::PlanResult result;
};

struct PlannerSummary {
  std::string planner;
  int runs = 0;
  double success_rate = 0.0;  ///< fraction of runs with a solution
  double target_rate = 0.0;   ///< fraction of runs that reached the target cost
  // Initial stage: medians and means over the solved runs (NaN if none).
  double first_iterations = NAN, first_nodes = NAN, first_cost = NAN, first_time_ms = NAN;
  double first_iterations_mean = NAN, first_nodes_mean = NAN, first_cost_mean = NAN, first_time_ms_mean = NAN;
  // Optimal stage: medians over all runs, a run that missed the target counting as
  // +infinity, so NaN (null in JSON) when fewer than half the runs reached it; means
  // over the runs that reached it.
  double target_iterations = NAN, target_nodes = NAN, target_time_ms = NAN;
  double target_iterations_mean = NAN, target_nodes_mean = NAN, target_time_ms_mean = NAN;
  double final_cost = NAN;  ///< median final cost of solved runs
  // Spread (REQ-PLAN-019): sample standard deviation over the runs that reached the stage,
  // lower and upper quartile over all runs (a missed stage counting as +inf, so a quartile
  // that lands on a miss is NaN / null).
  double first_iterations_sd = NAN, first_iterations_q1 = NAN, first_iterations_q3 = NAN;
  double first_time_ms_sd = NAN, first_time_ms_q1 = NAN, first_time_ms_q3 = NAN;
  double target_iterations_sd = NAN, target_iterations_q1 = NAN, target_iterations_q3 = NAN;
  double target_time_ms_sd = NAN, target_time_ms_q1 = NAN, target_time_ms_q3 = NAN;
  int target_reached = 0;  ///< runs that reached the target (target_rate x runs)
};

struct FrontendBenchResult {
  std::string map;
  Eigen::Vector3d start, goal;
  double robot_radius = 0.0;
  double reference_cost = 0.0;   ///< A* path length
  double target_cost = 0.0;
  double lower_bound = 0.0;      ///< straight-line distance
  double steer_step = 0.0, goal_radius = 0.0;
  std::string region_source;
  std::size_t region_cells = 0;
  /// SHA-256 of the region's document (HeuristicRegion::to_json), and of the sGAN weights'
  /// bytes ("" when miner-sgan does not run): a merge compares them, since a path names
  /// whatever file is there when a part runs (sixteenth campaign F10).
  std::string region_sha256, weights_sha256;
  double region_ms = 0.0;        ///< time to build the region (not in MINER's times)
  std::vector<RunRecord> runs;
  std::vector<PlannerSummary> summaries;
  // Throughput (iterations per second over throughput_iterations, median of the runs).
  double rrtstar_iterations_per_s = NAN;
  double ompl_rrtstar_iterations_per_s = NAN;
  double total_s = 0.0;
  FrontendBenchOptions options;
};

/// The default planner list, every planner: rrtstar, informed, guided, miner, miner-sgan, then
/// OMPL's.
std::vector<std::string> default_frontend_planners();

/// Runs the campaign on `map` (`map_name` labels the outputs). `progress` (may be null)
/// receives one line per planner.
FrontendBenchResult run_frontend_bench(const world::Map& map, const std::string& map_name,
                                       const Eigen::Vector3d& start, const Eigen::Vector3d& goal,
                                       double robot_radius, const FrontendBenchOptions& options,
                                       std::ostream* progress);

/// Summary of a planner's runs (exposed for tests).
PlannerSummary summarise(const std::string& planner, const std::vector<RunRecord>& runs);

/// One record per planner: planner, runs, success_rate, first_* and target_* (medians,
/// null where undefined), *_mean, final_cost; plus the campaign's settings.
nlohmann::json to_json(const FrontendBenchResult& result);

/// Joins the `to_json` outputs of shards 0..N-1 of one campaign (same map, query, seed,
/// runs, planners and settings; every shard exactly once) into the JSON the unsharded
/// campaign writes: run records in planner-then-run order, summaries recomputed from
/// them, total_s summed. Throws miner::Error naming the mismatch or the missing shard.
/// `names` (the files, for messages; default "shard file k") name the part at fault; a part
/// that is not a `bench frontend --json` output (a map file, a truncated record) is refused
/// naming the file and the field.
nlohmann::json merge_frontend_shards(const std::vector<nlohmann::json>& parts,
                                     const std::vector<std::string>& names = {});
/// A table like the paper's Table I.
void print_table(const FrontendBenchResult& result, std::ostream& out);
/// OMPL's benchmark log format (ompl::tools::Benchmark::saveResultsToStream), readable by
/// `ompl_benchmark_statistics` and Planner Arena.
void write_ompl_log(const FrontendBenchResult& result, std::ostream& out);

}  // namespace miner::bench
