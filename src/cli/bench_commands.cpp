// `miner bench backend` (REQ-TRAJ-009).
#include <algorithm>
#include <map>
#include <ostream>
#include <sstream>
#include <tuple>

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "bench/backend_bench.hpp"
#include "bench/frontend_bench.hpp"
#include "bench/heuristic_bench.hpp"
#include "bench/ompl_planners.hpp"
#include "bench/paper_bench.hpp"
#include "bench/suite_bench.hpp"
#include "bench/voxel_bench.hpp"
#include "miner/core/progress.hpp"
#include "cli/cli.hpp"
#include "miner/core/shard.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/plan/heuristic_region.hpp"

namespace miner::cli {

namespace {
struct BackendOptions {
  bench::BackendBenchOptions bench;
  OutputOptions output;
};

struct FrontendOptions {
  QueryOptions query;
  bench::FrontendBenchOptions bench;
  std::vector<int> region_dims = std::vector<int>(3, plan::HeuristicRegion::kGridSide);
  std::string ompl_log;
  std::string shard;
  bool quiet = false;
  OutputOptions output;
};

void run_frontend(const FrontendOptions& o, std::ostream& out) {
  const ResolvedQuery q = resolve_query(o.query);
  bench::FrontendBenchOptions options = o.bench;
  options.region_dims = Eigen::Vector3i(o.region_dims[0], o.region_dims[1], o.region_dims[2]);
  if (!o.shard.empty()) std::tie(options.shard_index, options.shard_count) = parse_shard(o.shard);
  // A progress bar on stderr when it is a terminal (--json output stays clean).
  const auto result = bench::run_frontend_bench(q.map, o.query.map, q.start, q.goal, q.radius, options,
                                                o.quiet ? nullptr : terminal_stream());
  if (!o.ompl_log.empty()) {
    std::ostringstream log;
    bench::write_ompl_log(result, log);
    write_file_atomic(o.ompl_log, log.str());
  }
  std::ostringstream table;
  bench::print_table(result, table);
  emit(o.output, bench::to_json(result), table.str(), out);
}

/// A figure folder (bench paper, bench suite) is replaced only when it is an earlier one, told
/// by its manifest (kFiguresMarker): the --figures option's own check, applied before the work
/// to the folder used, the default one too.
/// A refusal is a usage error naming --figures, the default folder's too (eighteenth campaign
/// F12: that one was exit 1 without naming the option).
void require_figures_folder(const std::filesystem::path& folder, bool given) {
  std::string path = folder.string();
  if (const std::string problem = output_folder_for(kFiguresMarker, {".svg", ".json"})(path); !problem.empty())
    throw CLI::ValidationError("--figures", (given ? "" : "the default figures folder (beside the report) ") + problem);
}

/// The figures folder of a report, checked before the work (require_figures_folder): --figures
/// when given, else beside the report and named after it (docs/results.md -> docs/results/), so
/// that two reports in one folder never share one figures folder, which each run replaces whole
/// (issue 20, eighth campaign D1, D2: a second report's run deleted the first one's box plots).
/// A name that is all suffix (".md") gets "-figures" added.
std::filesystem::path figures_folder(const std::filesystem::path& results, const std::string& given) {
  const std::filesystem::path stem = results.stem();
  const std::filesystem::path folder =
      !given.empty() ? std::filesystem::path(given)
                     : results.parent_path() / (stem == results.filename() ? stem.string() + "-figures" : stem.string());
  require_figures_folder(folder, !given.empty());
  return folder;
}

/// The figures and their manifest figures.json (format, command, files), written as one folder:
/// a later run with other maps or steps knows the folder as its own by the manifest (seventh
/// campaign C6: it was refused for holding none of the new file names).
void write_figures(const std::filesystem::path& folder, const std::map<std::string, std::string>& figures,
                   const std::string& command) {
  std::vector<std::pair<std::string, std::string>> files(figures.begin(), figures.end());
  Json names = Json::array();
  for (const auto& f : files) names.push_back(f.first);
  files.emplace_back(kFiguresMarker.file, dump_json({{"format", kFiguresFormat}, {"command", command}, {"files", names}}));
  write_folder_atomic(folder.string(), files, kFiguresMarker);
}
}  // namespace

void add_bench_commands(CLI::App& app, std::ostream& out) {
  CLI::App* bench_cmd = app.add_subcommand("bench", "benchmarks (figures for docs/)");
  bench_cmd->require_subcommand(1);
  auto o = std::make_shared<BackendOptions>();
  CLI::App* b = bench_cmd->add_subcommand("backend", "MINCO vs dense LU, closed form and KKT QP (paper Table II)");
  b->add_option("--segments", o->bench.segments, "segment counts M")->capture_default_str()->delimiter(',')
      ->check(integer_in(1, 1000000));
  b->add_option("--orders", o->bench.orders, "orders s (3 jerk, 4 snap)")->capture_default_str()->delimiter(',')
      ->check(integer_in(3, 4));
  b->add_option("--methods", o->bench.methods, "minco, dense-lu, closed-form, kkt-qp")->capture_default_str()->delimiter(',')
      ->check(CLI::IsMember({"minco", "dense-lu", "closed-form", "kkt-qp"}));
  b->add_option("--max-dense-segments", o->bench.max_dense_segments, "skip the O(M^3) baselines above this M")
      // The dense baselines cost O((2sM)^3) per solve: kkt-qp's KKT solve takes ~1 s at M = 200
      // and 15 s at M = 500 (issue 20: a campaign at 500 ran for minutes whatever --budget said,
      // since every method is solved at least --samples + 1 times).
      ->capture_default_str()->check(integer_in(0, 200));
  b->add_option("--budget", o->bench.budget_s, "seconds per (method, order, M)")->capture_default_str()
      ->check(finite_in(1e-4, 3600.0));
  b->add_option("--samples", o->bench.samples, "timed batches (median reported; fewer when one solve outlasts a batch)")
      ->capture_default_str()->check(integer_in(3, 10000));
  b->add_option("--seed", o->bench.seed, "seed of the waypoints")->capture_default_str()->check(kUnsigned64);
  add_output_options(b, o->output);
  b->callback([o, &out] {
    const auto records = bench::run_backend_bench(o->bench);
    std::ostringstream table;
    bench::print_table(records, table);
    emit(o->output, bench::to_json(records), table.str(), out);
  });

  auto f = std::make_shared<FrontendOptions>();
  CLI::App* fc = bench_cmd->add_subcommand(
      "frontend", "Monte Carlo front-end campaign like the paper's Table I, with OMPL's planners beside ours");
  add_query_options(fc, f->query);
  // An unknown name is a usage error (exit 2) naming every valid one (issue 20: it failed later, exit 1).
  const CLI::Validator planner_name([](std::string& name) { return bench::unknown_planner(name); }, "PLANNER");
  fc->add_option("--planners", f->bench.planners,
                 "planners (default: rrtstar,informed,guided,miner and every ompl:* planner)")
      ->delimiter(',')
      ->check(planner_name);
  fc->add_option("--runs", f->bench.runs, "runs per planner")->check(kRunsRange)->capture_default_str();
  fc->add_option("--seed", f->bench.seed, "master seed (run k uses stream k)")->capture_default_str()->check(kUnsigned64);
  fc->add_option("--target-factor", f->bench.target_factor, "target cost = this x the A* reference cost")
      ->check(finite_in(bench::kMinTargetFactor, bench::kMaxTargetFactor))
      ->capture_default_str();
  fc->add_option("--iterations,--max-iterations", f->bench.max_iterations, "iteration budget per run (as plan --iterations)")
      ->check(kIterationsRange)
      ->capture_default_str();
  fc->add_option("--time-limit", f->bench.time_limit_s, "wall-clock cap per run of OMPL's planners in s (ours stop on --iterations)")
      ->check(finite_in(bench::kMinTimeLimitS, bench::kMaxTimeLimitS))
      ->capture_default_str();
  fc->add_option("--ompl-checks", f->bench.ompl_checks,
                 "instead of --time-limit: OMPL's planners stop after N termination checks (one per iteration), "
                 "so their records repeat exactly")
      ->check(integer_in(1, static_cast<long long>(bench::kMaxOmplChecks)));
  // The same ranges as plan's (issue 20: 1e308 was accepted and printed with all its digits).
  fc->add_option("--step", f->bench.planner_options.steer_step, "steering step eta in m (default 0.1 x diagonal)")
      ->check(finite_in(1e-6, 1e6));
  fc->add_option("--goal-radius", f->bench.planner_options.goal_radius, "goal radius in m (default 2 x resolution)")
      ->check(finite_in(bench::kMinGoalRadius, bench::kMaxGoalRadius));
  fc->add_flag("!--no-safeguard", f->bench.planner_options.safeguard,
               "miner, miner-sgan: the paper's fixed mu, without the safeguard (REQ-PLAN-020)");
  fc->add_option("--region", f->bench.region_file, "miner's region file (default: the A*-dilated region)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            // plan's source names are no files here (eighteenth campaign F11: a file named sgan
            // was read and the campaign labelled "sgan"): miner runs on the A*-dilated region
            // without --region, miner-sgan on the network's.
            std::string lower = text;
            for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            if (lower == "astar" || lower == "sgan")
              return text + " names a region source of `miner plan`; bench frontend's --region takes a region file "
                            "(without it miner runs on the A*-dilated region, and the miner-sgan planner on the "
                            "network's): write ./" + text + " for a file of that name";
            return "";
          },
          "FILE"));
  fc->add_option("--weights", f->bench.weights_file, "miner-sgan's weights (default: the shipped fixtures/sgan/sgan.bin)");
  fc->add_option("--dims,--region-dims", f->region_dims, "A*-dilated region grid nx ny nz (as plan --dims)")->expected(3)->check(integer_in(1, 4096));
  fc->add_option("--throughput-iterations", f->bench.throughput_iterations,
                 "iterations of the rrtstar vs ompl:RRTstar throughput check (0: skip)")
      ->capture_default_str()
      ->check(integer_in(0, 100000));  // two RRT* runs of this many iterations: ~1 min at the bound
  fc->add_option("--ompl-log", f->ompl_log, "also write OMPL's benchmark log format to this file")->check(kOutputFile);
  fc->add_option("--shard", f->shard, "i/N: run only runs r with r % N == i (join the parts with `miner bench merge`)")
      ->check(kShard);
  fc->add_flag("--quiet", f->quiet, "no progress bar on stderr");
  add_output_options(fc, f->output);
  fc->callback([f, fc, &out] {
    // Options that only miner or miner-sgan read are refused when --planners leaves them out
    // (issue 20, third campaign: they were ignored without a word).
    const std::vector<std::string>& names = f->bench.planners;
    const auto runs = [&](const std::string& planner) {
      return names.empty() || std::find(names.begin(), names.end(), planner) != names.end();
    };
    const auto given = [&](const char* name) { return fc->get_option(name)->count() > 0; };
    for (const char* name : {"--region", "--dims"})
      if (given(name) && !runs("miner"))
        throw CLI::ValidationError(name, "applies to the miner planner, which --planners leaves out");
    if (given("--region") && given("--dims"))
      throw CLI::ValidationError("--dims", "sets the A*-dilated region's grid, which --region replaces");
    if (given("--weights") && !runs(bench::kMinerSgan))
      throw CLI::ValidationError("--weights", "applies to the miner-sgan planner, which --planners leaves out");
    if (given("--no-safeguard") && !runs("miner") && !runs(bench::kMinerSgan))
      throw CLI::ValidationError("--no-safeguard", "applies to miner and miner-sgan, which --planners leaves out");
    // Ours stop on --max-iterations only (sixteenth campaign F21: a --time-limit that bound no
    // planner was recorded in the campaign as if it had).
    {
      const std::vector<std::string> ran = names.empty() ? bench::default_frontend_planners() : names;
      const bool any_ompl = std::any_of(ran.begin(), ran.end(), [](const std::string& n) { return bench::is_ompl_planner(n); });
      for (const char* name : {"--time-limit", "--ompl-checks"})
        if (given(name) && !any_ompl)
          throw CLI::ValidationError(name, "applies to OMPL's planners, which --planners leaves out (ours stop on --max-iterations)");
      if (given("--time-limit") && given("--ompl-checks"))
        throw CLI::ValidationError("--ompl-checks", "replaces --time-limit (a budget that repeats, not the wall clock): give one");
      // The clock must not bind when the checks do: a day, the longest limit.
      if (given("--ompl-checks")) f->bench.time_limit_s = bench::kMaxTimeLimitS;
    }
    check_region_dims(fc, f->region_dims);
    run_frontend(*f, out);
  });

  struct HeuristicOptions {
    bench::HeuristicBenchOptions bench;
    OutputOptions output;
  };
  auto h = std::make_shared<HeuristicOptions>();
  CLI::App* hc = bench_cmd->add_subcommand(
      "heuristic", "sGAN quality like the paper's heuristic table, and what its region buys MINER over RRT*");
  hc->add_option("--data", h->bench.data, "`miner dataset` folders, one map family each (a summary per family)")
      ->required();
  hc->add_option("--split", h->bench.split, "split to measure (test: map seeds never trained on)")->capture_default_str()
      ->check(CLI::IsMember({"train", "val", "test"}));
  hc->add_option("--samples", h->bench.samples, "first N samples of the split (0: all)")->capture_default_str()
      ->check(integer_in(0, 10000000));
  hc->add_option("--weights", h->bench.weights, "sGAN weights (default: the shipped fixtures/sgan/sgan.bin)");
  hc->add_option("--seed", h->bench.seed, "noise seed (a sample: seed + its own key, whatever --data holds beside it) and planner seed")->capture_default_str()->check(kUnsigned64);
  hc->add_option("--iterations", h->bench.max_iterations, "planner iteration budget per query")
      ->check(kIterationsRange)
      ->capture_default_str();
  hc->add_option("--target-factor", h->bench.target_factor, "target cost = this x the sample's A* cost")
      ->capture_default_str()->check(finite_in(0.01, 100.0));
  hc->add_flag("!--no-planners", h->bench.planners, "quality only: do not run MINER and RRT*");
  hc->add_flag("--strict-bridge", h->bench.strict_bridge,
               "filter step 5 too: the strict bridge on the continuous map (REQ-HEUR-014)");
  add_output_options(hc, h->output);
  hc->callback([h, hc, &out] {
    // With --no-planners no planner runs: their budget and target would be ignored (issue 20).
    if (!h->bench.planners)
      for (const char* name : {"--iterations", "--target-factor"})
        if (hc->get_option(name)->count() > 0)
          throw CLI::ValidationError(name, "sets the planners' runs, which --no-planners turns off");
    const bench::HeuristicBenchResult r = bench::run_heuristic_bench(h->bench, progress_stream());
    emit(h->output, bench::to_json(r), bench::to_text(r), out);
  });

  struct MergeOptions {
    std::vector<std::string> parts;
    OutputOptions output;
  };
  auto mo = std::make_shared<MergeOptions>();
  CLI::App* mc = bench_cmd->add_subcommand("merge", "join the --json outputs of `bench frontend --shard i/N` runs");
  mc->add_option("parts", mo->parts, "the N shard files (any order)")->required();
  add_output_options(mc, mo->output);
  mc->callback([mo, &out] {
    std::vector<Json> parts;
    for (const auto& file : mo->parts) parts.push_back(read_json_file(file));
    const Json merged = bench::merge_frontend_shards(parts, mo->parts);
    std::ostringstream text;
    text << "merged " << parts.size() << " shards of " << merged["map"].get<std::string>() << ": "
         << merged["run_records"].size() << " runs\n";
    for (const auto& s : merged["planners"])
      text << "  " << s["planner"].get<std::string>() << ": success " << 100.0 * s["success_rate"].get<double>()
           << " %, target " << 100.0 * s["target_rate"].get<double>() << " %\n";
    emit(mo->output, merged, text.str(), out);
  });

  struct PaperOptions {
    bench::PaperBenchOptions bench;
    std::string results = "docs/results.md";
    std::string figures;  // empty: figures_folder's default
    bool json = false;
    bool quiet = false;
  };
  auto p = std::make_shared<PaperOptions>();
  CLI::App* pc = bench_cmd->add_subcommand(
      "paper", "the paper's Table I, heuristic quality, Table II and tracking MSE side by side -> docs/results.md");
  pc->add_option("--maps", p->bench.maps, "front-end and back-end maps (with stored queries)")
      ->delimiter(',')->capture_default_str();
  pc->add_option("--planners", p->bench.planners, "front-end planners")->delimiter(',')->capture_default_str();
  pc->add_option("--runs", p->bench.runs, "front-end runs per planner and map")->capture_default_str()
      ->check(kRunsRange);
  pc->add_option("--seed", p->bench.seed, "seed of every campaign")->capture_default_str()->check(kUnsigned64);
  pc->add_option("--time-limit", p->bench.time_limit_s, "wall-clock cap per front-end run of OMPL's planners in s")->capture_default_str()
      ->check(finite_in(bench::kMinTimeLimitS, bench::kMaxTimeLimitS));
  pc->add_option("--iterations", p->bench.max_iterations, "front-end iteration budget")->capture_default_str()
      ->check(kIterationsRange);
  pc->add_option("--weights", p->bench.weights, "sGAN weights (default: the shipped ones)");
  pc->add_option("--heuristic-data", p->bench.heuristic_data, "a `miner dataset` folder (default: generate unseen maps)");
  pc->add_option("--heuristic-samples", p->bench.heuristic_samples,
                 "unseen maps generated for the heuristic table (with --heuristic-data: its first N test "
                 "samples, all of them when not given)")
      ->capture_default_str()->check(integer_in(1, 100000));
  pc->add_option("--heuristic-iterations", p->bench.heuristic_iterations, "MINER vs RRT* budget per heuristic query")
      ->capture_default_str()->check(kIterationsRange);
  pc->add_option("--scenarios", p->bench.scenarios, "tracking scenarios (default: indoor-1 and indoor-2)")->delimiter(',');
  pc->add_option("--tracking-maps", p->bench.tracking_maps, "maps flown with the default scenario besides indoor-1")
      ->delimiter(',')->capture_default_str();
  pc->add_option("--backend-budget", p->bench.backend_budget_s, "seconds per back-end method and order")
      ->capture_default_str()->check(finite_in(1e-4, 3600.0));
  pc->add_option("--jobs", p->bench.jobs, "threads for generating the heuristic test set")->capture_default_str()
      ->check(integer_in(1, 256));
  pc->add_option("--out,--results", p->results, "the Markdown report to write (.md; --results: its former name)")->capture_default_str()
      ->check(kOutputFileNewFolder & suffix_output(".md", "the report is Markdown"));
  pc->add_option("--figures", p->figures, "folder for the box plots (default: beside --out, named after it: docs/results.md -> docs/results)")
      ->check(output_folder_for(kFiguresMarker, {".svg", ".json"}));
  pc->add_flag("--json", p->json, "print every figure as JSON");
  pc->add_flag("--quiet", p->quiet, "no progress on stderr");
  pc->callback([p, pc, &out] {
    // Tracking maps are flown with the default scenario; --scenarios replaces it (issue 20,
    // fourth campaign: a missing --tracking-maps file beside --scenarios went unread).
    if (pc->get_option("--tracking-maps")->count() > 0 && pc->get_option("--scenarios")->count() > 0)
      throw CLI::ValidationError("--tracking-maps", "maps flown with the default scenario, which --scenarios replaces");
    p->bench.heuristic_samples_given = pc->get_option("--heuristic-samples")->count() > 0;
    const std::string command = command_line(pc, {"--runs", "--seed", "--time-limit", "--heuristic-samples"});
    namespace fs = std::filesystem;
    const fs::path results(p->results);
    const fs::path figures = figures_folder(results, p->figures);  // the default one checked too (seventh campaign C6)
    const auto r = bench::run_paper_bench(p->bench, command, p->quiet ? nullptr : terminal_stream());
    const std::string link = fs::relative(fs::absolute(figures), fs::absolute(results).parent_path()).generic_string();
    const auto plots = bench::results_figures(r);
    write_figures(figures, plots, command);
    if (!results.parent_path().empty()) fs::create_directories(results.parent_path());
    write_file_atomic(results.string(), bench::results_markdown(r, link));
    if (p->json) out << dump_json(bench::to_json(r));
    else out << "wrote " << results.string() << " and " << plots.size() << " box plots in " << figures.string() << "\n";
  });

  struct SuiteOptions {
    bench::SuiteBenchOptions bench;
    std::string suite = "fixtures/bench/suite.json";
    std::string results = "docs/suite.md";
    std::string figures;  // empty: figures_folder's default
    bool json = false;
    bool quiet = false;
  };
  auto su = std::make_shared<SuiteOptions>();
  CLI::App* sc = bench_cmd->add_subcommand(
      "suite", "Table I over a suite of map families at the paper's difficulty, steering step swept -> docs/suite.md");
  sc->add_option("--suite", su->suite, "suite file (miner-bench-suite-v1: maps, steps, band)")->capture_default_str();
  sc->add_option("--planners", su->bench.planners, "planners")->delimiter(',')->capture_default_str();
  sc->add_option("--runs", su->bench.runs, "runs per planner, map and steering step")->capture_default_str()
      ->check(kRunsRange);
  sc->add_option("--seed", su->bench.seed, "seed of every campaign")->capture_default_str()->check(kUnsigned64);
  sc->add_option("--time-limit", su->bench.time_limit_s, "wall-clock cap per run of OMPL's planners in s")->capture_default_str()
      ->check(finite_in(bench::kMinTimeLimitS, bench::kMaxTimeLimitS));
  sc->add_option("--iterations", su->bench.max_iterations, "iteration budget per run")->capture_default_str()
      ->check(kIterationsRange);
  sc->add_option("--weights", su->bench.weights, "sGAN weights (default: the shipped ones)");
  sc->add_option("--out,--results", su->results, "the Markdown report to write (.md; --results: its former name)")->capture_default_str()
      ->check(kOutputFileNewFolder & suffix_output(".md", "the report is Markdown"));
  sc->add_option("--figures", su->figures, "folder for the box plots (default: beside --out, named after it: docs/suite.md -> docs/suite)")
      ->check(output_folder_for(kFiguresMarker, {".svg", ".json"}));
  sc->add_flag("--json", su->json, "print every figure as JSON");
  sc->add_flag("--quiet", su->quiet, "no progress on stderr");
  sc->callback([su, sc, &out] {
    namespace fs = std::filesystem;
    const std::vector<std::string>& planners = su->bench.planners;
    if (sc->get_option("--weights")->count() > 0 &&
        std::find(planners.begin(), planners.end(), bench::kMinerSgan) == planners.end())
      throw CLI::ValidationError("--weights", "applies to the miner-sgan planner, which --planners leaves out");
    su->bench.suite = bench::load_suite(su->suite);
    su->bench.suite_file = su->suite;
    const fs::path results(su->results);
    const std::string command = command_line(sc, {"--suite", "--runs", "--seed", "--time-limit", "--iterations"});
    const fs::path figures = figures_folder(results, su->figures);  // the default one checked too (seventh campaign C6)
    const auto r = bench::run_suite_bench(su->bench, command, su->quiet ? nullptr : terminal_stream());
    const std::string link = fs::relative(fs::absolute(figures), fs::absolute(results).parent_path()).generic_string();
    const auto plots = bench::suite_figures(r);
    write_figures(figures, plots, command);
    if (!results.parent_path().empty()) fs::create_directories(results.parent_path());
    write_file_atomic(results.string(), bench::suite_markdown(r, link));
    if (su->json) out << dump_json(bench::to_json(r));
    else out << "wrote " << results.string() << " and " << plots.size() << " box plots in " << figures.string() << "\n";
  });

  struct VoxelOptions {
    std::string map;
    bench::VoxelBenchOptions bench;
    OutputOptions output;
  };
  auto vo = std::make_shared<VoxelOptions>();
  CLI::App* vc = bench_cmd->add_subcommand(
      "voxels", "voxel map costs: load time, memory, point/segment/ray queries per second, A* grid and sGAN encoding");
  vc->add_option("--map", vo->map, "map file (.bt, .ot or .json)")->required();
  vc->add_option("--radius", vo->bench.robot_radius, "robot radius in m")->capture_default_str()->check(finite_in(0.0, world::kMaxRobotRadius));
  // Bounds on the work a benchmark is asked for: 10^6 queries of each kind and 100 repeats take
  // a few seconds on a small scan (issue 20, seventh campaign U2: 1000 repeats took 27 s).
  vc->add_option("--queries", vo->bench.queries, "random queries of each kind (at most 10^6)")->capture_default_str()
      ->check(integer_in(1, 1000000));
  vc->add_option("--segment-length", vo->bench.segment_length, "segment query length in m")->capture_default_str()
      ->check(finite_in(1e-3, 1e4));
  vc->add_option("--repeats", vo->bench.repeats, "timed loads, grid builds and encodings (median; at most 100)")
      ->capture_default_str()
      ->check(integer_in(1, 100));
  vc->add_option("--seed", vo->bench.seed, "seed of the random queries")->capture_default_str()->check(kUnsigned64);
  add_output_options(vc, vo->output);
  vc->callback([vo, &out] {
    const Json doc = bench::run_voxel_bench(vo->map, vo->bench);
    std::ostringstream human;
    bench::print_voxel_bench(doc, human);
    emit(vo->output, doc, human.str(), out);
  });
}

}  // namespace miner::cli
