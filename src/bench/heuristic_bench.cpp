#include "bench/heuristic_bench.hpp"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <limits>
#include <sstream>

#include "bench/campaign_stats.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/heuristic/strict_quality.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

double rate(const std::vector<HeuristicSampleRecord>& s, bool HeuristicSampleRecord::*field) {
  if (s.empty()) return NAN;
  std::size_t n = 0;
  for (const auto& r : s) n += (r.*field) ? 1 : 0;
  return static_cast<double>(n) / static_cast<double>(s.size());
}

/// Medians over all samples of a stage's iterations and time (+inf where not reached).
nlohmann::json stage_summary(const std::vector<HeuristicSampleRecord>& s, plan::PlanResult HeuristicSampleRecord::*who) {
  std::vector<double> fi, ft, ti, tt;
  std::size_t solved = 0, reached = 0;
  for (const auto& r : s) {
    const plan::PlanResult& p = r.*who;
    solved += p.first ? 1 : 0;
    reached += p.target ? 1 : 0;
    fi.push_back(p.first ? static_cast<double>(p.first->iteration) : kInf);
    ft.push_back(p.first ? p.first->time_ms : kInf);
    ti.push_back(p.target ? static_cast<double>(p.target->iteration) : kInf);
    tt.push_back(p.target ? p.target->time_ms : kInf);
  }
  const double n = static_cast<double>(std::max<std::size_t>(s.size(), 1));
  return {{"success_rate", static_cast<double>(solved) / n}, {"target_rate", static_cast<double>(reached) / n},
          {"first_iterations", num(median(fi))},             {"first_time_ms", num(median(ft))},
          {"target_iterations", num(median(ti))},            {"target_time_ms", num(median(tt))}};
}

/// A sample's key: its family and its map seed (which the dataset's seed and the sample's
/// number give), mixed by splitmix64, so each sample draws the same noise and planner stream in
/// any run that measures it.
std::uint64_t sample_key(const std::string& family, std::uint64_t map_seed) {
  return splitmix64(fnv1a64(family.data(), family.size()) ^ map_seed);
}

}  // namespace

