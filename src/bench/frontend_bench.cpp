#include "bench/frontend_bench.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <unistd.h>

#include "bench/ompl_planners.hpp"
#include "miner/core/error.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/shard.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/core/text.hpp"
#include "miner/core/json_io.hpp"
#include "bench/campaign_stats.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/reference.hpp"
#include "miner/world/map.hpp"

namespace miner::bench {

namespace {

/// Whether the campaign's iteration budget binds `planner`: ours, and OMPL's RRT*s, which are
/// given it; OMPL's other planners stop on the time limit (or the target) only.
bool bounded_by_iterations(const std::string& planner) {
  return planner.rfind("ompl:", 0) != 0 || planner == "ompl:RRTstar" || planner == "ompl:InformedRRTstar";
}


using Clock = std::chrono::steady_clock;


}  // namespace

std::vector<std::string> default_frontend_planners() {
  std::vector<std::string> names;
  for (plan::PlannerKind k : plan::all_planners()) names.push_back(plan::planner_name(k));
  names.push_back(kMinerSgan);
  for (const auto& n : ompl_planner_names()) names.push_back(n);
  return names;
}

std::string unknown_planner(const std::string& name) {
  const std::vector<std::string> valid = default_frontend_planners();
  if (std::find(valid.begin(), valid.end(), name) != valid.end()) return {};
  std::string list;
  for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
  return "unknown planner \"" + name + "\" (planners: " + list + ")";
}

PlannerSummary summarise(const std::string& planner, const std::vector<RunRecord>& runs) {
  PlannerSummary s;
  s.planner = planner;
  // Per run; a run that missed a stage holds +inf there (NaN: a counter OMPL does not report).
  std::vector<double> fi, fn, fc, ft, ti, tn, tt, final_cost;
  const double inf = std::numeric_limits<double>::infinity();
  const auto count = [](std::size_t c) {
    return c == kUnknownCount ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(c);
  };
  int solved = 0, reached = 0;
  for (const RunRecord& r : runs) {
    if (r.planner != planner) continue;
    ++s.runs;
    const plan::PlanResult& res = r.result;
    if (res.solved) {
      ++solved;
      final_cost.push_back(res.cost);
    }
    if (res.first) {
      fi.push_back(count(res.first->iteration));
      fn.push_back(count(res.first->nodes));
      fc.push_back(res.first->cost);
      ft.push_back(res.first->time_ms);
    }
    reached += res.target.has_value();
    ti.push_back(res.target ? count(res.target->iteration) : inf);
    tn.push_back(res.target ? count(res.target->nodes) : inf);
    tt.push_back(res.target ? res.target->time_ms : inf);
  }
  if (s.runs == 0) return s;
  s.success_rate = static_cast<double>(solved) / s.runs;
  s.target_rate = static_cast<double>(reached) / s.runs;
  s.first_iterations = median(fi);
  s.first_nodes = median(fn);
  s.first_cost = median(fc);
  s.first_time_ms = median(ft);
  s.first_iterations_mean = mean(fi);
  s.first_nodes_mean = mean(fn);
  s.first_cost_mean = mean(fc);
  s.first_time_ms_mean = mean(ft);
  // A median that lands on a missed run (no more than half reached) is infinite: median()
  // reports it as unknown (null).
  s.target_iterations = median(ti);
  s.target_nodes = median(tn);
  s.target_time_ms = median(tt);
  const auto reached_only = [](std::vector<double> v) {
    v.erase(std::remove(v.begin(), v.end(), std::numeric_limits<double>::infinity()), v.end());
    return v;
  };
  s.target_iterations_mean = mean(reached_only(ti));
  s.target_nodes_mean = mean(reached_only(tn));
  s.target_time_ms_mean = mean(reached_only(tt));
  s.final_cost = median(final_cost);
  s.target_reached = reached;
  // sd over the runs that reached the stage; the quartiles over the runs its median is taken
  // over (fourteenth campaign C3: the first stage's median over the solved runs fell below its
  // lower quartile over all runs): the first stage's over the solved runs, the target stage's
  // over all runs with a miss as +inf.
  const auto spread = [](const std::vector<double>& reached_runs, const std::vector<double>& median_runs, double& sd,
                         double& q1, double& q3) {
    sd = stddev(reached_runs);
    q1 = quantile(median_runs, 0.25);
    q3 = quantile(median_runs, 0.75);
  };
  spread(fi, fi, s.first_iterations_sd, s.first_iterations_q1, s.first_iterations_q3);
  spread(ft, ft, s.first_time_ms_sd, s.first_time_ms_q1, s.first_time_ms_q3);
  spread(ti, ti, s.target_iterations_sd, s.target_iterations_q1, s.target_iterations_q3);
  spread(tt, tt, s.target_time_ms_sd, s.target_time_ms_q1, s.target_time_ms_q3);
  return s;
}

FrontendBenchResult run_frontend_bench(const world::Map& map, const std::string& map_name,
                                       const Eigen::Vector3d& start, const Eigen::Vector3d& goal,
                                       double robot_radius, const FrontendBenchOptions& options,
                                       std::ostream* progress) {
  if (options.runs < 1) throw Error("--runs: must be >= 1, got " + std::to_string(options.runs));
  require_shard(options.shard_index, options.shard_count);
  // A shard that holds no run would report rates over nothing (issue 20, fifth campaign:
  // "--runs 1 --shard 1/2" gave a 0 % success rate).
  if (options.shard_index >= options.runs)
    throw Error("--shard " + std::to_string(options.shard_index) + "/" + std::to_string(options.shard_count) +
                    ": with --runs " + std::to_string(options.runs) + " this shard holds no run (runs r with r % " +
                    std::to_string(options.shard_count) + " == " + std::to_string(options.shard_index) + ")",
                ExitCode::kUsage);
  if (!(options.target_factor > 0.0)) throw Error("--target-factor: must be > 0");
  // A campaign measures planners between two points (issue 20, fifth campaign: start == goal
  // scored 100 % for one planner and 0 % for another).
  if (start == goal) throw Error("start and goal coincide at " + format_point(start) + ": there is no path to measure");
  const Clock::time_point campaign_start = Clock::now();
  const plan::PlanningProblem problem = plan::PlanningProblem::make(map, start, goal, robot_radius);
  const plan::ReferencePath reference = plan::astar_reference(problem);

  FrontendBenchResult out;
  out.options = options;
  if (out.options.planners.empty()) out.options.planners = default_frontend_planners();
  out.map = map_name;
  out.start = start;
  out.goal = goal;
  out.robot_radius = robot_radius;
  out.reference_cost = reference.cost;
  out.target_cost = options.target_factor * reference.cost;
  out.lower_bound = plan::straight_line_bound(problem);

  plan::PlannerOptions base = options.planner_options;
  base.max_iterations = options.max_iterations;
  base.target_cost = out.target_cost;
  base.stop_at_first = false;
  base.record_tree = false;
  // Resolve the defaults once so OMPL gets the same eta and goal radius.
  base.steer_step = plan::resolved_steer_step(base, map);
  base.goal_radius = plan::resolved_goal_radius(base, map);
  out.steer_step = base.steer_step;
  out.goal_radius = base.goal_radius;
  // A start inside X_goal is solved by the root alone at iteration 0, by every planner: no tree,
  // no time, a throughput of 0 iterations per second (sixteenth campaign F17). Not a campaign.
  if ((goal - start).norm() <= base.goal_radius)
    throw Error(map_name + ": the start " + format_point(start) + " lies within the goal radius " +
                exact_number(base.goal_radius) + " m of the goal " + format_point(goal) +
                ": every planner solves this query at iteration 0 without a tree, so there is nothing to measure "
                "(lower --goal-radius, or give a start and goal farther apart)");

  const Clock::time_point region_start = Clock::now();
  const plan::HeuristicRegion region =
      options.region_file.empty()
          ? plan::astar_dilated_region(problem, reference, options.region_dims, options.region_dilation)
          : plan::HeuristicRegion::load(options.region_file);
  out.region_ms = elapsed_ms(region_start);
  region.require_matches(map, options.region_file.empty() ? std::string("bench frontend") : options.region_file);
  // A file is labelled as one, with the source it records, so a file named like a source is
  // not read as that source (eighteenth campaign F11).
  out.region_source = options.region_file.empty()
                          ? region.source()
                          : "file " + options.region_file + " (" +
                                (region.source().empty() ? std::string("no source recorded") : region.source()) + ")";
  out.region_cells = region.cells().size();
  out.region_sha256 = sha256_hex(region.to_json().dump());

  std::optional<heuristic::Sgan> sgan;
  init_ompl();
  const auto ompl_options = [&](const std::string& name) {
    OmplRunOptions o;
    o.planner = name;
    o.time_limit_s = options.time_limit_s;
    if (bounded_by_iterations(name)) o.max_iterations = options.max_iterations;
    if (options.ompl_checks > 0) o.max_condition_checks = options.ompl_checks;
    o.steer_step = base.steer_step;
    o.goal_radius = base.goal_radius;
    o.goal_bias = base.goal_bias;
    o.rewire_factor = base.rewire_factor;
    o.target_cost = out.target_cost;
    return o;
  };

  ProgressBar bar(progress, "frontend " + map_name,
                  out.options.planners.size() * static_cast<std::size_t>(options.runs));
  std::size_t done = 0;
  struct Entry {
    std::string name;
    bool ompl = false, sgan_planner = false;
    plan::PlannerKind kind = plan::PlannerKind::kRrtStar;
  };
  std::vector<Entry> entries;
  for (const std::string& name : out.options.planners) {
    const bool ompl = is_ompl_planner(name);
    if (const std::string why = unknown_planner(name); !why.empty()) throw Error(why);
    const bool sgan_planner = name == kMinerSgan;
    const plan::PlannerKind kind =
        ompl ? plan::PlannerKind::kRrtStar : sgan_planner ? plan::PlannerKind::kMiner : plan::planner_from_name(name);
    if (sgan_planner && !sgan) {
      sgan.emplace(heuristic::Sgan::load_or_builtin(options.weights_file));
      out.weights_sha256 = sgan->sha256();
      // Warm-up query: the first oneDNN execution pays one-time page faults, as it would
      // once at start-up on board.
      heuristic::query_region(*sgan, map, start, goal, robot_radius, options.seed);
    }
    entries.push_back({name, ompl, sgan_planner, kind});
  }
  // Interleaved: run k of every planner before run k + 1 of any, so every planner's times are
  // sampled over the same stretch of the campaign and a slow spell of a shared machine falls
  // on all of them alike (planner after planner, it fell on whichever ran then: BIT*'s median
  // on sim-3 moved between 3.6 and 5.3 ms from one campaign to the next).
  std::vector<std::vector<RunRecord>> records(entries.size());
  for (int run = 0; run < options.runs; ++run) {
    if (run % options.shard_count != options.shard_index) continue;
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const Entry& e = entries[i];
      RunRecord record;
      record.planner = e.name;
      record.run = run;
      if (e.ompl) {
        OmplRunOptions oo = ompl_options(e.name);
        oo.seed = ompl_run_seed(options.seed, run);  // this run's seed, whatever ran before
        record.result = run_ompl(problem, oo);
      } else {
        plan::PlannerOptions po = base;
        po.planner = e.kind;
        po.seed = options.seed;
        po.stream = static_cast<std::uint64_t>(run);  // common random numbers across planners
        if (e.sgan_planner) {
          // End to end: encoding, inference and filtering count in every time (Alg. 1 lines 2-3).
          const Clock::time_point t0 = Clock::now();
          const heuristic::HeuristicQuery q =
              heuristic::query_region(*sgan, map, start, goal, robot_radius, options.seed + static_cast<std::uint64_t>(run));
          const double region_ms = elapsed_ms(t0);
          record.result = plan::plan(problem, po, &q.region);
          plan::add_setup_time(record.result, region_ms);
        } else {
          record.result = plan::plan(problem, po, e.kind == plan::PlannerKind::kMiner ? &region : nullptr);
        }
      }
      records[i].push_back(std::move(record));
      bar.update(++done);
    }
  }
  for (std::size_t i = 0; i < entries.size(); ++i) {  // records grouped by planner, as before
    for (RunRecord& r : records[i]) out.runs.push_back(std::move(r));
    out.summaries.push_back(summarise(entries[i].name, out.runs));
  }
  bar.finish();

