#include "bench/heuristic_bench.hpp"

#include <chrono>
#include <iomanip>
#include <limits>
#include <sstream>

#include "bench/campaign_stats.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/world/map_generator.hpp"

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

}  // namespace

HeuristicBenchResult run_heuristic_bench(const HeuristicBenchOptions& o, std::ostream* progress) {
  if (o.samples < 0) throw Error("--samples: must be >= 0");
  if (o.max_iterations < 1) throw Error("--iterations: must be >= 1");
  if (!(o.target_factor > 0.0)) throw Error("--target-factor: must be > 0");
  const Clock::time_point t_start = Clock::now();
  const Json meta = read_json_file(o.data + "/dataset.json");
  HeuristicBenchResult out;
  out.options = o;
  out.preset = JsonField(meta, "", o.data + "/dataset.json").at("preset").string();
  const world::GeneratorPreset preset = world::generator_preset(out.preset);
  std::vector<heuristic::Sample> split = heuristic::read_split(o.data, o.split);
  if (o.samples > 0 && static_cast<std::size_t>(o.samples) < split.size()) split.resize(static_cast<std::size_t>(o.samples));
  if (split.empty()) throw Error(o.data + ": split '" + o.split + "' has no samples");
  const heuristic::Sgan sgan = heuristic::Sgan::load_or_builtin(o.weights);
  const Eigen::Vector3i dims(meta["dims"][0].get<int>(), meta["dims"][1].get<int>(), meta["dims"][2].get<int>());
  if (dims != sgan.architecture().dims)
    throw Error(o.data + ": the dataset's grid differs from the weights' grid (" + sgan.path() + ")");

  ProgressBar bar(progress, "heuristic", split.size());
  for (std::size_t k = 0; k < split.size(); ++k) {
    const heuristic::Sample& s = split[k];
    const world::Map map = world::generate_map(preset, s.map_seed);
    HeuristicSampleRecord rec;
    rec.map_seed = s.map_seed;
    const Clock::time_point t0 = Clock::now();
    const heuristic::HeuristicQuery q =
        heuristic::query_region(sgan, map, s.start, s.goal, preset.robot_radius, o.seed + k);
    rec.region_ms = elapsed_ms(t0);
    rec.inference_ms = q.inference_ms;
    rec.raw_connected = q.report.raw_connected;
    rec.raw_safe = q.report.raw_safe;
    rec.connected = q.report.connected;
    rec.safe = q.report.safe;
    rec.raw_cells = q.report.raw_cells;
    rec.cells = q.report.cells;
    rec.bridge_cells = q.report.bridge_cells;
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
    bar.update(k + 1);
  }
  bar.finish();
  out.total_s = std::chrono::duration<double>(Clock::now() - t_start).count();
  return out;
}

nlohmann::json to_json(const HeuristicBenchResult& r) {
  std::vector<double> inference, region, raw_cells, cells;
  std::size_t bridged = 0;
  for (const auto& s : r.samples) {
    inference.push_back(s.inference_ms);
    region.push_back(s.region_ms);
    raw_cells.push_back(static_cast<double>(s.raw_cells));
    cells.push_back(static_cast<double>(s.cells));
    bridged += s.bridge_cells > 0 ? 1 : 0;
  }
  nlohmann::json j = {{"data", r.options.data},
                      {"split", r.options.split},
                      {"preset", r.preset},
                      {"weights", r.options.weights.empty() ? "builtin" : r.options.weights},
                      {"samples", r.samples.size()},
                      {"seed", r.options.seed},
                      {"connectivity_rate_raw", rate(r.samples, &HeuristicSampleRecord::raw_connected)},
                      {"safety_rate_raw", rate(r.samples, &HeuristicSampleRecord::raw_safe)},
                      {"connectivity_rate_filtered", rate(r.samples, &HeuristicSampleRecord::connected)},
                      {"safety_rate_filtered", rate(r.samples, &HeuristicSampleRecord::safe)},
                      {"bridged_rate", static_cast<double>(bridged) / static_cast<double>(std::max<std::size_t>(r.samples.size(), 1))},
                      {"raw_cells_median", num(median(raw_cells))},
                      {"cells_median", num(median(cells))},
                      {"inference_ms", num(median(inference))},
                      {"region_ms", num(median(region))},
                      {"total_s", r.total_s}};
  if (r.options.planners) {
    j["max_iterations"] = r.options.max_iterations;
    j["target_factor"] = r.options.target_factor;
    j["miner"] = stage_summary(r.samples, &HeuristicSampleRecord::miner);
    j["rrtstar"] = stage_summary(r.samples, &HeuristicSampleRecord::rrtstar);
  }
  return j;
}

std::string to_text(const HeuristicBenchResult& r) {
  const nlohmann::json j = to_json(r);
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "sGAN on " << r.options.data << " (" << r.options.split << ", " << r.samples.size() << " samples, preset "
    << r.preset << ")\n"
    << "connectivity: raw " << 100.0 * j["connectivity_rate_raw"].get<double>() << " %, filtered "
    << 100.0 * j["connectivity_rate_filtered"].get<double>() << " %\n"
    << "safety:       raw " << 100.0 * j["safety_rate_raw"].get<double>() << " %, filtered "
    << 100.0 * j["safety_rate_filtered"].get<double>() << " %\n"
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