HeuristicBenchResult run_heuristic_bench(const HeuristicBenchOptions& o, std::ostream* progress) {
  if (o.samples < 0) throw Error("--samples: must be >= 0");
  if (o.max_iterations < 1) throw Error("--iterations: must be >= 1");
  if (!(o.target_factor > 0.0)) throw Error("--target-factor: must be > 0");
  if (o.data.empty()) throw Error("--data: at least one `miner dataset` folder");
  const Clock::time_point t_start = Clock::now();
  HeuristicBenchResult out;
  out.options = o;
  const heuristic::Sgan sgan = heuristic::Sgan::load_or_builtin(o.weights);
  // Every folder is read and checked before the first sample is measured.
  struct Family {
    std::string data, preset;
    std::vector<heuristic::Sample> split;
  };
  std::vector<Family> families;
  std::size_t total = 0;
  for (const std::string& data : o.data) {
    const Json meta = read_json_file(data + "/dataset.json");
    Family f{data, JsonField(meta, "", data + "/dataset.json").at("preset").string(), {}};
    for (const Family& g : families)
      if (g.preset == f.preset) throw Error(data + ": family '" + f.preset + "' is already measured from " + g.data);
    f.split = heuristic::read_split(data, o.split);
    if (f.split.empty()) throw Error(data + ": split '" + o.split + "' has no samples");
    // More samples than the split holds is refused, not measured on fewer without a word
    // (issue 20, fourth campaign).
    if (static_cast<std::size_t>(o.samples) > f.split.size())
      throw Error(o.samples_option + " " + std::to_string(o.samples) + ": " + data + ": split '" + o.split + "' has only " +
                  std::to_string(f.split.size()) + " samples (give at most that many, or " +
                  (o.samples_option == "--samples" ? "0 for all)" : "leave the option out for all)"));
    if (o.samples > 0) f.split.resize(static_cast<std::size_t>(o.samples));
    // The measured samples are the generator's: each is made again and compared byte for byte,
    // so truth edited within its levels and re-hashed is refused (seventh campaign W2).
    heuristic::verify_samples(data, f.split);
    const Eigen::Vector3i dims(meta["dims"][0].get<int>(), meta["dims"][1].get<int>(), meta["dims"][2].get<int>());
    if (dims != sgan.architecture().dims)
      throw Error(data + ": the dataset's grid differs from the weights' grid (" + sgan.path() + ")");
    total += f.split.size();
    out.families.push_back(f.preset);
    families.push_back(std::move(f));
  }
  // The folders sorted, like the families: the output does not depend on the order --data
  // names them in (seventeenth campaign F10).
  {
    std::vector<std::string> folders;
    for (const Family& f : families) folders.push_back(f.data);
    std::sort(folders.begin(), folders.end());
    for (const std::string& folder : folders) out.data_label += (out.data_label.empty() ? "" : ", ") + folder;
  }

  ProgressBar bar(progress, "heuristic", total);
  std::size_t done = 0;
  for (const Family& family : families) {
    const world::GeneratorPreset preset = world::generator_preset(family.preset);
    for (const heuristic::Sample& s : family.split) {
      // The sample's own stream (noise seed + key, planner stream key), from what the sample is,
      // not where it falls in the run: a family's figures do not depend on the order of --data
      // or on which families are measured beside it (sixteenth campaign F23).
      const std::uint64_t k = sample_key(family.preset, s.map_seed);
      const world::Map map = world::generate_map(preset, s.map_seed);
      HeuristicSampleRecord rec;
      rec.family = family.preset;
      rec.map_seed = s.map_seed;
      const Clock::time_point t0 = Clock::now();
      const heuristic::HeuristicQuery q =
          heuristic::query_region(sgan, map, s.start, s.goal, preset.robot_radius, o.seed + k, true, o.strict_bridge);
      rec.region_ms = elapsed_ms(t0);
      rec.inference_ms = q.inference_ms;
      rec.raw_connected = q.report.raw_connected;
      rec.raw_safe = q.report.raw_safe;
      rec.connected = q.report.connected;
      rec.safe = q.report.safe;
      rec.raw_cells = q.report.raw_cells;
      rec.threshold = q.report.threshold;
      rec.widened = q.report.threshold < sgan.architecture().threshold;
      rec.cells = q.report.cells;
      rec.bridge_cells = q.report.bridge_cells;
      rec.strict_cells = q.report.strict_cells;
      rec.strict_witness = q.report.strict_connected;
      rec.filter_ms = q.filter_ms;
      // Strict quality (REQ-HEUR-011) on the map's voxels, raw and filtered.
      const world::VoxelGrid voxels(map, preset.robot_radius);
      const plan::HeuristicRegion raw(map.bounds(), sgan.architecture().dims,
                                      std::vector<double>(q.probabilities.begin(), q.probabilities.end()),
                                      q.report.threshold, "sgan-raw");  // the rule's (REQ-HEUR-016)
      const heuristic::StrictQuality raw_strict = heuristic::strict_quality(map, voxels, raw, s.start, s.goal);
      const heuristic::StrictQuality strict = heuristic::strict_quality(map, voxels, q.region, s.start, s.goal);
      const plan::HeuristicRegion truth(map.bounds(), sgan.architecture().dims,
                                        std::vector<double>(s.target.begin(), s.target.end()), 0.5, "astar-dilated");
      const heuristic::StrictQuality truth_strict = heuristic::strict_quality(map, voxels, truth, s.start, s.goal);
      rec.truth_connected_strict = truth_strict.connected;
      rec.truth_safe_strict = truth_strict.safe;
      rec.raw_connected_strict = raw_strict.connected;
      rec.raw_safe_strict = raw_strict.safe;
      rec.connected_strict = strict.connected;
      rec.safe_strict = strict.safe;
      if (o.planners) {
        const plan::PlanningProblem problem = plan::PlanningProblem::make(map, s.start, s.goal, preset.robot_radius);
        plan::PlannerOptions po;
        po.max_iterations = o.max_iterations;
        po.target_cost = o.target_factor * s.astar_cost;
        po.seed = o.seed;
        po.stream = k;  // common random numbers for the two planners
        po.planner = plan::PlannerKind::kMiner;
        rec.miner = plan::plan(problem, po, &q.region);
        plan::add_setup_time(rec.miner, rec.region_ms);
        po.planner = plan::PlannerKind::kRrtStar;
        rec.rrtstar = plan::plan(problem, po);
      }
      out.samples.push_back(std::move(rec));
      bar.update(++done);
    }
  }
  bar.finish();
  out.total_s = std::chrono::duration<double>(Clock::now() - t_start).count();
  return out;
}

