#include "bench/paper_bench.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "bench/campaign_stats.hpp"
#include "bench/results_text.hpp"
#include "bench/ompl_planners.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/text.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"
#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/report/svg_plot.hpp"
#include "miner/world/map.hpp"

namespace miner::bench {

namespace {

using Clock = std::chrono::steady_clock;

/// See unseen_heuristic_seed() (paper_bench.hpp).
constexpr std::uint64_t kUnseenSalt = 0x9E3779B97F4A7C15ull;

/// The paper's Table I (sim maps 1-3): initial iteration, nodes, cost, time (ms),
/// optimal iteration, nodes, time (ms).
struct PaperFrontRow {
  const char* method;
  double v[7];
};
const PaperFrontRow kPaperTable1[3][4] = {
    {{"RRT*", {737.0, 590.4, 99.4, 2.1, 34007.9, 30579.4, 491.1}},
     {"I-RRT*", {899.1, 746.2, 100.5, 2.5, 4118.1, 3592.4, 31.9}},
     {"G-RRT*", {842.2, 685.9, 102.9, 2.8, 14276.4, 12995.9, 102.4}},
     {"Ours", {156.9, 146.9, 82.4, 1.2, 437.9, 415.4, 5.3}}},
    {{"RRT*", {1729.1, 1438.1, 101.4, 7.3, 17095.8, 15549.6, 135.0}},
     {"I-RRT*", {1536.8, 1286.1, 102.6, 6.2, 3816.5, 3274.0, 27.1}},
     {"G-RRT*", {1503.5, 1251.5, 102.0, 5.0, 6160.9, 5673.8, 45.4}},
     {"Ours", {122.4, 113.5, 84.7, 1.2, 221.7, 210.4, 3.1}}},
    {{"RRT*", {1379.0, 1174.0, 99.6, 7.0, 11480.1, 10499.2, 88.3}},
     {"I-RRT*", {2192.7, 1882.3, 99.3, 10.2, 3930.5, 3519.0, 26.5}},
     {"G-RRT*", {1937.9, 1706.8, 98.0, 9.9, 5680.8, 5294.3, 44.3}},
     {"Ours", {209.7, 198.5, 81.9, 2.0, 380.7, 314.2, 4.6}}}};
/// `miner` samples the A*-dilated region built from the same A* path that defines the
/// target: an upper bound on what a learned region can give, never a headline.
constexpr const char* kOraclePlanner = "miner";

/// The paper's planner names for the project's planners.
const char* paper_name(const std::string& planner) {
  if (planner == "rrtstar") return "RRT*";
  if (planner == "informed") return "I-RRT*";
  if (planner == "guided") return "G-RRT*";
  if (planner == "miner-sgan") return "Ours";
  return nullptr;
}
/// Table II: initial time (ms) of RRT* and of MINER per map, then min-jerk / min-snap time
/// (ms) per back-end method.
const double kPaperInitial[3][2] = {{2.10, 1.29}, {7.31, 1.20}, {7.01, 2.08}};
struct PaperBackRow {
  const char* method;
  const char* label;
  double jerk_snap[3][2];
};
const PaperBackRow kPaperTable2[] = {
    {"kkt-qp", "QP (Mellinger)", {{0.550, 1.445}, {0.375, 0.597}, {0.464, 1.023}}},
    {"closed-form", "Closed form (Bry, Oleynikova)", {{2.618, 4.390}, {1.809, 2.821}, {2.575, 4.839}}},
    {"minco", "Optimal condition (Wang; ours)", {{0.0023, 0.0043}, {0.0022, 0.0040}, {0.0024, 0.0045}}},
};
const double kPaperConnectivity = 0.963, kPaperSafety = 0.971;
/// The paper's tracking MSE (real flights, Map1 and Map2).
const double kPaperMse[2][6] = {{0.0513, 0.0919, 0.0003, 0.0222, 0.0285, 0.0006},
                                {0.0716, 0.1089, 0.0004, 0.0237, 0.0115, 0.0008}};

std::string f(double v, int digits) { return fixed(v, digits); }

std::string pct(double v) { return std::isfinite(v) ? f(100.0 * v, 1) + " %" : "—"; }


std::string map_label(const std::string& path) { return std::filesystem::path(path).stem().string(); }


const BackendRecord* find_record(const std::vector<BackendRecord>& records, const std::string& method, int order) {
  for (const auto& r : records)
    if (r.method == method && r.order == order && !r.skipped) return &r;
  return nullptr;
}

/// The map's headline, generated from its campaign: the fastest planner to the target and
/// to the first solution (medians, misses as +inf) among every planner run except the
/// oracle, miner-sgan's ratio to it, and whether the paper's claims reproduce here.

std::string headline(const FrontendBenchResult& fr, const std::vector<std::string>& planners) {
  std::vector<std::string> set;
  for (const auto& p : planners)
    if (p != kOraclePlanner && find_summary(fr, p)) set.push_back(p);
  const auto value = [](const PlannerSummary* s, bool target) {
    const double v = target ? s->target_time_ms : s->first_time_ms;
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  std::ostringstream h;
  h << "**Headline (generated; comparison set: " << set.size() << " planners, every one run here except the oracle: ";
  for (std::size_t i = 0; i < set.size(); ++i) h << (i ? ", " : "") << "`" << set[i] << "`";
  h << ").**";
  const PlannerSummary* ours = find_summary(fr, kMinerSgan);
  for (const bool target : {true, false}) {
    const char* stage = target ? "the target" : "the first solution";
    std::string best;
    double best_v = std::numeric_limits<double>::infinity();
    for (const auto& p : set) {
      const double v = value(find_summary(fr, p), target);
      if (v < best_v) best_v = v, best = p;
    }
    if (best.empty()) {
      h << " No planner reached " << stage << " in half its runs.";
      continue;
    }
    h << " Fastest to " << stage << " (median): `" << best << "`, " << f(best_v, 2) << " ms.";
    if (!ours) continue;
    const double mine = value(ours, target);
    if (best == kMinerSgan) {
      // The margin over the runner-up.
      double second = std::numeric_limits<double>::infinity();
      for (const auto& p : set)
        if (p != kMinerSgan) second = std::min(second, value(find_summary(fr, p), target));
      h << " miner-sgan is the fastest, " << (std::isfinite(second) ? f(second / mine, 2) + "x" : std::string("alone"))
        << " ahead of the next.";
    } else {
      h << " miner-sgan: " << (std::isfinite(mine) ? f(mine, 2) + " ms, " + f(mine / best_v, 2) + "x the fastest" : "—")
        << ".";
    }
    h << " The paper's claim (MINER reaches " << stage << " before every baseline) "
      << (best == kMinerSgan ? "reproduces" : "does **not** reproduce") << " on this map.";
  }
  return h.str();
}

}  // namespace

PaperBenchResult run_paper_bench(const PaperBenchOptions& o, const std::string& command, std::ostream* progress) {
  if (o.maps.empty()) throw Error("bench paper: --maps needs at least one map");
  if (o.runs < 1) throw Error("bench paper: --runs must be >= 1");
  if (o.heuristic_samples < 1) throw Error("bench paper: --heuristic-samples must be >= 1");
  // More heuristic samples than the given folder's test split holds is refused before any run,
  // naming this command's option (session 23 review: it failed after every other table, naming
  // bench heuristic's --samples). The count is the test shards' the folder holds.
  // The folder's test split is read and checked whole before any campaign (seventh campaign
  // C5: a corrupt shard was found after 20 s of campaigns).
  if (!o.heuristic_data.empty()) (void)heuristic::read_split(o.heuristic_data, "test");
  if (!o.heuristic_data.empty() && o.heuristic_samples_given) {
    const std::size_t held = heuristic::split_samples_held(o.heuristic_data, "test");
    if (held < static_cast<std::size_t>(o.heuristic_samples))
      throw Error("--heuristic-samples " + std::to_string(o.heuristic_samples) + ": " + o.heuristic_data +
                  ": split 'test' has only " + std::to_string(held) +
                  " samples (give at most that many, or leave the option out to measure them all)");
  }
  const auto t0 = Clock::now();
  PaperBenchResult out;
  out.options = o;
  out.command = command;
  out.commit = git_commit();
  // Load everything first: a bad map or scenario fails before minutes of benchmarking.
  // The back end's whole time is bounded like `bench backend`'s, checked before any work.
  {
    const double total = o.backend_budget_s * 8.0 * static_cast<double>(o.maps.size());  // 4 methods x 2 orders
    if (total > kMaxBackendTotalSeconds)
      throw Error("--backend-budget: " + std::to_string(o.backend_budget_s) + " s x 4 methods x 2 orders x " +
                      std::to_string(o.maps.size()) + " maps is over the " +
                      std::to_string(static_cast<int>(kMaxBackendTotalSeconds)) + " s bound",
                  ExitCode::kUsage);
  }
  // The weights too (issue 20, fourth campaign: a file that is not weights was refused only
  // after the front-end campaign).
  if (!o.weights.empty()) (void)heuristic::Sgan::load(o.weights);
  // An input given twice under two names (two files of one content; a scenario whose map is
  // inlined once and referenced once) would run its campaign twice and count it twice.
  const auto refuse_repeats = [](const std::vector<Json>& docs, const std::vector<std::string>& names,
                                 const std::string& option, const std::string& what) {
    if (const auto same = first_repeated(docs))
      throw Error(option + ": " + names[same->second] + " is the same " + what + " as " + names[same->first] +
                  ": each is run once");
  };
  std::vector<world::Map> maps;
  std::vector<Json> map_docs;
  for (const auto& path : o.maps) {
    maps.push_back(world::Map::load(path));
    if (!maps.back().query()) throw Error(path + ": the map stores no query (start, goal, robot radius)");
    map_docs.push_back(maps.back().to_json());
  }
  refuse_repeats(map_docs, o.maps, "--maps", "map");
  std::vector<pipeline::Scenario> scenarios;
  std::vector<Json> scenario_docs;
  std::vector<std::string> scenario_names;
  if (o.scenarios.empty()) {
    scenarios.push_back(pipeline::default_scenario());
    scenario_docs.push_back(scenarios.back().map->to_json());
    scenario_names.push_back("indoor-1 (the default scenario's map)");
    for (const auto& m : o.tracking_maps) {
      Json doc = pipeline::default_scenario_document();
      doc["map"] = read_json_file(m);
      doc["name"] = map_label(m);
      scenarios.push_back(pipeline::scenario_from_json(doc, m, ""));
      scenario_docs.push_back(scenarios.back().map->to_json());
      scenario_names.push_back(m);
    }
    refuse_repeats(scenario_docs, scenario_names, "--tracking-maps", "map");
  } else {
    for (const auto& s : o.scenarios) {
      scenarios.push_back(pipeline::load_scenario(s));
      Json doc = pipeline::self_contained_scenario(read_json_file(s), std::filesystem::path(s).parent_path().string());
      if (doc.is_object()) doc.erase("name");  // a name does not change the flight
      scenario_docs.push_back(std::move(doc));
    }
    refuse_repeats(scenario_docs, o.scenarios, "--scenarios", "scenario");
  }
  if (!o.weights.empty())
    for (auto& s : scenarios) s.weights = o.weights;

  // Table I and the box plots.
  for (std::size_t i = 0; i < maps.size(); ++i) {
    if (progress) *progress << "front end on " << o.maps[i] << "\n";
    const FrontendBenchOptions fo = frontend_options_of(o);
    const auto& q = *maps[i].query();
    out.grid_resolution.push_back(maps[i].resolution());
    out.frontend.push_back(
        run_frontend_bench(maps[i], map_label(o.maps[i]), q.start, q.goal, q.robot_radius, fo, progress));
  }
  // Table II: the back end on the path of MINER (sGAN)'s first solved run, else RRT*'s.
  BackendBenchOptions bo;
  bo.budget_s = o.backend_budget_s;
  bo.methods = {"minco", "closed-form", "kkt-qp", "dense-lu"};
  for (const auto& fr : out.frontend) {
    const plan::PlanResult* path = nullptr;
    std::string source;
    for (const char* who : {"miner-sgan", "rrtstar"})
      for (const auto& run : fr.runs)
        if (!path && run.planner == who && run.result.solved) {
          path = &run.result;
          source = std::string(who) + " run " + std::to_string(run.run);
        }
    out.backend_source.push_back(source);
    if (!path) {
      out.backend.emplace_back();
      out.backend_segments.push_back(0);
      continue;
    }
    Eigen::MatrixX3d points(static_cast<Eigen::Index>(path->path.size()), 3);
    for (std::size_t k = 0; k < path->path.size(); ++k) points.row(static_cast<Eigen::Index>(k)) = path->path[k].transpose();
    out.backend.push_back(run_backend_on_path(points, traj::Limits{2.0, 1.0}, bo));
    out.backend_segments.push_back(path->path.size() - 1);
  }
  // Heuristic quality.
  HeuristicBenchOptions ho;
  // A given folder is measured whole unless --heuristic-samples says how much of it (the
  // default 100 is the size of the set generated below, not a cap on a user's split).
  ho.samples = o.heuristic_data.empty() || o.heuristic_samples_given ? o.heuristic_samples : 0;
  ho.samples_option = "--heuristic-samples";
  ho.weights = o.weights;
  ho.seed = o.seed;
  ho.max_iterations = o.heuristic_iterations;
  std::string generated;
  if (o.heuristic_data.empty()) {
    generated = (std::filesystem::temp_directory_path() / ("miner-paper-data-" + std::to_string(::getpid()))).string();
    heuristic::DatasetOptions d;
    d.count = 1;  // the test split alone is used: map seeds after the first `count`
    d.test_count = o.heuristic_samples;
    d.seed = unseen_heuristic_seed(o.seed);
    d.jobs = std::max(1, o.jobs);
    if (progress) *progress << "generating " << o.heuristic_samples << " unseen heuristic test samples\n";
    heuristic::write_dataset(d, generated, progress);
    ho.data = {generated};
  } else {
    ho.data = {o.heuristic_data};
  }
  try {
    out.heuristic = run_heuristic_bench(ho, progress);
  } catch (...) {
    if (!generated.empty()) std::filesystem::remove_all(generated);
    throw;
  }
  if (!generated.empty()) {
    std::filesystem::remove_all(generated);
    out.heuristic.data_label = "(generated: miner dataset --count 1 --test-count " +
                                 std::to_string(o.heuristic_samples) + " --seed " +
                                 std::to_string(unseen_heuristic_seed(o.seed)) + ")";
  }
  // Tracking.
  for (const auto& s : scenarios) {
    if (progress) *progress << "flying " << s.name << "\n";
    const auto reference = pipeline::build_reference(s);
    const auto r = pipeline::fly(s, reference);
    out.tracking.push_back({s.name, r.position_mse, r.velocity_mse, r.max_position_error, r.collisions, r.goal_reached,
                            reference_label(s, reference)});
  }
  out.total_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::map<std::string, std::string> results_figures(const PaperBenchResult& r) {
  std::map<std::string, std::string> figures;
  for (const auto& fr : r.frontend) {
    std::vector<report::BoxGroup> first, target;
    for (const auto& planner : r.options.planners) {
      report::BoxGroup a{planner, {}}, b{planner, {}};
      for (const auto& run : fr.runs) {
        if (run.planner != planner) continue;
        // A run that never got there is shown as a miss, not dropped (issue 17 item 3).
        if (run.result.first) a.values.push_back(run.result.first->time_ms);
        else ++a.missed;
        if (run.result.target) b.values.push_back(run.result.target->time_ms);
        else ++b.missed;
      }
      first.push_back(a);
      target.push_back(b);
    }
    const int width = 110 * static_cast<int>(std::max<std::size_t>(r.options.planners.size(), 4));
    figures[fr.map + "-first.svg"] = report::svg_box_plot(
        {fr.map + ": time to the first solution", "", "ms (log)", width, 300}, first, true);
    figures[fr.map + "-target.svg"] = report::svg_box_plot(
        {fr.map + ": time to the target cost (A* cost x " + f(fr.target_cost / fr.reference_cost, 2) + ")",
         "", "ms (log)", width, 300},
        target, true);
  }
  return figures;
}

std::uint64_t unseen_heuristic_seed(std::uint64_t seed) { return seed ^ kUnseenSalt; }

std::string reference_label(const pipeline::Scenario& s, const pipeline::ReferencePlan& reference) {
  const std::string minco = std::string("min-") + (s.order == 3 ? "jerk" : "snap") + " MINCO";
  if (reference.source == "file") return "trajectory file";
  if (reference.source == "waypoints") return minco + " through the scenario's waypoints";
  return "MINER RRT* on the " + (reference.region ? reference.region->source() : std::string("no")) + " region + " +
         minco;
}

std::string results_markdown(const PaperBenchResult& r, const std::string& figure_dir) {
  std::ostringstream md;
  md << "# Results: the paper's tables reproduced\n\n"
     << "Generated by `" << r.command << "` at commit `" << r.commit << "` (" << f(r.total_s, 0)
     << " s). The paper's numbers come from its own hardware (and, for tracking, real flights); ours from this "
        "machine, single-threaded. Times are wall clock and vary between runs and machines; iterations, nodes "
        "and costs are deterministic for the seed for our planners and OMPL's RRT*s, which stop at an iteration "
        "count; OMPL's other planners stop on the clock, so theirs vary from run to run (`miner bench frontend "
        "--ompl-checks N` repeats them). Method: docs/report.md.\n\n";

  md << "## Table I: front end (medians over " << r.options.runs << " runs per planner)\n\n"
     << "Columns as in the paper: initial = first solution, optimal = first time the cost is at or below the "
        "target (the A* path's length on the map's own grid, its resolution in each map's heading; the paper's "
        "\"asymptotic optimal cost\" is not given). \"Ours\" is MINER RRT* sampling the sGAN's filtered region with "
        "the region's time (encoding, inference, filter) included. A dash: no value (no more than half the runs got there, "
        "or OMPL does not report it). OMPL's planners run under a " << f(r.options.time_limit_s, 1)
     << " s limit per run.\n\n";
  for (std::size_t i = 0; i < r.frontend.size(); ++i) {
    const auto& fr = r.frontend[i];
    md << "### Map " << (i + 1) << " (" << fr.map << ", A* cost " << f(fr.reference_cost, 1) << " m on its "
       << short_number(r.grid_resolution.at(i)) << " m grid)\n\n"
       << "| method | source | success | initial iteration | initial nodes | initial cost (m) | initial time (ms) "
          "| optimal iteration | optimal nodes | optimal time (ms) | n | target reached | optimal time mean ± sd (ms, reached runs) "
          "| optimal time median [IQR] (ms, misses as +inf) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& planner : r.options.planners) {
      const PlannerSummary* s = find_summary(fr, planner);
      if (!s) continue;
      const char* pn = paper_name(planner);
      if (pn && i < 3)
        for (const auto& row : kPaperTable1[i])
          if (std::string(row.method) == pn)
            md << "| " << pn << " | paper | — | " << f(row.v[0], 1) << " | " << f(row.v[1], 1) << " | "
               << f(row.v[2], 1) << " | " << f(row.v[3], 1) << " | " << f(row.v[4], 1) << " | " << f(row.v[5], 1)
               << " | " << f(row.v[6], 1) << " | 50 (means) | — | — | — |\n";
      const bool ompl = is_ompl_planner(planner);
      md << "| " << (pn ? pn : planner == kOraclePlanner ? "A* oracle region (upper bound)" : planner.c_str()) << " | "
         << (ompl ? "OMPL " : "MINER ") << "`" << planner << "` | "
         << pct(s->success_rate) << " | " << f(s->first_iterations, 1) << " | " << f(s->first_nodes, 1) << " | "
         << f(s->first_cost, 1) << " | " << f(s->first_time_ms, 2) << " | " << f(s->target_iterations, 1) << " | "
         << f(s->target_nodes, 1) << " | " << f(s->target_time_ms, 2) << " | " << s->runs << " | " << s->target_reached
         << "/" << s->runs << " | " << f(s->target_time_ms_mean, 2) << " ± " << f(s->target_time_ms_sd, 2) << " | "
         << f(s->target_time_ms, 2) << " [" << f(s->target_time_ms_q1, 2) << ", " << f(s->target_time_ms_q3, 2)
         << "] |\n";
    }
    md << "\n" << headline(fr, r.options.planners) << "\n";
    md << "\n![" << fr.map << " first](" << figure_dir << "/" << fr.map << "-first.svg) ![" << fr.map << " target]("
       << figure_dir << "/" << fr.map << "-target.svg)\n\n";
  }

  const auto h = to_json(r.heuristic);
  md << "## Heuristic quality (" << r.heuristic.samples.size() << " unseen maps)\n\n"
     << "Data: " << r.heuristic.data_label << ". Exact definitions of connected and safe: spec/heuristic.md "
        "REQ-HEUR-004. Raw = the network's thresholded output; filtered = after Alg. 1 line 3's filter.\n\n"
     << "| method | connectivity rate | safety rate |\n|---|---|---|\n"
     << "| Li et al. (paper) | 91.53 % | 91.90 % |\n| Ma et al. (paper) | 91.80 % | 92.40 % |\n"
     << "| Ours (paper) | " << pct(kPaperConnectivity) << " | " << pct(kPaperSafety) << " |\n"
     << "| MINER sGAN, raw | " << pct(h["connectivity_rate_raw"].get<double>()) << " | "
     << pct(h["safety_rate_raw"].get<double>()) << " |\n"
     << "| MINER sGAN, filtered | " << pct(h["connectivity_rate_filtered"].get<double>()) << " | "
     << pct(h["safety_rate_filtered"].get<double>()) << " |\n\n";
  const auto ms = [&](const char* k) { return h[k].is_number() ? f(h[k].get<double>(), 2) : std::string("—"); };
  md << "Inference median " << ms("inference_ms") << " ms, whole region query " << ms("region_ms") << " ms.";
  if (h.contains("miner") && h.contains("rrtstar")) {
    const auto stage = [&](const char* who, const char* k) {
      return h[who][k].is_number() ? f(h[who][k].get<double>(), 1) : std::string("—");
    };
    md << " On the same queries (budget " << r.options.heuristic_iterations
       << " iterations), median iterations to the target: MINER " << stage("miner", "target_iterations")
       << ", RRT* " << stage("rrtstar", "target_iterations") << "; time to the target: MINER "
       << stage("miner", "target_time_ms") << " ms, RRT* " << stage("rrtstar", "target_time_ms") << " ms.";
  }
  md << "\n\n";

  md << "## Table II: front end + back end (ms)\n\n"
     << "Initial time: median time to the first solution (Table I). Back end: minimum jerk / minimum snap solve "
        "on the waypoints of a path found on the same map (MINER (sGAN)'s first solved run, else RRT*'s; which one "
        "is listed below the table), durations by trapezoidal allocation (v_max 2, "
        "a_max 1), median of timed batches. The paper's MINCO row is Wang et al.'s code; ours is this "
        "project's O(M) solver.\n\n"
     << "| method | source |";
  for (const auto& fr : r.frontend) md << " " << fr.map << " |";
  md << "\n|---|---|";
  for (std::size_t i = 0; i < r.frontend.size(); ++i) md << "---|";
  md << "\n";
  const auto backend_ms = [&](std::size_t i, const char* method, int order) {
    const BackendRecord* b = find_record(r.backend[i], method, order);
    return b ? f(b->us_per_solve / 1000.0, 4) : std::string("—");
  };
  for (const auto& row : kPaperTable2) {
    md << "| RRT* + " << row.label << " | paper |";
    for (std::size_t i = 0; i < r.frontend.size(); ++i)
      md << " " << (i < 3 ? f(kPaperInitial[i][0], 2) + " + " + f(row.jerk_snap[i][0], 4) + "/" + f(row.jerk_snap[i][1], 4)
                          : std::string("—"))
         << " |";
    md << "\n| RRT* + " << row.label << " | MINER |";
    for (std::size_t i = 0; i < r.frontend.size(); ++i) {
      const PlannerSummary* s = find_summary(r.frontend[i], "rrtstar");
      md << " " << (s ? f(s->first_time_ms, 2) : std::string("—")) << " + " << backend_ms(i, row.method, 3) << "/"
         << backend_ms(i, row.method, 4) << " |";
    }
    md << "\n";
  }
  md << "| MINER-RRT* (ours) | paper |";
  for (std::size_t i = 0; i < r.frontend.size(); ++i)
    md << " " << (i < 3 ? f(kPaperInitial[i][1], 2) + " + " + f(kPaperTable2[2].jerk_snap[i][0], 4) + "/" +
                              f(kPaperTable2[2].jerk_snap[i][1], 4)
                        : std::string("—"))
       << " |";
  md << "\n| MINER-RRT* (ours) | MINER (`miner-sgan`) |";
  for (std::size_t i = 0; i < r.frontend.size(); ++i) {
    const PlannerSummary* s = find_summary(r.frontend[i], "miner-sgan");
    md << " " << (s ? f(s->first_time_ms, 2) : std::string("—")) << " + " << backend_ms(i, "minco", 3) << "/"
       << backend_ms(i, "minco", 4) << " |";
  }
  md << "\n| dense LU (extra baseline) | MINER |";
  for (std::size_t i = 0; i < r.frontend.size(); ++i)
    md << " " << backend_ms(i, "dense-lu", 3) << "/" << backend_ms(i, "dense-lu", 4) << " |";
  md << "\n\nPath per map:";
  for (std::size_t i = 0; i < r.frontend.size(); ++i)
    md << " " << r.frontend[i].map << " "
       << (r.backend_source.at(i).empty() ? std::string("none (neither miner-sgan nor rrtstar solved it)")
                                          : r.backend_source[i] + ", " + std::to_string(r.backend_segments[i]) + " segments")
       << ";";
  md << " OMPL has no trajectory back end, so it has no row here.\n\n";

  md << "## Tracking error (MSE)\n\n"
     << "The paper flew a real quadrotor (Map1, Map2); ours are closed-loop simulations (CVODE dynamics, emulated "
        "N3, EKF on noisy IMU and pose, SE(3) PID) of the scenarios listed, each row naming its reference. "
        "m^2 and (m/s)^2.\n\n"
     << "| env. | source | pos. x | pos. y | pos. z | vel. x | vel. y | vel. z | max error (m) | collisions | reference |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (int k = 0; k < 2; ++k) {
    md << "| Map" << (k + 1) << " | paper (real flight) |";
    for (double v : kPaperMse[k]) md << " " << f(v, 4) << " |";
    md << " — | — | real flight |\n";
  }
  for (const auto& t : r.tracking) {
    md << "| " << t.env << " | MINER (simulation) |";
    for (int a = 0; a < 3; ++a) md << " " << f(t.position_mse[a], 4) << " |";
    for (int a = 0; a < 3; ++a) md << " " << f(t.velocity_mse[a], 4) << " |";
    md << " " << f(t.max_position_error, 3) << " | " << t.collisions << (t.goal_reached ? "" : " (goal NOT reached)")
       << " | " << t.reference << " |\n";
  }
  return md.str();
}

nlohmann::json to_json(const PaperBenchResult& r) {
  nlohmann::json j{{"commit", r.commit}, {"command", r.command}, {"total_s", r.total_s}};
  j["frontend"] = nlohmann::json::array();
  for (const auto& fr : r.frontend) j["frontend"].push_back(to_json(fr));
  j["backend"] = nlohmann::json::array();
  for (const auto& b : r.backend) j["backend"].push_back(to_json(b));
  j["heuristic"] = to_json(r.heuristic);
  j["tracking"] = nlohmann::json::array();
  for (const auto& t : r.tracking)
    j["tracking"].push_back({{"env", t.env},
                             {"position_mse", {t.position_mse.x(), t.position_mse.y(), t.position_mse.z()}},
                             {"velocity_mse", {t.velocity_mse.x(), t.velocity_mse.y(), t.velocity_mse.z()}},
                             {"max_position_error", t.max_position_error},
                             {"collisions", t.collisions},
                             {"goal_reached", t.goal_reached},
                             {"reference", t.reference}});
  return j;
}

}  // namespace miner::bench