  if (options.throughput_iterations > 0 && options.shard_index == 0) {
    std::vector<double> mine, theirs;
    const bool with_ompl = ompl_available();
    for (int run = 0; run < std::min(options.runs, 5); ++run) {
      plan::PlannerOptions po = base;
      po.planner = plan::PlannerKind::kRrtStar;
      po.target_cost.reset();
      po.max_iterations = options.throughput_iterations;
      po.seed = options.seed;
      po.stream = static_cast<std::uint64_t>(run);
      const plan::PlanResult r = plan::plan(problem, po);
      mine.push_back(static_cast<double>(r.iterations) / (r.time_ms / 1000.0));
      if (with_ompl) {
        OmplRunOptions oo = ompl_options("ompl:RRTstar");
        oo.target_cost.reset();
        oo.max_condition_checks.reset();  // the throughput check runs its iterations, whatever the campaign's budget
        oo.max_iterations = options.throughput_iterations;
        oo.seed = ompl_run_seed(options.seed, run);
        const plan::PlanResult t = run_ompl(problem, oo);
        theirs.push_back(static_cast<double>(t.iterations) / (t.time_ms / 1000.0));
      }
    }
    out.rrtstar_iterations_per_s = median(mine);
    out.ompl_rrtstar_iterations_per_s = median(theirs);
  }
  out.total_s = std::chrono::duration<double>(Clock::now() - campaign_start).count();
  return out;
}