namespace {

/// Quality, timing and planner figures over a set of samples (all, or one family's).
nlohmann::json quality_json(const std::vector<HeuristicSampleRecord>& samples, bool planners) {
  std::vector<double> inference, region, raw_cells, cells, filter, thresholds;
  std::size_t bridged = 0, strict_bridged = 0;
  for (const auto& s : samples) {
    thresholds.push_back(s.threshold);
    inference.push_back(s.inference_ms);
    filter.push_back(s.filter_ms);
    strict_bridged += s.strict_cells > 0 ? 1 : 0;
    region.push_back(s.region_ms);
    raw_cells.push_back(static_cast<double>(s.raw_cells));
    cells.push_back(static_cast<double>(s.cells));
    bridged += s.bridge_cells > 0 ? 1 : 0;
  }
  using R = HeuristicSampleRecord;
  // The share of the samples counted (0 for none).
  const auto share = [&](std::size_t count) {
    return static_cast<double>(count) / static_cast<double>(std::max<std::size_t>(samples.size(), 1));
  };
  nlohmann::json j = {{"samples", samples.size()},
                      {"connectivity_rate_raw", rate(samples, &R::raw_connected)},
                      {"safety_rate_raw", rate(samples, &R::raw_safe)},
                      {"connectivity_rate_filtered", rate(samples, &R::connected)},
                      {"safety_rate_filtered", rate(samples, &R::safe)},
                      {"connectivity_rate_strict", rate(samples, &R::raw_connected_strict)},
                      {"safety_rate_strict", rate(samples, &R::raw_safe_strict)},
                      {"connectivity_rate_strict_filtered", rate(samples, &R::connected_strict)},
                      {"safety_rate_strict_filtered", rate(samples, &R::safe_strict)},
                      {"connectivity_rate_strict_truth", rate(samples, &R::truth_connected_strict)},
                      {"safety_rate_strict_truth", rate(samples, &R::truth_safe_strict)},
                      {"bridged_rate", share(bridged)},
                      {"threshold_median", num(median(thresholds))},
                      {"widened_rate", rate(samples, &R::widened)},
                      {"raw_cells_median", num(median(raw_cells))},
                      {"cells_median", num(median(cells))},
                      {"strict_bridged_rate", share(strict_bridged)},
                      {"strict_witness_rate", rate(samples, &R::strict_witness)},
                      {"inference_ms", num(median(inference))},
                      {"filter_ms", num(median(filter))},
                      {"filter_ms_max", num(filter.empty() ? 0.0 : *std::max_element(filter.begin(), filter.end()))},
                      {"region_ms", num(median(region))}};
  if (planners) {
    j["miner"] = stage_summary(samples, &R::miner);
    j["rrtstar"] = stage_summary(samples, &R::rrtstar);
  }
  return j;
}

}  // namespace

nlohmann::json to_json(const HeuristicBenchResult& r) {
  nlohmann::json j = quality_json(r.samples, r.options.planners);
  j["data"] = r.data_label;
  j["split"] = r.options.split;
  j["preset"] = r.families.size() == 1 ? r.families.front() : std::string("mixed");
  j["weights"] = r.options.weights.empty() ? "builtin" : r.options.weights;
  j["seed"] = r.options.seed;
  j["total_s"] = r.total_s;
  if (r.options.planners) {
    j["max_iterations"] = r.options.max_iterations;
    j["target_factor"] = r.options.target_factor;
  }
  nlohmann::json families = nlohmann::json::object();
  for (const std::string& family : r.families) {
    std::vector<HeuristicSampleRecord> of;
    for (const auto& s : r.samples)
      if (s.family == family) of.push_back(s);
    families[family] = quality_json(of, r.options.planners);
  }
  j["families"] = families;
  return j;
}

std::string to_text(const HeuristicBenchResult& r) {
  const nlohmann::json j = to_json(r);
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "sGAN on " << r.data_label << " (" << r.options.split << ", " << r.samples.size() << " samples, preset "
    << j["preset"].get<std::string>() << ")\n"
    << "connectivity: raw " << 100.0 * j["connectivity_rate_raw"].get<double>() << " %, filtered "
    << 100.0 * j["connectivity_rate_filtered"].get<double>() << " %\n"
    << "safety:       raw " << 100.0 * j["safety_rate_raw"].get<double>() << " %, filtered "
    << 100.0 * j["safety_rate_filtered"].get<double>() << " %\n"
    << "strict (continuous map, REQ-HEUR-011): connectivity raw "
    << 100.0 * j["connectivity_rate_strict"].get<double>() << " %, filtered "
    << 100.0 * j["connectivity_rate_strict_filtered"].get<double>() << " %; safety raw "
    << 100.0 * j["safety_rate_strict"].get<double>() << " %, filtered "
    << 100.0 * j["safety_rate_strict_filtered"].get<double>() << " % (ground truth T: "
    << 100.0 * j["connectivity_rate_strict_truth"].get<double>() << " % / "
    << 100.0 * j["safety_rate_strict_truth"].get<double>() << " %)\n"
    << "bridged by the filter: " << 100.0 * j["bridged_rate"].get<double>() << " % of queries\n"
    << std::setprecision(2) << "median inference " << j["inference_ms"].get<double>() << " ms, region (encode + "
    << "inference + filter) " << j["region_ms"].get<double>() << " ms\n";
  if (r.options.planners) {
    s << "planner      success  target   first it  first ms  target it  target ms   (medians; region time in miner's)\n";
    for (const char* who : {"miner", "rrtstar"}) {
      const auto& p = j[who];
      auto cell = [](const nlohmann::json& v, int w) {
        std::ostringstream c;
        c << std::setw(w);
        if (v.is_null()) c << "-"; else c << std::fixed << std::setprecision(1) << v.get<double>();
        return c.str();
      };
      s << std::left << std::setw(12) << who << std::right << std::setw(7) << 100.0 * p["success_rate"].get<double>()
        << "%" << std::setw(7) << 100.0 * p["target_rate"].get<double>() << "%" << cell(p["first_iterations"], 11)
        << cell(p["first_time_ms"], 10) << cell(p["target_iterations"], 11) << cell(p["target_time_ms"], 11) << "\n";
    }
  }
  return s.str();
}

}  // namespace miner::bench
