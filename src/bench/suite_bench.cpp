#include "bench/suite_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <sstream>

#include "bench/campaign_stats.hpp"
#include "bench/results_text.hpp"
#include "bench/ompl_planners.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/text.hpp"
#include "miner/report/svg_plot.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_layer.hpp"

namespace miner::bench {

namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kSuiteFormat = "miner-bench-suite-v1";
/// `miner` samples the A*-dilated region built from the A* path that defines the target: an
/// upper bound, never in a headline.
constexpr const char* kOraclePlanner = "miner";

std::string f(double v, int digits) { return fixed(v, digits); }



/// The runs' values of one stage (`target` or first solution), +inf for a miss.
std::vector<double> stage_values(const FrontendBenchResult& r, const std::string& planner, bool target, bool time) {
  std::vector<double> v;
  for (const auto& run : r.runs) {
    if (run.planner != planner) continue;
    const auto& stage = target ? run.result.target : run.result.first;
    // A counter OMPL does not report (RRTConnect's iterations) is NaN, not kUnknownCount's
    // 1.8e19 (the suite's tables printed "18446744073709551616 ± 0").
    if (!stage) v.push_back(std::numeric_limits<double>::infinity());
    else if (time) v.push_back(stage->time_ms);
    else v.push_back(stage->iteration == kUnknownCount ? std::numeric_limits<double>::quiet_NaN()
                                                       : static_cast<double>(stage->iteration));
  }
  return v;
}

/// "mean ± sd" over the runs that got there, and "median [q1, q3]" over all runs with a
/// miss as +inf ("miss" where a quantile lands on one).
bool any_uncounted(const std::vector<double>& v) {
  return std::any_of(v.begin(), v.end(), [](double x) { return std::isnan(x); });
}
/// Written in place of an iteration figure the planner does not count.
constexpr const char* kUncounted = "not counted by the planner";

std::string mean_sd(const std::vector<double>& v, int digits) {
  if (any_uncounted(v)) return kUncounted;
  std::vector<double> reached;
  for (double x : v)
    if (std::isfinite(x)) reached.push_back(x);
  if (reached.empty()) return "—";
  return f(mean(reached), digits) + " ± " + f(stddev(reached), digits);
}
std::string median_iqr(const std::vector<double>& v, int digits) {
  if (v.empty()) return "—";
  if (any_uncounted(v)) return kUncounted;
  const auto q = [&](double p) {
    const double x = quantile(v, p);
    return std::isfinite(x) ? f(x, digits) : std::string("miss");
  };
  return q(0.5) + " [" + q(0.25) + ", " + q(0.75) + "]";
}
int reached(const std::vector<double>& v) {
  return static_cast<int>(std::count_if(v.begin(), v.end(), [](double x) { return std::isfinite(x); }));
}

std::string planner_label(const std::string& planner) {
  if (planner == kOraclePlanner) return "`miner` (A* oracle region, upper bound)";
  return "`" + planner + "`";
}

double finite_or_inf(double v) { return std::isfinite(v) ? v : std::numeric_limits<double>::infinity(); }

/// Our planners and their OMPL counterparts (issue 17 item 2).
const std::pair<const char*, const char*> kCounterparts[] = {{"rrtstar", "ompl:RRTstar"},
                                                             {"informed", "ompl:InformedRRTstar"}};
/// Two-sided significance level of "slower" in the headlines.
constexpr double kSignificance = 0.05;

struct Comparison {
  bool run = false;  ///< both planners are in the campaign
  double ours_ms = NAN, theirs_ms = NAN, ours_it = NAN, theirs_it = NAN, p = NAN;
  bool slower = false;       ///< our median time to the target is above theirs (misses as +inf)
  bool significant = false;  ///< and the Mann-Whitney test on the times says so at kSignificance
};

Comparison compare(const FrontendBenchResult& fr, const std::string& ours, const std::string& theirs) {
  Comparison c;
  const auto a = stage_values(fr, ours, true, true), b = stage_values(fr, theirs, true, true);
  if (a.empty() || b.empty()) return c;
  c.run = true;
  c.ours_ms = median(a);
  c.theirs_ms = median(b);
  c.ours_it = median(stage_values(fr, ours, true, false));
  c.theirs_it = median(stage_values(fr, theirs, true, false));
  c.p = mann_whitney_p(a, b);
  c.slower = finite_or_inf(c.ours_ms) > finite_or_inf(c.theirs_ms);
  c.significant = c.slower && c.p < kSignificance;
  return c;
}

/// Generated headline of one campaign: the fastest planner to the target (median time,
/// misses as +inf) among every planner except the oracle, miner-sgan's ratio to it, and
/// our RRT* / Informed RRT* against OMPL's (issue 17 item 2).
std::string cell_headline(const FrontendBenchResult& fr, const std::vector<std::string>& planners) {
  std::ostringstream h;
  std::string best;
  double best_v = std::numeric_limits<double>::infinity();
  for (const auto& p : planners) {
    if (p == kOraclePlanner) continue;
    const PlannerSummary* s = find_summary(fr, p);
    if (s && finite_or_inf(s->target_time_ms) < best_v) best_v = s->target_time_ms, best = p;
  }
  if (best.empty()) {
    h << "No planner (oracle aside) reached the target in half its runs.";
  } else {
    h << "Fastest to the target (median, oracle aside): `" << best << "` " << f(best_v, 1) << " ms.";
    if (const PlannerSummary* s = find_summary(fr, kMinerSgan); s && best != kMinerSgan)
      h << " `miner-sgan`: " << (std::isfinite(s->target_time_ms) ? f(s->target_time_ms / best_v, 2) + "x the fastest"
                                                                      : std::string("no more than half its runs reached it"))
        << ".";
  }
  for (const auto& [ours, theirs] : kCounterparts) {
    const Comparison c = compare(fr, ours, theirs);
    if (!c.run) continue;
    h << " `" << ours << "` vs `" << theirs << "` to the target: " << f(c.ours_ms, 1) << " vs " << f(c.theirs_ms, 1)
      << " ms, " << f(c.ours_it, 0) << " vs " << f(c.theirs_it, 0) << " iterations ("
      << (c.slower ? (c.significant ? "**slower**" : "slower, not significantly") : "no slower")
      << ", Mann-Whitney p = " << f(c.p, 2) << " on the times);";
  }
  std::string s = h.str();
  if (!s.empty() && s.back() == ';') s.back() = '.';
  return s;
}

/// The suite's headline, generated from every campaign: who is fastest to the target how
/// often (every planner run except the oracle), miner-sgan against the fastest other
/// planner and against issue 16's bar (5x faster than every other planner), and our RRT* and
/// Informed RRT* against OMPL's.
std::string suite_headline(const SuiteBenchResult& r) {
  std::map<std::string, int> fastest;
  int sgan_fastest = 0, sgan_five = 0, sgan_run = 0;
  double worst_ratio = 0.0, best_ratio = std::numeric_limits<double>::infinity();
  std::map<std::string, std::pair<int, int>> slower;  // ours -> (slower, significantly)
  for (const SuiteCell& c : r.cells) {
    std::string best;
    double best_v = std::numeric_limits<double>::infinity(), other_best = best_v;
    for (const auto& p : r.options.planners) {
      if (p == kOraclePlanner) continue;
      const PlannerSummary* s = find_summary(c.result, p);
      if (!s) continue;
      const double v = finite_or_inf(s->target_time_ms);
      if (v < best_v) best_v = v, best = p;
      if (p != kMinerSgan) other_best = std::min(other_best, v);
    }
    ++fastest[best.empty() ? std::string("(none in half its runs)") : best];
    if (const PlannerSummary* s = find_summary(c.result, kMinerSgan)) {
      ++sgan_run;
      const double mine = finite_or_inf(s->target_time_ms);
      if (best == kMinerSgan) ++sgan_fastest;
      if (std::isfinite(mine) && mine * 5.0 <= other_best) ++sgan_five;
      const double ratio = mine / other_best;  // > 1: slower than the fastest other planner
      if (!std::isnan(ratio)) {
        worst_ratio = std::max(worst_ratio, ratio);
        best_ratio = std::min(best_ratio, ratio);
      }
    }
    for (const auto& [ours, theirs] : kCounterparts) {
      const Comparison cmp = compare(c.result, ours, theirs);
      if (!cmp.run) continue;
      auto& [n_slower, n_significant] = slower[ours];
      n_slower += cmp.slower ? 1 : 0;
      n_significant += cmp.significant ? 1 : 0;
    }
  }
  std::ostringstream h;
  const std::size_t n = r.cells.size();
  std::size_t set = 0;
  for (const auto& p : r.options.planners) set += p == kOraclePlanner ? 0 : 1;
  h << "## Headline (generated from the " << n << " campaigns below; comparison set: the " << set
    << " planners run, the oracle aside)\n\n- Fastest to the target (median time, misses as +inf):";
  bool first = true;
  for (const auto& [p, k] : fastest) h << (first ? " " : ", ") << "`" << p << "` in " << k, first = false;
  h << " of " << n << " campaigns.\n";
  if (sgan_run > 0) {
    h << "- `miner-sgan` (sGAN region, its query time included) is the fastest in " << sgan_fastest << " of " << sgan_run
      << " and at least 5x faster than every other planner (issue 16's bar) in " << sgan_five << " of " << sgan_run
      << "; its median time to the target is " << f(best_ratio, 2) << "x to " << f(worst_ratio, 2)
      << "x the fastest other planner's. The paper's claim (MINER reaches the target before every baseline) "
         "reproduces in "
      << sgan_fastest << " of " << sgan_run << " campaigns and does **not** in the other " << (sgan_run - sgan_fastest)
      << ".\n";
  }
  for (const auto& [ours, theirs] : kCounterparts) {
    const auto it = slower.find(ours);
    if (it == slower.end()) continue;
    h << "- `" << ours << "` against `" << theirs << "`: slower to the target (median) in " << it->second.first << " of " << n
      << " campaigns, significantly (Mann-Whitney on the times, p < " << f(kSignificance, 2) << ") in "
      << it->second.second << ".\n";
  }
  std::string out = h.str();
  if (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

}  // namespace

SuiteDefinition load_suite(const std::string& path) {
  const Json doc = read_json_file(path);
  const JsonField root(doc, "", path);
  root.only_keys({"format", "description", "steps", "band", "maps"});
  if (root.at("format").string() != kSuiteFormat)
    root.at("format").fail(std::string("expected \"") + kSuiteFormat + "\", got \"" + root.at("format").string() + "\"");
  if (root.has("description")) (void)root.at("description").string();
  SuiteDefinition s;
  const JsonField steps = root.at("steps");
  // Bounded work (issue 20: 10^5 steps ran for ever): each step is a whole campaign per map.
  constexpr std::size_t kMaxSteps = 16, kMaxMaps = 64;
  if (steps.array_size() == 0) steps.fail("needs at least one steering step");
  if (steps.array_size() > kMaxSteps) steps.fail("at most 16 steering steps, got " + std::to_string(steps.array_size()));
  for (std::size_t i = 0; i < steps.array_size(); ++i) {
    const double x = steps.at(i).positive_number();
    // A step is named in the tables and the figure files by step_label: two steps with one label
    // would share a column and a plot (seventh campaign W4: 0.0001 and 0.0002 both "0.000", the
    // second plot written over the first), and below a thousandth of the diagonal a step is no
    // campaign of the paper's kind.
    if (x < kMinStepFraction || x > 1.0)
      steps.at(i).fail("a steering step is a fraction of the map's diagonal in [" + short_number(kMinStepFraction) +
                       ", 1], got " + steps.at(i).value().dump());
    for (const double earlier : s.step_fractions)
      if (step_label(earlier) == step_label(x))
        steps.at(i).fail("repeated steering step " + step_label(x) + " (steps are told apart by 6 significant digits)");
    s.step_fractions.push_back(x);
  }
  if (root.has("band")) {
    const JsonField band = root.at("band");
    if (band.array_size() != 2) band.fail("expected [lo, hi] iterations");
    // Iterations are whole numbers: 700.7 was rounded without a word (eighteenth campaign F27).
    for (std::size_t k = 0; k < 2; ++k) {
      const int value = band.at(k).integer();
      if (value < 1) band.at(k).fail("iterations are at least 1, got " + std::to_string(value));
      (k == 0 ? s.band_lo : s.band_hi) = value;
    }
    if (s.band_hi < s.band_lo) band.fail("hi is below lo");
  }
  const JsonField maps = root.at("maps");
  if (maps.array_size() == 0) maps.fail("needs at least one map");
  if (maps.array_size() > kMaxMaps) maps.fail("at most 64 maps, got " + std::to_string(maps.array_size()));
  const auto presets = world::generator_preset_names();
  for (std::size_t i = 0; i < maps.array_size(); ++i) {
    const JsonField m = maps.at(i);
    m.only_keys({"name", "preset", "seed", "obstacles", "size", "resolution"});
    SuiteMap sm;
    sm.name = m.at("name").string();
    if (sm.name.empty() || sm.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_.") != std::string::npos)
      m.at("name").fail("a name is lower-case letters, digits, '-', '_' and '.' (it names the figure files)");
    for (const auto& other : s.maps)
      if (other.name == sm.name) m.at("name").fail("repeated map name \"" + sm.name + "\"");
    sm.preset = m.at("preset").string();
    if (std::find(presets.begin(), presets.end(), sm.preset) == presets.end()) {
      std::string list;
      for (const auto& p : presets) list += (list.empty() ? "" : ", ") + p;
      m.at("preset").fail("unknown preset \"" + sm.preset + "\" (known: " + list + ")");
    }
    const int seed = m.at("seed").integer();
    if (seed < 0) m.at("seed").fail("must be >= 0");
    sm.seed = static_cast<std::uint64_t>(seed);
    if (m.has("obstacles")) {
      const int n = m.at("obstacles").integer();
      if (n < 0 || n > 100000) m.at("obstacles").fail("must be in [0, 100000]");
      sm.overrides.obstacles = n;
    }
    if (m.has("size")) sm.overrides.size = m.at("size").vec3();
    if (m.has("resolution")) sm.overrides.resolution = m.at("resolution").positive_number();
    s.maps.push_back(sm);
  }
  return s;
}

bool in_paper_band(const SuiteCell& cell, const SuiteDefinition& suite) {
  const PlannerSummary* s = find_summary(cell.result, "rrtstar");
  return s && std::isfinite(s->first_iterations) && s->first_iterations >= suite.band_lo &&
         s->first_iterations <= suite.band_hi;
}

/// What a generated map is, for telling two entries' maps apart: its JSON, with voxels made in
/// memory (the `scan` preset, which has no file to reference) standing as their grid and the
/// SHA-256 of their cell states (issue 20, sixth campaign U15: to_json() refused them mid-run with
/// an internal message).
namespace {
Json map_fingerprint(const world::Map& map) {
  const auto& source = map.voxel_source();
  if (!source || !source->file.empty()) return map.to_json();
  Json doc = world::Map(map.bounds(), map.resolution(), map.obstacles(), map.query()).to_json();
  const world::VoxelLayer& layer = *source->layer;
  doc["voxels"] = {{"origin_cells", {layer.origin_cells().x(), layer.origin_cells().y(), layer.origin_cells().z()}},
                   {"dims", {layer.dims().x(), layer.dims().y(), layer.dims().z()}},
                   {"states_sha256", sha256_hex(std::string(layer.states().begin(), layer.states().end()))},
                   {"unknown", world::to_string(source->unknown)}};
  return doc;
}
}  // namespace

std::string step_label(double fraction) { return short_number(fraction); }

SuiteBenchResult run_suite_bench(const SuiteBenchOptions& o, const std::string& command, std::ostream* progress) {
  if (o.suite.maps.empty() || o.suite.step_fractions.empty()) throw Error("bench suite: the suite has no map or no step");
  if (o.runs < 1) throw Error("bench suite: --runs must be >= 1");
  const auto t0 = Clock::now();
  SuiteBenchResult out;
  out.options = o;
  out.command = command;
  out.commit = git_commit();
  // Generate every map first: a bad recipe fails before minutes of benchmarking.
  // A fault names the suite file and the entry (issue 20, fourth campaign: `bench suite: map
  // "in"` named neither).
  const std::string suite_file = o.suite_file.empty() ? std::string("bench suite") : o.suite_file;
  const auto entry = [&](std::size_t i) {
    return suite_file + ": maps[" + std::to_string(i) + "] (\"" + o.suite.maps[i].name + "\")";
  };
  std::vector<world::Map> maps;
  std::vector<Json> generated;
  for (std::size_t i = 0; i < o.suite.maps.size(); ++i) {
    const SuiteMap& m = o.suite.maps[i];
    try {
      maps.push_back(world::generate_map(world::generator_preset(m.preset), m.seed, m.overrides));
    } catch (const Error& e) {
      throw Error(entry(i) + ": " + e.what(), e.code());  // "no solvable map" stays exit 3, as in map gen
    }
    generated.push_back(map_fingerprint(maps.back()));
  }
  // Two entries that generate one map (names aside) would run its campaign twice and count
  // it twice in every summary.
  if (const auto same = first_repeated(generated))
    throw Error(entry(same->second) + " generates the same map as " + entry(same->first) +
                ": each map is benchmarked once");
  for (std::size_t i = 0; i < maps.size(); ++i) {
    const world::Map& map = maps[i];
    const auto& q = *map.query();
    const double diagonal = map.bounds().extent().norm();
    for (const double fraction : o.suite.step_fractions) {
      if (progress) *progress << "suite: " << o.suite.maps[i].name << ", eta = " << fraction << " x diagonal\n";
      FrontendBenchOptions fo = frontend_options_of(o);
      fo.planner_options.steer_step = fraction * diagonal;
      SuiteCell cell;
      cell.map = o.suite.maps[i].name;
      cell.preset = o.suite.maps[i].preset;
      cell.extent = map.bounds().extent();
      cell.resolution = map.resolution();
      cell.step_fraction = fraction;
      cell.result = run_frontend_bench(map, cell.map, q.start, q.goal, q.robot_radius, fo, progress);
      out.cells.push_back(std::move(cell));
    }
  }
  out.total_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::string suite_markdown(const SuiteBenchResult& r, const std::string& figure_dir) {
  const auto& o = r.options;
  const auto& suite = o.suite;
  std::ostringstream md;
  md << "# Benchmark suite: map families at the paper's difficulty, steering step swept\n\n"
     << "Generated by `" << r.command << "` at commit `" << r.commit << "` (" << f(r.total_s, 0)
     << " s), suite `" << r.options.suite_file << "`. Every planner runs " << o.runs
     << " times per map and eta (n = " << o.runs << " in every row and plot), interleaved run by run; ours stop at "
     << o.max_iterations << " iterations, OMPL's RRTstar and InformedRRTstar at the same count or " << f(o.time_limit_s, 1)
     << " s, OMPL's other planners at " << f(o.time_limit_s, 1)
     << " s. Iterations, nodes and costs are deterministic for the seed for our planners and for OMPL's RRTstar and "
        "InformedRRTstar when the count stops them (REQ-PLAN-017); OMPL's planners stopped by the clock vary from run to "
        "run (`miner bench frontend --ompl-checks N` repeats them). Times are wall clock on this machine and vary. One goal rule for all planners (REQ-PLAN-018): a path ends exactly at x_goal "
        "and costs its whole length. Target = the A* path's length on the map's grid. `miner-sgan` includes its "
        "region query (encode, inference, filter) in every time; `miner` samples the A*-dilated region built from the "
        "path that defines the target and is an upper bound, never a result. A missed stage counts as +inf in medians "
        "and quartiles (\"miss\") and is left out of mean ± sd, which is over the runs that got there.\n\n";

  md << suite_headline(r) << "\n\n";

  md << "## Difficulty: RRT*'s first solution against the paper's Table I\n\n"
     << "The suite's band: RRT*'s first solution after " << f(suite.band_lo, 0) << "-" << f(suite.band_hi, 0)
     << " iterations (the suite file's `band`, default 700-2000; the paper's Table I has about 740-1730 over its "
        "three maps). Per map and eta (as a fraction of the map's diagonal): `rrtstar`'s median [IQR] "
        "first-solution iterations; **in band** marks a median inside the suite's band.\n\n| map | preset | extent (m) | resolution (m) | A* cost (m) | straight line (m) |";
  for (double s : suite.step_fractions) md << " eta = " << step_label(s) << " x diag |";
  md << "\n|---|---|---|---|---|---|";
  for (std::size_t k = 0; k < suite.step_fractions.size(); ++k) md << "---|";
  md << "\n";
  int in_band = 0;
  const std::size_t per_map = suite.step_fractions.size();
  for (std::size_t i = 0; i < r.cells.size(); i += per_map) {
    const SuiteCell& c0 = r.cells[i];
    md << "| " << c0.map << " | " << c0.preset << " | " << f(c0.extent.x(), 1) << " x " << f(c0.extent.y(), 1) << " x "
       << f(c0.extent.z(), 1) << " | " << f(c0.resolution, 2) << " | " << f(c0.result.reference_cost, 1) << " | "
       << f(c0.result.lower_bound, 1) << " |";
    for (std::size_t k = 0; k < per_map && i + k < r.cells.size(); ++k) {
      const SuiteCell& c = r.cells[i + k];
      const auto v = stage_values(c.result, "rrtstar", false, false);
      const bool band = in_paper_band(c, suite);
      in_band += band ? 1 : 0;
      md << " " << (v.empty() ? std::string("(rrtstar not run)") : median_iqr(v, 0)) << (band ? " **in band**" : "")
         << " (eta " << f(c.result.steer_step, 2) << " m) |";
    }
    md << "\n";
  }
  md << "\n**" << in_band << " of " << r.cells.size()
     << " campaigns are at the paper's difficulty** (generated from the table above).\n\n";

  // Step sweep: median time to the target per planner and eta, per map.
  md << "## Steering step sweep: median time to the target (ms) [reached/n]\n\n";
  for (std::size_t i = 0; i < r.cells.size(); i += per_map) {
    md << "### " << r.cells[i].map << "\n\n| planner |";
    for (std::size_t k = 0; k < per_map; ++k) md << " eta = " << step_label(suite.step_fractions[k]) << " x diag |";
    md << "\n|---|";
    for (std::size_t k = 0; k < per_map; ++k) md << "---|";
    md << "\n";
    for (const auto& p : o.planners) {
      md << "| " << planner_label(p) << " |";
      for (std::size_t k = 0; k < per_map && i + k < r.cells.size(); ++k) {
        const auto v = stage_values(r.cells[i + k].result, p, true, true);
        md << " " << (v.empty() ? std::string("—") : (std::isfinite(median(v)) ? f(median(v), 1) : std::string("miss")))
           << " [" << reached(v) << "/" << v.size() << "] |";
      }
      md << "\n";
    }
    md << "\n";
  }

  md << "## Every campaign\n\n"
     << "Per planner: first solution (iterations, time) and the target (iterations, time), each as mean ± sd over "
        "the runs that got there and median [IQR] over all n runs.\n\n";
  for (const SuiteCell& c : r.cells) {
    const auto& fr = c.result;
    md << "### " << c.map << ", eta = " << step_label(c.step_fraction) << " x diagonal (" << f(fr.steer_step, 2)
       << " m)" << (in_paper_band(c, suite) ? ", at the paper's difficulty" : "") << "\n\n"
       << "A* cost " << f(fr.reference_cost, 2) << " m, target " << f(fr.target_cost, 2) << " m, straight line "
       << f(fr.lower_bound, 2) << " m, goal radius " << f(fr.goal_radius, 2) << " m, robot radius "
       << f(fr.robot_radius, 2) << " m.\n\n"
       << "| planner | n | solved | first iterations mean ± sd | first iterations median [IQR] | first time (ms) "
          "median [IQR] | target reached | target iterations median [IQR] | target time (ms) mean ± sd | target "
          "time (ms) median [IQR] |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& p : o.planners) {
      const PlannerSummary* s = find_summary(fr, p);
      if (!s) continue;
      const auto fi = stage_values(fr, p, false, false), ft = stage_values(fr, p, false, true);
      const auto ti = stage_values(fr, p, true, false), tt = stage_values(fr, p, true, true);
      // Reached counts come from the times, which every planner reports.
      md << "| " << planner_label(p) << " | " << s->runs << " | " << reached(ft) << "/" << s->runs << " | "
         << mean_sd(fi, 0) << " | " << median_iqr(fi, 0) << " | " << median_iqr(ft, 2) << " | " << reached(tt) << "/"
         << s->runs << " | " << median_iqr(ti, 0) << " | " << mean_sd(tt, 2) << " | " << median_iqr(tt, 2) << " |\n";
    }
    md << "\n" << cell_headline(fr, o.planners) << "\n\n";
    const std::string fig = c.map + "-" + step_label(c.step_fraction) + "-target.svg";
    md << "![" << c.map << " eta " << step_label(c.step_fraction) << "](" << figure_dir << "/" << fig << ")\n\n";
  }
  return md.str();
}

std::map<std::string, std::string> suite_figures(const SuiteBenchResult& r) {
  std::map<std::string, std::string> figures;
  for (const SuiteCell& c : r.cells) {
    std::vector<report::BoxGroup> groups;
    for (const auto& p : r.options.planners) {
      report::BoxGroup g{p, {}, 0};
      for (double v : stage_values(c.result, p, true, true)) {
        if (std::isfinite(v)) g.values.push_back(v);
        else ++g.missed;
      }
      groups.push_back(std::move(g));
    }
    const int width = 110 * static_cast<int>(std::max<std::size_t>(groups.size(), 4));
    figures[c.map + "-" + step_label(c.step_fraction) + "-target.svg"] = report::svg_box_plot(
        {c.map + ", eta " + step_label(c.step_fraction) + " x diagonal: time to the target", "", "ms (log)", width, 300},
        groups, true);
  }
  return figures;
}

nlohmann::json to_json(const SuiteBenchResult& r) {
  nlohmann::json j{{"commit", r.commit}, {"command", r.command}, {"total_s", r.total_s}, {"suite", r.options.suite_file},
                   {"band", {r.options.suite.band_lo, r.options.suite.band_hi}}};
  j["cells"] = nlohmann::json::array();
  for (const SuiteCell& c : r.cells) {
    nlohmann::json cell = to_json(c.result);
    cell["suite_map"] = c.map;
    cell["preset"] = c.preset;
    cell["step_fraction"] = c.step_fraction;
    cell["in_paper_band"] = in_paper_band(c, r.options.suite);
    j["cells"].push_back(std::move(cell));
  }
  return j;
}

}  // namespace miner::bench