namespace {

nlohmann::json summary_json(const PlannerSummary& s) {
  return {{"planner", s.planner},
          {"runs", s.runs},
          {"success_rate", s.success_rate},
          {"target_rate", s.target_rate},
          {"first_iterations", num(s.first_iterations)},
          {"first_nodes", num(s.first_nodes)},
          {"first_cost", num(s.first_cost)},
          {"first_time_ms", num(s.first_time_ms)},
          {"first_iterations_mean", num(s.first_iterations_mean)},
          {"first_nodes_mean", num(s.first_nodes_mean)},
          {"first_cost_mean", num(s.first_cost_mean)},
          {"first_time_ms_mean", num(s.first_time_ms_mean)},
          {"target_iterations", num(s.target_iterations)},
          {"target_nodes", num(s.target_nodes)},
          {"target_time_ms", num(s.target_time_ms)},
          {"target_iterations_mean", num(s.target_iterations_mean)},
          {"target_nodes_mean", num(s.target_nodes_mean)},
          {"target_time_ms_mean", num(s.target_time_ms_mean)},
          {"final_cost", num(s.final_cost)},
          {"target_reached", s.target_reached},
          {"first_iterations_sd", num(s.first_iterations_sd)},
          {"first_iterations_q1", num(s.first_iterations_q1)},
          {"first_iterations_q3", num(s.first_iterations_q3)},
          {"first_time_ms_sd", num(s.first_time_ms_sd)},
          {"first_time_ms_q1", num(s.first_time_ms_q1)},
          {"first_time_ms_q3", num(s.first_time_ms_q3)},
          {"target_iterations_sd", num(s.target_iterations_sd)},
          {"target_iterations_q1", num(s.target_iterations_q1)},
          {"target_iterations_q3", num(s.target_iterations_q3)},
          {"target_time_ms_sd", num(s.target_time_ms_sd)},
          {"target_time_ms_q1", num(s.target_time_ms_q1)},
          {"target_time_ms_q3", num(s.target_time_ms_q3)}};
}

nlohmann::json count_json(std::size_t c) { return c == kUnknownCount ? nlohmann::json(nullptr) : nlohmann::json(c); }
std::size_t count_from(const nlohmann::json& j) { return j.is_null() ? kUnknownCount : j.get<std::size_t>(); }

nlohmann::json stage_json(const std::optional<plan::StageRecord>& s) {
  if (!s) return nullptr;
  return {{"iteration", count_json(s->iteration)}, {"nodes", count_json(s->nodes)}, {"cost", s->cost},
          {"time_ms", s->time_ms}};
}
std::optional<plan::StageRecord> stage_from(const nlohmann::json& j) {
  if (j.is_null()) return std::nullopt;
  return plan::StageRecord{count_from(j.at("iteration")), count_from(j.at("nodes")), j.at("cost").get<double>(),
                           j.at("time_ms").get<double>()};
}

/// What summarise() and a merge need of one run.
nlohmann::json run_json(const RunRecord& r) {
  return {{"planner", r.planner},     {"run", r.run},
          {"solved", r.result.solved}, {"cost", r.result.solved ? nlohmann::json(r.result.cost) : nlohmann::json(nullptr)},
          {"iterations", count_json(r.result.iterations)},
          {"first", stage_json(r.result.first)},
          {"target", stage_json(r.result.target)}};
}
/// A count a record may hold: null (not known) or a non-negative integer (issue 20: -3 nodes
/// wrapped to 2^64 - 3 and 99.5 iterations were read).
void check_count(const JsonField& f) {
  if (!f.value().is_null() && !f.value().is_number_unsigned()) f.fail("expected null or an integer >= 0");
}

/// What a run record can say, checked beyond its types (issue 20: impossible records merged
/// into the figures): counts are integers >= 0, a stage (first solution, target) comes no later
/// than the run's last iteration and costs no less than the lower bound, its time is finite and
/// >= 0, and an unsolved run has no cost and no stages.
void check_run_record(const JsonField& r, double lower_bound) {
  constexpr double kRoundoff = 1e-9;
  constexpr double kMaxStageMs = 1e9;  // 11 days: far beyond any campaign's time limit
  check_count(r.at("iterations"));
  if (!r.at("solved").value().is_boolean()) r.at("solved").fail("expected true or false");
  const bool solved = r.at("solved").value().get<bool>();
  // A solved run's cost is a number, named as the field when it is not (issue 20, sixth
  // campaign U13: "malformed run record: type must be number, but is string").
  if (solved) (void)r.at("cost").number();
  // A solved run found a first solution (fourteenth campaign C4: solved runs without one were
  // merged as 100 % success with no first-solution figures).
  if (solved && r.at("first").value().is_null()) r.at("first").fail("null, but the run is solved: a solved run has a first solution");
  // Our planners count iterations and vertices; only OMPL's records leave them null (fourteenth
  // campaign C4: null counters of rrtstar were merged).
  const bool ours = r.at("planner").value().is_string() && r.at("planner").string().rfind("ompl:", 0) != 0;
  if (ours) {
    (void)r.at("iterations").number();
    for (const char* stage : {"first", "target"})
      if (!r.at(stage).value().is_null())
        for (const char* k : {"iteration", "nodes"}) (void)r.at(stage).at(k).number();
  }
  if (!solved)
    for (const char* k : {"cost", "first", "target"})
      if (!r.at(k).value().is_null()) r.at(k).fail("an unsolved run has no " + std::string(k));
  for (const char* stage : {"first", "target"}) {
    const JsonField st = r.at(stage);
    if (st.value().is_null()) continue;
    st.only_keys({"iteration", "nodes", "cost", "time_ms"});
    check_count(st.at("iteration"));
    check_count(st.at("nodes"));
    const double t = st.at("time_ms").number();
    if (!(t >= 0.0 && t <= kMaxStageMs)) st.at("time_ms").fail("a time must be in [0, 1e9] ms");
    if (st.at("cost").number() < lower_bound * (1.0 - kRoundoff)) st.at("cost").fail("below the campaign's lower bound");
    if (st.at("iteration").value().is_number_unsigned() && r.at("iterations").value().is_number_unsigned() &&
        st.at("iteration").value().get<std::uint64_t>() > r.at("iterations").value().get<std::uint64_t>())
      st.at("iteration").fail("comes after the run's last iteration " + r.at("iterations").value().dump());
    // Our planners' trees hold the root and at most one new vertex per iteration (seventh
    // campaign W3: 1e9 nodes at iteration 84 were averaged in). OMPL's may add batches.
    // nodes counts the vertices besides the root: a solution found after iteration 0 ends at a
    // vertex the run added (fifteenth campaign F7: first.nodes 0 at iteration 84 merged); only a
    // start within the goal radius is solved at iteration 0 by the root alone.
    if (ours && st.at("nodes").value().is_number_unsigned() && st.at("nodes").value().get<std::uint64_t>() == 0 &&
        st.at("iteration").value().is_number_unsigned() && st.at("iteration").value().get<std::uint64_t>() > 0)
      st.at("nodes").fail("0 vertices at iteration " + st.at("iteration").value().dump() + ": a solution of " +
                          r.at("planner").string() + " after iteration 0 ends at a vertex the run added");
    if (ours && st.at("nodes").value().is_number_unsigned() && st.at("iteration").value().is_number_unsigned() &&
        st.at("nodes").value().get<std::uint64_t>() > st.at("iteration").value().get<std::uint64_t>() + 1)
      st.at("nodes").fail(st.at("nodes").value().dump() + " vertices at iteration " + st.at("iteration").value().dump() +
                          ": a tree of " + r.at("planner").string() + " holds its root and at most one vertex per iteration");
  }
  // Our planners stop at the target cost (the campaign sets it): a run with a target stage ran
  // no iteration after it (fifteenth campaign F7: 821 iterations after a target at 820 merged).
  if (ours && !r.at("target").value().is_null() && r.at("target").at("iteration").value().is_number_unsigned() &&
      r.at("iterations").value().is_number_unsigned() &&
      r.at("iterations").value().get<std::uint64_t>() != r.at("target").at("iteration").value().get<std::uint64_t>())
    r.at("iterations").fail(r.at("iterations").value().dump() + " iterations, but the target was reached at iteration " +
                            r.at("target").at("iteration").value().dump() + " (a run stops at its target)");
  // The target is reached at or after the first solution: never at an earlier iteration, with
  // fewer vertices or sooner (ninth campaign recheck of C1: such records were merged).
  const JsonField first = r.at("first"), target = r.at("target");
  if (!first.value().is_null() && !target.value().is_null())
    for (const char* k : {"iteration", "nodes", "time_ms"})  // (OMPL's stages have no iteration count: null)
      if (target.at(k).value().is_number() && first.at(k).value().is_number() &&
          target.at(k).number() < first.at(k).number())
        target.at(k).fail(target.at(k).value().dump() + " is before the first solution's " + first.at(k).value().dump() +
                          " (the target is reached at or after the first solution)");
}

RunRecord run_from(const nlohmann::json& j) {
  RunRecord r;
  r.planner = j.at("planner").get<std::string>();
  r.run = j.at("run").get<int>();
  r.result.solved = j.at("solved").get<bool>();
  if (r.result.solved) r.result.cost = j.at("cost").get<double>();
  r.result.iterations = count_from(j.at("iterations"));
  r.result.first = stage_from(j.at("first"));
  r.result.target = stage_from(j.at("target"));
  return r;
}

}  // namespace

