#pragma once
/// \file
/// `miner bench suite` (REQ-REPORT-008): the front-end campaign of Table I over a suite of
/// generated maps of several families, each with its generated query, and over a sweep of
/// the steering step eta. The paper's Table I is hard in a specific way — RRT*'s first
/// solution comes after ~740-1730 iterations — and the fixture maps are not (78-122): the
/// suite shows, per map and eta, how hard the query is for RRT* (its first-solution
/// iterations against the paper's band) and every planner's figures with their spread, n
/// and misses, so a claim can be read on maps as hard as the paper's.
///
/// A suite file (`miner-bench-suite-v1`, fixtures/bench/suite.json):
///   {"format": "miner-bench-suite-v1",
///    "steps": [0.05, 0.1],               // eta as fractions of the bounds' diagonal
///    "band": [700, 2000],                // the paper's RRT* first-solution iterations
///    "maps": [{"name": "sim-300", "preset": "sim", "seed": 12, "obstacles": 300},
///             {"name": "rooms-24", "preset": "rooms", "seed": 13,
///              "size": [24, 16, 4], "resolution": 0.2}]}
/// Every key is checked; an unknown one is refused.

#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/frontend_bench.hpp"
#include "miner/world/map_generator.hpp"

namespace miner::bench {

/// One map of the suite: `miner map gen --preset P --seed S [--obstacles N] [--size X Y Z]
/// [--resolution R]`, benchmarked on the query the generator stores with it.
struct SuiteMap {
  std::string name;
  std::string preset;
  std::uint64_t seed = 1;
  world::GeneratorOverrides overrides;
};

/// The smallest steering step a suite may ask for, as a fraction of the map's diagonal.
inline constexpr double kMinStepFraction = 1e-3;
/// A step as the tables and figure names show it: 6 significant digits ("0.1", "0.0002").
std::string step_label(double fraction);

struct SuiteDefinition {
  std::vector<SuiteMap> maps;
  std::vector<double> step_fractions;  ///< eta / diagonal of the map's bounds, each in (0, 1]
  double band_lo = 700.0, band_hi = 2000.0;  ///< the paper's RRT* first-solution iterations
};

/// Reads and checks a suite file; throws miner::Error naming the file and field.
SuiteDefinition load_suite(const std::string& path);

struct SuiteBenchOptions {
  SuiteDefinition suite;
  std::string suite_file;               ///< where `suite` came from (shown in the results)
  /// Every planner of ours and every OMPL planner; `miner` (the A*-oracle region) is an
  /// upper bound and never in a headline.
  std::vector<std::string> planners{"rrtstar", "informed", "guided", "miner-sgan", "miner",
                                    "ompl:RRTstar", "ompl:InformedRRTstar", "ompl:BITstar", "ompl:ABITstar",
                                    "ompl:AITstar", "ompl:RRTConnect"};
  int runs = 20;
  std::uint64_t seed = 1;
  double time_limit_s = 1.0;
  std::size_t max_iterations = 100000;
  std::string weights;                  ///< sGAN weights; empty: the shipped ones
};

/// One campaign: one map at one eta.
struct SuiteCell {
  std::string map;           ///< the suite map's name
  std::string preset;
  Eigen::Vector3d extent;    ///< the map's bounds
  double resolution = 0.0;
  double step_fraction = 0.0;
  FrontendBenchResult result;
};

struct SuiteBenchResult {
  SuiteBenchOptions options;
  std::vector<SuiteCell> cells;  ///< map-major, then eta in the suite's order
  std::string commit, command;
  double total_s = 0.0;
};

/// Runs every (map, eta) campaign. All maps are generated (and refused if unsolvable)
/// before the first campaign runs.
SuiteBenchResult run_suite_bench(const SuiteBenchOptions& options, const std::string& command,
                                 std::ostream* progress);

/// Whether RRT*'s median first-solution iterations in `cell` lie in the suite's band
/// (false when RRT* is not in the planner set or fewer than half its runs solved).
bool in_paper_band(const SuiteCell& cell, const SuiteDefinition& suite);

/// docs/suite.md: the difficulty table (RRT*'s first solution per map and eta against the
/// paper's band), then per map and eta every planner with mean ± sd, median [IQR], n and
/// the target-reach rate, a generated headline, and the step sweep per planner.
std::string suite_markdown(const SuiteBenchResult& result, const std::string& figure_dir);
/// Per map and eta a box plot of the time to the target (every run shown: misses above
/// the axis, n per box).
std::map<std::string, std::string> suite_figures(const SuiteBenchResult& result);
nlohmann::json to_json(const SuiteBenchResult& result);

}  // namespace miner::bench
