#pragma once
/// \file
/// `miner bench paper` (REQ-REPORT-005): the paper's four result tables reproduced on
/// this machine and written beside the paper's own numbers — Table I (front end: the
/// project's RRT* family and MINER with the sGAN, OMPL's planners beside them), the
/// heuristic-quality table (sGAN on unseen maps), Table II (front-end initial time +
/// MINCO vs the baselines on the front end's own path) and the tracking-MSE table
/// (closed-loop flights of the indoor scenarios) — plus box plots like Fig. Map1-3.

#include <map>
#include <string>
#include <vector>

#include "bench/backend_bench.hpp"
#include "bench/frontend_bench.hpp"
#include "bench/heuristic_bench.hpp"
#include "miner/pipeline/scenario.hpp"

namespace miner::bench {

struct PaperBenchOptions {
  std::vector<std::string> maps{"fixtures/maps/sim-1.json", "fixtures/maps/sim-2.json", "fixtures/maps/sim-3.json"};
  /// Every planner of ours and every OMPL planner (issue 17: no selective comparison set);
  /// `miner` (the A*-oracle region) is shown as an upper bound and never in a headline.
  std::vector<std::string> planners{"rrtstar", "informed", "guided", "miner-sgan", "miner",
                                    "ompl:RRTstar", "ompl:InformedRRTstar", "ompl:BITstar", "ompl:ABITstar",
                                    "ompl:AITstar", "ompl:RRTConnect"};
  int runs = 20;
  std::uint64_t seed = 1;
  double time_limit_s = 2.0;            ///< per front-end run (OMPL's anytime planners use it all)
  std::size_t max_iterations = 200000;
  std::string weights;                  ///< sGAN weights; empty: the shipped ones
  /// Heuristic quality: a `miner dataset` folder's test split, or (empty) a test set
  /// generated here from unseen map seeds.
  std::string heuristic_data;
  /// Unseen maps generated for the heuristic table; with heuristic_data, the first this many of
  /// its test split when heuristic_samples_given, else all of it.
  int heuristic_samples = 100;
  bool heuristic_samples_given = false;
  std::size_t heuristic_iterations = 20000;
  /// Tracking: scenario files; empty: the embedded default (indoor-1) and the same
  /// scenario on each map in tracking_maps.
  std::vector<std::string> scenarios;
  std::vector<std::string> tracking_maps{"fixtures/maps/indoor-2.json"};
  double backend_budget_s = 0.2;        ///< per (method, order) on each map's path
  int jobs = 1;                         ///< dataset generation threads
};

struct TrackingRow {
  std::string env;
  Eigen::Vector3d position_mse, velocity_mse;
  double max_position_error = 0.0;
  int collisions = 0;
  bool goal_reached = false;
  std::string reference;  ///< what the flown reference is ("MINER RRT* on the sgan region + min-snap MINCO")
};

struct PaperBenchResult {
  PaperBenchOptions options;
  std::vector<FrontendBenchResult> frontend;            ///< one per map
  std::vector<double> grid_resolution;                  ///< one per map: the grid of its A* reference (m)
  std::vector<std::vector<BackendRecord>> backend;      ///< one per map, on backend_source's path
  std::vector<std::size_t> backend_segments;            ///< that path's segment count
  /// One per map: whose path the back end ran on ("miner-sgan run 0"; empty: none solved).
  std::vector<std::string> backend_source;
  HeuristicBenchResult heuristic;
  std::vector<TrackingRow> tracking;
  std::string commit;                                   ///< `git describe --always --dirty`, or "unknown"
  std::string command;
  double total_s = 0.0;
};

/// Master seed of the heuristic test set that `miner bench paper` generates. Datasets draw
/// map k from splitmix64(seed ^ k); a training set made with a seed and a count below 2^32
/// feeds splitmix64 inputs below 2^32, while unseen_heuristic_seed(seed) ^ k keeps a salt's
/// high bits, so (splitmix64 being a bijection) no generated test map is a map such a training
/// set holds, whatever seed the bench is given. The test split of the bench's own seed would
/// not do: with --count 1 its maps k >= 1 are the first training maps of that seed.
std::uint64_t unseen_heuristic_seed(std::uint64_t seed);

/// What a flown reference is, as the tracking table names it: "MINER RRT* on the sgan region +
/// min-snap MINCO", "min-jerk MINCO through the scenario's waypoints", "trajectory file".
std::string reference_label(const pipeline::Scenario& s, const pipeline::ReferencePlan& reference);

PaperBenchResult run_paper_bench(const PaperBenchOptions& options, const std::string& command, std::ostream* progress);

/// docs/results.md: each table with the paper's numbers, this run's and OMPL's side by
/// side, the command and commit; `figure_dir` is where the box plots are linked from.
std::string results_markdown(const PaperBenchResult& result, const std::string& figure_dir);
/// The box plots (file name -> SVG): per map, time to the first solution and to the
/// target cost, one box per planner (log scale).
std::map<std::string, std::string> results_figures(const PaperBenchResult& result);
nlohmann::json to_json(const PaperBenchResult& result);

}  // namespace miner::bench