nlohmann::json to_json(const FrontendBenchResult& r) {
  nlohmann::json planners = nlohmann::json::array();
  for (const PlannerSummary& s : r.summaries) planners.push_back(summary_json(s));
  nlohmann::json runs = nlohmann::json::array();
  for (const RunRecord& run : r.runs) runs.push_back(run_json(run));
  return {{"map", r.map},
          {"start", vec3_json(r.start)},
          {"goal", vec3_json(r.goal)},
          {"robot_radius", r.robot_radius},
          {"runs", r.options.runs},
          {"seed", r.options.seed},
          {"reference_cost", r.reference_cost},
          {"target_factor", r.options.target_factor},
          {"target_cost", r.target_cost},
          {"lower_bound", r.lower_bound},
          {"steer_step", r.steer_step},
          {"goal_radius", r.goal_radius},
          {"max_iterations", r.options.max_iterations},
          {"time_limit_s", r.options.time_limit_s},
          {"ompl_checks", r.options.ompl_checks > 0 ? nlohmann::json(r.options.ompl_checks) : nlohmann::json(nullptr)},
          {"safeguard", r.options.planner_options.safeguard},
          {"region",
           {{"source", r.region_source}, {"cells", r.region_cells}, {"sha256", r.region_sha256}, {"build_ms", r.region_ms}}},
          {"weights", r.weights_sha256.empty() ? nlohmann::json(nullptr)
                                               : nlohmann::json{{"source", r.options.weights_file.empty()
                                                                               ? std::string("builtin")
                                                                               : r.options.weights_file},
                                                                {"sha256", r.weights_sha256}}},
          {"throughput",
           {{"iterations", r.options.throughput_iterations},
            {"rrtstar_iterations_per_s", num(r.rrtstar_iterations_per_s)},
            {"ompl_rrtstar_iterations_per_s", num(r.ompl_rrtstar_iterations_per_s)}}},
          {"total_s", r.total_s},
          {"shard", {{"index", r.options.shard_index}, {"count", r.options.shard_count}}},
          {"planners", planners},
          {"run_records", runs}};
}

namespace {
/// The SHA-256 of the shipped sGAN weights, as a part records them for "builtin".
const std::string& builtin_weights_sha256() {
  static const std::string hash = heuristic::Sgan::builtin().sha256();
  return hash;
}
}  // namespace

