#pragma once
/// \file
/// `miner bench heuristic` (REQ-HEUR-009): the sGAN measured like the paper's heuristic
/// quality table (connectivity and safety rates, Sec. V-A.2) on a dataset split of maps
/// never seen in training, plus what the region buys the planner: iterations and time to
/// the first solution and to the target cost for MINER with the filtered sGAN region
/// (region time included) and for RRT*, on the same queries with the same random streams.
/// Several datasets (one map family each) give one summary per family besides the total
/// (REQ-HEUR-009); strict rates are measured on the continuous map (REQ-HEUR-011).

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "miner/plan/rrt_star.hpp"

namespace miner::bench {

struct HeuristicBenchOptions {
  std::vector<std::string> data;  ///< `miner dataset` folders (one family each)
  std::string split = "test";
  int samples = 0;              ///< first N samples of the split (0: all)
  /// The option that set `samples`, named when the split has fewer (bench paper's own name).
  std::string samples_option = "--samples";
  std::string weights;          ///< empty: the shipped weights
  std::uint64_t seed = 1;       ///< noise of a sample: seed + its key (its family and map seed); planner stream: the key
  std::size_t max_iterations = 20000;
  double target_factor = 1.0;   ///< target cost = factor x the sample's A* cost
  bool planners = true;         ///< also run MINER and RRT* (false: quality only)
  bool strict_bridge = false;   ///< filter step 5 too (REQ-HEUR-014); false: steps 1-4
};

struct HeuristicSampleRecord {
  std::string family;  ///< the dataset's preset
  std::uint64_t map_seed = 0;
  bool raw_connected = false, raw_safe = false, connected = false, safe = false;
  /// REQ-HEUR-011 on the continuous map, for the raw and the filtered region.
  bool raw_connected_strict = false, raw_safe_strict = false, connected_strict = false, safe_strict = false;
  /// The same for the sample's ground truth T (the A*-dilated region): what a perfect
  /// network would score.
  bool truth_connected_strict = false, truth_safe_strict = false;
  std::size_t raw_cells = 0, cells = 0, bridge_cells = 0;
  /// Step 1's threshold for this query and whether the widest rule lowered it below the
  /// weights' own (REQ-HEUR-016).
  double threshold = 0.0;
  bool widened = false;
  std::size_t strict_cells = 0;     ///< filter step 5: cells added
  bool strict_witness = false;      ///< step 5 found a checked polyline inside H
  double filter_ms = 0.0;
  double inference_ms = 0.0, region_ms = 0.0;  ///< region: encode + inference + filter
  plan::PlanResult miner, rrtstar;
};

struct HeuristicBenchResult {
  HeuristicBenchOptions options;
  std::string data_label;            ///< what the data was (the folders, or how it was generated)
  std::vector<std::string> families;  ///< presets in the order of the datasets
  std::vector<HeuristicSampleRecord> samples;
  double total_s = 0.0;
};

HeuristicBenchResult run_heuristic_bench(const HeuristicBenchOptions& options, std::ostream* progress);
nlohmann::json to_json(const HeuristicBenchResult& r);
std::string to_text(const HeuristicBenchResult& r);

}  // namespace miner::bench