nlohmann::json merge_frontend_shards(const std::vector<nlohmann::json>& parts, const std::vector<std::string>& files) {
  if (parts.empty()) throw Error("merge: no shard files");
  // Each part must be a campaign's JSON before anything is compared (REQ-REPORT-006): a map
  // or a truncated file is named with the field at fault, not as "a different campaign".
  std::vector<std::string> names;
  std::vector<RunRecord> runs;  // every part's records, parsed once here
  std::vector<std::size_t> first_run;  // part p's records are runs[first_run[p], first_run[p + 1])
  for (std::size_t p = 0; p < parts.size(); ++p) {
    names.push_back(p < files.size() ? files[p] : "shard file " + std::to_string(p + 1));
    first_run.push_back(runs.size());
    const JsonField root(parts[p], "", names.back());
    if (!parts[p].is_object()) root.fail("expected the JSON of `miner bench frontend --shard i/N --json`");
    if (parts[p].contains("format"))
      root.fail("is a \"" + (parts[p]["format"].is_string() ? parts[p]["format"].get<std::string>() : std::string("?")) +
                "\" file, not the JSON of `miner bench frontend --shard i/N --json`");
    // Every key of a campaign's JSON, and no other (issue 20: an added or renamed key was called
    // "a different campaign" of the other file).
    root.only_keys({"map", "start", "goal", "robot_radius", "runs", "seed", "reference_cost", "target_factor",
                    "target_cost", "lower_bound", "steer_step", "goal_radius", "max_iterations", "time_limit_s", "ompl_checks",
                    "safeguard", "region", "weights", "throughput", "total_s", "shard", "planners", "run_records"});
    for (const char* k : {"runs", "seed"}) (void)root.at(k);
    const JsonField shard = root.at("shard");
    shard.only_keys({"index", "count"});  // eighteenth campaign F7: an unknown key in it was ignored
    (void)shard.at("index").integer();
    (void)shard.at("count").integer();
    // A part's wall clock: no campaign part runs a year (seventeenth campaign F27: two parts of
    // 1e308 s summed to inf, written as null).
    if (!(root.at("total_s").number() >= 0.0 && root.at("total_s").number() <= kMaxPartSeconds))
      root.at("total_s").fail("a part's duration must be in [0, " + exact_number(kMaxPartSeconds) + "] s (a year), got " +
                              exact_number(root.at("total_s").number()));
    // The settings as `bench frontend` writes them (seventeenth campaign F1, F2): integers
    // written as integers (a seed of 1.0 beside 1 compared equal, and the merged bytes followed
    // the order of the parts), the options' ranges, a boolean safeguard, a named map, a region of
    // at least one cell.
    const auto whole = [&](const JsonField& f, std::uint64_t lo, std::uint64_t hi, const std::string& as) {
      if (!f.value().is_number_unsigned() || f.value().get<std::uint64_t>() < lo || f.value().get<std::uint64_t>() > hi)
        f.fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (as " + as + "), got " +
               f.value().dump());
    };
    whole(root.at("seed"), 0, std::numeric_limits<std::uint64_t>::max(), "--seed");
    whole(root.at("runs"), 1, std::numeric_limits<int>::max(), "--runs");
    whole(root.at("max_iterations"), 1, plan::kMaxIterations, "--max-iterations");
    whole(root.at("throughput").at("iterations"), 0, std::numeric_limits<std::uint64_t>::max(), "--throughput-iterations");
    whole(root.at("region").at("cells"), 1, plan::HeuristicRegion::kMaxCells, "a region's cells");
    if (!root.at("safeguard").value().is_boolean()) root.at("safeguard").fail("expected true or false, got " + root.at("safeguard").value().dump());
    if (root.at("map").string().empty()) root.at("map").fail("names no map");
    (void)root.at("region").at("source").string();
    if (const double f = root.at("target_factor").number(); !(f >= kMinTargetFactor && f <= kMaxTargetFactor))
      root.at("target_factor").fail("must be in [0.01, 100] (as --target-factor), got " + root.at("target_factor").value().dump());
    root.at("region").only_keys({"source", "cells", "sha256", "build_ms"});
    // The region's build time is copied into the merge from shard 0: a time like every other
    // (eighteenth campaign F6: -5, 1e300, a string or no value merged).
    {
      constexpr double kMaxBuildMs = 1e9;  // as a record's stage time: 11 days
      const JsonField build = root.at("region").at("build_ms");
      if (!(build.number() >= 0.0 && build.number() <= kMaxBuildMs)) build.fail("a time must be in [0, 1e9] ms");
    }
    (void)sha256_field(root.at("region").at("sha256"));
    // The weights miner-sgan ran with, by content: given exactly when miner-sgan ran, and the
    // shipped ones' own hash for "builtin" (seventeenth campaign F3, F20: null beside miner-sgan
    // records, weights without them, "builtin" with any hash were merged).
    {
      bool sgan_ran = false;
      const JsonField listed = root.at("planners");
      for (std::size_t i = 0; i < listed.array_size(); ++i)
        sgan_ran = sgan_ran || listed.at(i).at("planner").string() == kMinerSgan;
      const JsonField w = root.at("weights");
      if (sgan_ran && w.value().is_null()) w.fail("null, but miner-sgan ran: its weights are recorded");
      if (!sgan_ran && !w.value().is_null()) w.fail("weights, but miner-sgan did not run (null without it)");
      if (!w.value().is_null()) {
        w.only_keys({"source", "sha256"});
        const std::string source = w.at("source").string(), hash = sha256_field(w.at("sha256"));
        if (source.empty()) w.at("source").fail("names no weights (\"builtin\" for the shipped ones)");
        if (source == "builtin" && hash != builtin_weights_sha256())
          w.at("sha256").fail("is not the shipped weights' SHA-256 " + builtin_weights_sha256());
      }
    }
    // The summaries and the throughput block have exactly the keys a campaign writes (issue 20:
    // unknown keys there were carried into the merge).
    root.at("throughput").only_keys({"iterations", "rrtstar_iterations_per_s", "ompl_rrtstar_iterations_per_s"});
    const nlohmann::json summary_keys = summary_json(PlannerSummary{});
    std::vector<std::string> keys;
    for (const auto& item : summary_keys.items()) keys.push_back(item.key());
    const JsonField planners = root.at("planners");
    for (std::size_t i = 0; i < planners.array_size(); ++i) {
      planners.at(i).only_keys(keys);
      (void)planners.at(i).at("planner").string();
    }
    const double lower = root.at("lower_bound").number(), budget = root.at("max_iterations").number();
    constexpr double kRoundoff = 1e-9;  // relative: the bound and the costs are sums of lengths
    // The campaign's costs agree with each other as run_frontend_bench sets them (issue 20,
    // fourth campaign: a target below the straight line was merged): the bound is a length,
    // the A* reference a path no shorter than it, the target the factor times the reference.
    if (!(lower >= 0.0)) root.at("lower_bound").fail("the straight-line bound is a length, >= 0");
    // The bound is |goal - start| (fourteenth campaign C4: 1.0 for a 10.77 m query was merged),
    // and the planners' settings are what a campaign can run with.
    {
      const auto point = [&](const char* k) {
        const JsonField f = root.at(k);
        if (f.array_size() != 3) f.fail("expected [x, y, z]");
        return Eigen::Vector3d(f.at(0).number(), f.at(1).number(), f.at(2).number());
      };
      const double line = (point("goal") - point("start")).norm();
      if (std::fabs(lower - line) > kRoundoff * std::max(1.0, line))
        root.at("lower_bound").fail(root.at("lower_bound").value().dump() + " is not |goal - start| = " + short_number(line));
    }
    const double steer = root.at("steer_step").number(), goal_radius = root.at("goal_radius").number(),
                 robot_radius = root.at("robot_radius").number();
    if (!(std::isfinite(steer) && steer > 0.0)) root.at("steer_step").fail("the steering step must be positive and finite");
    // The ranges `bench frontend` takes (fifteenth campaign F7: a goal radius or a time limit of
    // 0, which no campaign can run with, merged).
    if (!(goal_radius >= kMinGoalRadius && goal_radius <= kMaxGoalRadius))
      root.at("goal_radius").fail("the goal radius must be in [1e-6, 1e6] m (as --goal-radius)");
    // ... and leaves the start outside X_goal, as `bench frontend` requires (F17).
    if (lower <= goal_radius)
      root.at("goal_radius").fail(root.at("goal_radius").value().dump() + " m reaches the start (|goal - start| = " +
                                  root.at("lower_bound").value().dump() + " m): no campaign runs such a query");
    if (!root.at("ompl_checks").value().is_null()) whole(root.at("ompl_checks"), 1, kMaxOmplChecks, "--ompl-checks");
    const double time_limit = root.at("time_limit_s").number();
    if (!(time_limit >= kMinTimeLimitS && time_limit <= kMaxTimeLimitS))
      root.at("time_limit_s").fail("the time limit must be in [0.001, 86400] s (as --time-limit)");
    // --ompl-checks lifts the clock to a day, and a campaign with it writes that (seventeenth
    // campaign F6: a part with ompl_checks and a time limit of 2 s merged).
    const bool by_checks = !root.at("ompl_checks").value().is_null();
    if (by_checks && time_limit != kMaxTimeLimitS)
      root.at("time_limit_s").fail(exact_number(time_limit) + ", but a campaign with ompl_checks runs with the clock lifted to " +
                                   exact_number(kMaxTimeLimitS) + " s (as --ompl-checks writes it)");
    if (!(std::isfinite(robot_radius) && robot_radius >= 0.0)) root.at("robot_radius").fail("the robot radius must be >= 0 and finite");
    const double reference = root.at("reference_cost").number();
    if (reference < lower * (1.0 - kRoundoff))
      root.at("reference_cost").fail("the A* reference " + root.at("reference_cost").value().dump() +
                                     " is below the lower bound " + root.at("lower_bound").value().dump() +
                                     " (no path is shorter)");
    const double factor = root.at("target_factor").number(), target = root.at("target_cost").number();
    if (std::fabs(target - factor * reference) > kRoundoff * std::max(1.0, std::fabs(target)))
      root.at("target_cost").fail(root.at("target_cost").value().dump() + " is not target_factor x reference_cost = " +
                                  root.at("target_factor").value().dump() + " x " +
                                  root.at("reference_cost").value().dump());
    const JsonField records = root.at("run_records");
    for (std::size_t k = 0; k < records.array_size(); ++k) {
      const JsonField r = records.at(k);
      r.only_keys({"planner", "run", "solved", "cost", "iterations", "first", "target"});
      (void)r.at("planner").string();
      // A run number as a campaign writes it: an integer, not 1.0 (fifteenth campaign F7).
      if (!r.at("run").value().is_number_integer()) r.at("run").fail("expected an integer run number, got " + r.at("run").value().dump());
      (void)r.at("run").integer();
      // OMPL's planners stop at the time limit, checked every 64 termination calls: a stage
      // found past twice the limit and a second is no run of this campaign (fifteenth campaign
      // F7: a target at 20 s of a 10 s campaign merged). Ours stop on iterations only.
      if (r.at("planner").string().rfind("ompl:", 0) == 0)
        for (const char* stage : {"first", "target"})
          if (r.has(stage) && r.at(stage).value().is_object() && r.at(stage).has("time_ms") &&
              r.at(stage).at("time_ms").number() > kOmplOvershoot * 1000.0 * time_limit + 1000.0)
            r.at(stage).at("time_ms").fail(r.at(stage).at("time_ms").value().dump() + " ms, past the campaign's time limit " +
                                           root.at("time_limit_s").value().dump() + " s (OMPL's runs stop there)");
      // A cost is a path length: finite and >= 0 (issue 20: a cost of -5 was averaged in), never
      // below the campaign's lower bound (the straight line), never above the run's own first
      // solution (costs only fall); a run stops within the iteration budget.
      if (r.has("cost") && r.at("cost").value().is_number()) {
        const double cost = r.at("cost").number();
        if (!(cost >= 0.0)) r.at("cost").fail("a path cost must be >= 0");
        if (cost < lower * (1.0 - kRoundoff))
          r.at("cost").fail("a path cost of " + r.at("cost").value().dump() + " is below the campaign's lower bound " +
                            root.at("lower_bound").value().dump() + " (no path is shorter)");
        if (r.has("first") && r.at("first").value().is_object() && r.at("first").has("cost") &&
            cost > r.at("first").at("cost").number() * (1.0 + kRoundoff))
          r.at("cost").fail("a final cost of " + r.at("cost").value().dump() + " is above the run's first solution's " +
                            r.at("first").at("cost").value().dump() + " (costs only fall)");
      }
      // A target stage is a solution at or below the campaign's target cost, no better than the
      // run's final cost and no worse than its first (ninth campaign C1: a target of 99 above a
      // 13.74 target and above the run's costs was merged and counted as reached).
      // A run that ended at or below the target cost reached it: a null target there is a lie.
      if (r.has("target") && r.at("target").value().is_null() && r.has("cost") && r.at("cost").value().is_number() &&
          r.at("cost").number() < target * (1.0 - kRoundoff))
        r.at("target").fail("null, but the run's cost " + r.at("cost").value().dump() +
                            " is below the campaign's target_cost " + root.at("target_cost").value().dump() +
                            ": the target was reached");
      if (r.has("target") && r.at("target").value().is_object() && r.at("target").has("cost")) {
        const JsonField t = r.at("target").at("cost");
        const double reached = t.number();
        if (reached > target * (1.0 + kRoundoff))
          t.fail(t.value().dump() + " is above the campaign's target_cost " + root.at("target_cost").value().dump() +
                 ": the target was not reached at that cost");
        if (r.has("cost") && r.at("cost").value().is_number() && reached < r.at("cost").number() * (1.0 - kRoundoff))
          t.fail(t.value().dump() + " is below the run's final cost " + r.at("cost").value().dump() + " (costs only fall)");
        if (r.has("first") && r.at("first").value().is_object() && r.at("first").has("cost") &&
            reached > r.at("first").at("cost").number() * (1.0 + kRoundoff))
          t.fail(t.value().dump() + " is above the run's first solution's " + r.at("first").at("cost").value().dump() +
                 " (costs only fall)");
      }
      // The budget binds our planners and OMPL's RRT*s, which are given it; OMPL's other
      // planners stop on the time limit only (session 36: an AIT* run of 4129 iterations in a
      // campaign of 1500 was refused, so no campaign with AIT* merged).
      if (r.has("iterations") && r.at("iterations").value().is_number() &&
          bounded_by_iterations(r.at("planner").string()) && r.at("iterations").number() > budget)
        r.at("iterations").fail("ran " + r.at("iterations").value().dump() + " iterations, more than the campaign's budget " +
                                root.at("max_iterations").value().dump());
      // With ompl_checks an OMPL planner stops after that many termination checks, one per
      // iteration (seventeenth campaign F11: a BIT* record of 10^6 iterations in a campaign of
      // 3000 checks merged).
      if (by_checks && r.at("planner").string().rfind("ompl:", 0) == 0 && r.has("iterations") &&
          r.at("iterations").value().is_number() && r.at("iterations").number() > root.at("ompl_checks").number())
        r.at("iterations").fail("ran " + r.at("iterations").value().dump() +
                                " iterations, more than the campaign's ompl_checks " +
                                root.at("ompl_checks").value().dump() + " (OMPL's runs stop there)");
      check_run_record(r, lower);
      try {
        runs.push_back(run_from(parts[p]["run_records"][k]));
      } catch (const nlohmann::json::exception& e) {
        r.fail("malformed run record: " + json_error_text(e));
      }
    }
    // Shard 0 alone measures the throughput (when its iterations are > 0); other parts carry
    // null rates (fifteenth campaign F7: rates in part 1, or null rates in part 0, merged).
    {
      const JsonField tp = root.at("throughput");
      const bool measures = shard.at("index").integer() == 0 && tp.at("iterations").number() > 0;
      if (measures && !tp.at("rrtstar_iterations_per_s").value().is_number())
        tp.at("rrtstar_iterations_per_s").fail("null, but shard 0 of a campaign with throughput iterations measures it");
      if (!measures)
        for (const char* k : {"rrtstar_iterations_per_s", "ompl_rrtstar_iterations_per_s"})
          if (!tp.at(k).value().is_null())
            tp.at(k).fail("a rate, but only shard 0 of a campaign with throughput iterations > 0 measures one");
      if (measures && tp.at("rrtstar_iterations_per_s").number() < 0.0)
        tp.at("rrtstar_iterations_per_s").fail("a rate must be >= 0");
      if (measures && tp.at("ompl_rrtstar_iterations_per_s").value().is_number() && tp.at("ompl_rrtstar_iterations_per_s").number() < 0.0)
        tp.at("ompl_rrtstar_iterations_per_s").fail("a rate must be >= 0");
    }
  }
  // An OMPL planner reports its vertex count at its first solution always or never (the count
  // is a progress property that some planners have): one record that differs from the others of its
  // planner was edited (sixteenth campaign F1: a first.nodes of 10 among nulls merged).
  {
    // The target's count may be the run's final one (ompl_planners.cpp), so only the first
    // solution's is the progress property's alone.
    std::map<std::string, std::pair<bool, std::string>> reports;  // planner -> (count known, where first seen)
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const JsonField records = JsonField(parts[p], "", names[p]).at("run_records");
      for (std::size_t k = 0; k < records.array_size(); ++k) {
        const JsonField r = records.at(k);
        const std::string planner = r.at("planner").string();
        if (planner.rfind("ompl:", 0) != 0 || !r.at("first").value().is_object()) continue;
        const JsonField nodes = r.at("first").at("nodes");
        const bool known = !nodes.value().is_null();
        const auto [it, fresh] = reports.emplace(planner, std::make_pair(known, names[p] + ": " + nodes.path()));
        if (!fresh && it->second.first != known)
          nodes.fail(std::string(known ? "a count" : "null") + ", but " + it->second.second + " is " +
                     (it->second.first ? "a count" : "null") + ": " + planner +
                     " reports its vertices at its first solution in every run or in none");
      }
    }
  }
  // Everything but the per-shard fields must agree; the throughput check's iteration count is a
  // setting (shard 0 measures it, the merge keeps shard 0's rates: parts given other counts are
  // other campaigns; issue 20, --throughput-iterations merged across parts that disagreed).
  // The region is built in every part from the same map and query: its source and cell count
  // are settings (fourteenth campaign C4: 1 cell in one part, 474 in the others, was merged);
  // only its build time is the part's own.
  const auto settings = [](nlohmann::json j) {
    for (const char* k : {"planners", "run_records", "shard", "total_s"}) j.erase(k);
    j["region"].erase("build_ms");
    // A region or weights file is known by its SHA-256: the same file spelled another way
    // (./reg.json, an absolute path, a copy) is the same campaign (seventeenth campaign F12); the
    // merged file records shard 0's spelling.
    if (j["region"].is_object() && j["region"].contains("sha256") && j["region"]["sha256"].is_string())
      j["region"].erase("source");
    if (j.contains("weights") && j["weights"].is_object() && j["weights"].contains("sha256") &&
        j["weights"]["sha256"].is_string() && j["weights"].contains("source") && j["weights"]["source"] != "builtin")
      j["weights"].erase("source");
    if (j.contains("throughput") && j["throughput"].is_object()) {
      j["throughput"].erase("rrtstar_iterations_per_s");
      j["throughput"].erase("ompl_rrtstar_iterations_per_s");
    }
    return j;
  };
  const nlohmann::json common = settings(parts.front());
  std::vector<nlohmann::json> tags;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const nlohmann::json mine = settings(parts[p]);
    // Name the first setting that differs, with both values.
    if (const std::string d = first_difference(mine, common); !d.empty())
      throw Error("merge: " + names[p] + " and " + names.front() + " are different campaigns: " + d);
    // The planner list is per-shard JSON (its summaries), so its names are compared on their own:
    // a part of other --planners is another campaign, not an incomplete one (fifth campaign).
    const auto planner_names = [](const nlohmann::json& part) {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& s : part.at("planners")) list.push_back(s.at("planner"));
      return list;
    };
    if (planner_names(parts[p]) != planner_names(parts.front()))
      throw Error("merge: " + names[p] + " and " + names.front() + " are different campaigns: their planners are " +
                  planner_names(parts[p]).dump() + " and " + planner_names(parts.front()).dump());
    tags.push_back(parts[p].at("shard"));
  }
  require_complete_parts(tags, names, "merge: the campaign");
  // The parts' times summed in shard order, not argument order (fifteenth campaign F6: the
  // merged total_s differed in its last digit with the order of the files, "any order").
  std::vector<std::pair<int, double>> part_seconds;
  for (const auto& part : parts) part_seconds.emplace_back(part.at("shard").at("index").get<int>(), part.at("total_s").get<double>());
  std::sort(part_seconds.begin(), part_seconds.end());
  double total_s = 0.0;
  for (const auto& [index, seconds] : part_seconds) total_s += seconds;
  nlohmann::json merged = parts.front();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& part = parts[p];
    if (part.at("shard").at("index").get<int>() == 0) {
      merged["throughput"] = part.at("throughput");
      merged["region"] = part.at("region");
      if (part.contains("weights")) merged["weights"] = part.at("weights");
    }
  }
  // A record twice (the same planner and run in two parts, or twice in one) would count
  // one sample as two: refused, naming both places.
  std::map<std::pair<std::string, int>, std::string> seen;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& records = parts[p].at("run_records");
    for (std::size_t k = 0; k < records.size(); ++k) {
      const std::pair<std::string, int> key{records[k].at("planner").get<std::string>(), records[k].at("run").get<int>()};
      const std::string where = names[p] + " run_records[" + std::to_string(k) + "]";
      const auto [it, fresh] = seen.emplace(key, where);
      if (!fresh) {
        throw Error("merge: " + where + ": planner " + key.first + " run " + std::to_string(key.second) +
                    " is already in " + it->second + " (a duplicated record)");
      }
    }
  }
  std::vector<std::string> order;
  for (const auto& s : parts.front().at("planners")) order.push_back(s.at("planner").get<std::string>());
  // Every record belongs to the campaign (a planner it ran, a run r < runs, in the part that
  // runs it: r % N == i), and every (planner, run) of the campaign has its record (issue 20: a
  // part missing a record merged into "5 runs" of 6).
  const int campaign_runs = JsonField(parts.front(), "", names.front()).at("runs").integer();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const auto& records = parts[p].at("run_records");
    const int index = parts[p].at("shard").at("index").get<int>(), count = parts[p].at("shard").at("count").get<int>();
    for (std::size_t k = 0; k < records.size(); ++k) {
      const std::string planner = records[k].at("planner").get<std::string>();
      const int run = records[k].at("run").get<int>();
      const std::string where = names[p] + ": run_records[" + std::to_string(k) + "]";
      if (std::find(order.begin(), order.end(), planner) == order.end())
        throw Error("merge: " + where + ".planner: \"" + planner + "\" is not a planner of this campaign");
      if (run < 0 || run >= campaign_runs || run % count != index)
        throw Error("merge: " + where + ".run: run " + std::to_string(run) + " is not a run of part " +
                    std::to_string(index) + "/" + std::to_string(count) + " of a campaign of " +
                    std::to_string(campaign_runs) + " runs");
    }
  }
  for (const auto& planner : order)
    for (int run = 0; run < campaign_runs; ++run)
      if (!seen.count({planner, run}))
        throw Error("merge: planner " + planner + " run " + std::to_string(run) + " has no record in any part (part " +
                    std::to_string(run % static_cast<int>(parts.size())) + " is incomplete)");
  // Each part's summaries are what its own records give (fifteenth campaign F7: a summary
  // edited to contradict the records merged; the merge recomputes them, but a part that
  // contradicts itself is not a campaign's output). Checked after the records are known to be
  // the campaign's, so a missing or foreign record is named as such.
  first_run.push_back(runs.size());
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const std::vector<RunRecord> own(runs.begin() + static_cast<std::ptrdiff_t>(first_run[p]),
                                     runs.begin() + static_cast<std::ptrdiff_t>(first_run[p + 1]));
    const JsonField planners = JsonField(parts[p], "", names[p]).at("planners");
    for (std::size_t i = 0; i < planners.array_size(); ++i) {
      const nlohmann::json want = summary_json(summarise(planners.at(i).at("planner").string(), own));
      if (const std::string d = first_difference(parts[p]["planners"][i], want); !d.empty())
        planners.at(i).fail("contradicts the part's own run_records (" + d + ")");
    }
  }
  const auto rank = [&](const std::string& planner) {
    return std::find(order.begin(), order.end(), planner) - order.begin();
  };
  std::stable_sort(runs.begin(), runs.end(), [&](const RunRecord& a, const RunRecord& b) {
    return rank(a.planner) != rank(b.planner) ? rank(a.planner) < rank(b.planner) : a.run < b.run;
  });
  merged["planners"] = nlohmann::json::array();
  for (const auto& planner : order) merged["planners"].push_back(summary_json(summarise(planner, runs)));
  merged["run_records"] = nlohmann::json::array();
  for (const auto& r : runs) merged["run_records"].push_back(run_json(r));
  merged["shard"] = {{"index", 0}, {"count", 1}};
  merged["total_s"] = total_s;
  return merged;
}

void print_table(const FrontendBenchResult& r, std::ostream& out) {
  out << "map " << r.map << ", " << r.options.runs << " runs per planner, seed " << r.options.seed << "\n"
      << std::fixed << std::setprecision(2) << "A* reference cost " << r.reference_cost << " m, target "
      << r.target_cost << " m (" << r.options.target_factor << " x), straight line " << r.lower_bound
      << " m; eta " << r.steer_step << " m, goal radius " << r.goal_radius << " m\n"
      << "miner region: " << r.region_source << " (" << r.region_cells << " cells, built in " << r.region_ms
      << " ms, not counted)\n\n";
  out << std::left << std::setw(22) << "planner" << std::right << std::setw(8) << "success" << std::setw(10)
      << "init it" << std::setw(10) << "init nod" << std::setw(10) << "init cost" << std::setw(10) << "init ms"
      << std::setw(8) << "target" << std::setw(10) << "opt it" << std::setw(10) << "opt nod" << std::setw(10)
      << "opt ms" << "\n";
  const auto cell = [&](double v, int prec) {
    std::ostringstream s;
    if (std::isfinite(v)) s << std::fixed << std::setprecision(prec) << v;
    else s << "-";
    return s.str();
  };
  for (const PlannerSummary& s : r.summaries) {
    out << std::left << std::setw(22) << s.planner << std::right << std::setw(7) << cell(100 * s.success_rate, 0)
        << "%" << std::setw(10) << cell(s.first_iterations, 0) << std::setw(10) << cell(s.first_nodes, 0)
        << std::setw(10) << cell(s.first_cost, 1) << std::setw(10) << cell(s.first_time_ms, 2) << std::setw(7)
        << cell(100 * s.target_rate, 0) << "%" << std::setw(10) << cell(s.target_iterations, 0) << std::setw(10)
        << cell(s.target_nodes, 0) << std::setw(10) << cell(s.target_time_ms, 2) << "\n";
  }
  out << "(medians; opt = until cost <= target, '-' unless more than half the runs got there)\n";
  if (std::isfinite(r.rrtstar_iterations_per_s)) {
    out << "throughput over " << r.options.throughput_iterations << " iterations: rrtstar "
        << cell(r.rrtstar_iterations_per_s, 0) << " it/s, ompl:RRTstar " << cell(r.ompl_rrtstar_iterations_per_s, 0)
        << " it/s\n";
  }
}

void write_ompl_log(const FrontendBenchResult& r, std::ostream& out) {
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  std::string experiment = r.map;
  for (char& c : experiment) {
    if (c == ' ' || c == '/' ) c = '_';
  }
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S", std::gmtime(&now));
  out << std::setprecision(17);
  out << "MINER version 0.1.0\n"
      << "Experiment frontend_" << experiment << "\n"
      << "3 experiment properties\n"
      << "target_cost REAL = " << r.target_cost << "\n"
      << "reference_cost REAL = " << r.reference_cost << "\n"
      << "goal_radius REAL = " << r.goal_radius << "\n"
      << "Running on " << host << "\n"
      << "Starting at " << date << "\n"
      << "<<<|\n"
      << "map " << r.map << "; start " << r.start.transpose() << "; goal " << r.goal.transpose()
      << "; robot radius " << r.robot_radius << "; steering step " << r.steer_step << "; target factor "
      << r.options.target_factor << "\n"
      << "|>>>\n"
      << r.options.seed << " is the random seed\n"
      << r.options.time_limit_s << " seconds per run\n"
      << "0 MB per run\n"
      << r.options.runs << " runs per planner\n"
      << r.total_s << " seconds spent to collect the data\n"
      << "0 enum types\n"
      << r.summaries.size() << " planners\n";
  const auto opt = [](bool has, double v) {
    std::ostringstream s;
    s << std::setprecision(17);
    if (has && std::isfinite(v)) s << v;
    return s.str();
  };
  for (const PlannerSummary& s : r.summaries) {
    out << s.planner << "\n"
        << "0 common properties\n"
        << "12 properties for each run\n"
        << "time REAL\n"
        << "solved BOOLEAN\n"
        << "best cost REAL\n"
        << "iterations INTEGER\n"
        << "graph states INTEGER\n"
        << "first solution time REAL\n"
        << "first solution cost REAL\n"
        << "first solution iterations INTEGER\n"
        << "first solution nodes INTEGER\n"
        << "target time REAL\n"
        << "target iterations INTEGER\n"
        << "target nodes INTEGER\n";
    std::vector<const RunRecord*> mine;
    for (const RunRecord& run : r.runs) {
      if (run.planner == s.planner) mine.push_back(&run);
    }
    out << mine.size() << " runs\n";
    for (const RunRecord* run : mine) {
      const plan::PlanResult& p = run->result;
      const bool f = p.first.has_value(), t = p.target.has_value();
      out << opt(true, p.time_ms / 1000.0) << "; " << (p.solved ? 1 : 0) << "; " << opt(p.solved, p.cost) << "; "
          << p.iterations << "; " << p.nodes + 1 << "; " << opt(f, f ? p.first->time_ms / 1000.0 : 0) << "; "
          << opt(f, f ? p.first->cost : 0) << "; " << (f ? std::to_string(p.first->iteration) : "") << "; "
          << (f ? std::to_string(p.first->nodes) : "") << "; " << opt(t, t ? p.target->time_ms / 1000.0 : 0)
          << "; " << (t ? std::to_string(p.target->iteration) : "") << "; "
          << (t ? std::to_string(p.target->nodes) : "") << "; \n";
    }
    out << "2 progress properties for each run\n"
        << "time REAL\n"
        << "best cost REAL\n"
        << mine.size() << " runs\n";
    for (const RunRecord* run : mine) {
      for (const plan::StageRecord& imp : run->result.improvements) {
        out << opt(true, imp.time_ms / 1000.0) << "," << opt(true, imp.cost) << ",;";
      }
      out << "\n";
    }
    out << ".\n";
  }
}

}  // namespace miner::bench
