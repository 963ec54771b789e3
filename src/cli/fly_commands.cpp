// `miner fly` (REQ-FLIGHT-009) and `miner bench sim` (REQ-FLIGHT-010).
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "bench/sim_bench.hpp"
#include "cli/cli.hpp"
#include "miner/core/error.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/core/text.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/run_folder.hpp"
#include "miner/report/flight_report.hpp"

namespace miner::cli {

namespace {

struct ScenarioOptions {
  std::string scenario;  ///< empty: the embedded default
  /// --seed, when given: any of 0..2^64-1 (issue 20, eighth campaign W1: a signed holder
  /// clamped every seed from 2^63 on to 2^63 - 1).
  std::uint64_t seed = 0;
  CLI::Option* seed_option = nullptr;
  bool seed_given() const { return seed_option != nullptr && seed_option->count() > 0; }
};

void add_scenario_options(CLI::App* cmd, ScenarioOptions& o) {
  cmd->add_option("--scenario", o.scenario, "miner-scenario-v1 file (default: the embedded indoor-1 scenario)");
  o.seed_option = cmd->add_option("--seed", o.seed, "override the scenario's seed")->check(kUnsigned64);
}

/// The scenario document as read once: --scenario's file, or the embedded default.
struct ScenarioDocument {
  Json doc;
  std::string origin, base_dir;
};

/// --seed overrides the document's own seed, so that what the run folder keeps of the scenario
/// flies the same flight again (eighth campaign W2: scenario.json kept the file's seed).
ScenarioDocument read_scenario_document(const ScenarioOptions& o) {
  ScenarioDocument d = o.scenario.empty()
                           ? ScenarioDocument{pipeline::default_scenario_document(), "<default scenario>", ""}
                           : ScenarioDocument{read_json_file(o.scenario), o.scenario,
                                              std::filesystem::path(o.scenario).parent_path().string()};
  if (o.seed_given() && d.doc.is_object()) d.doc["seed"] = o.seed;
  return d;
}

pipeline::Scenario resolve_scenario(const ScenarioDocument& d) {
  return pipeline::scenario_from_json(d.doc, d.origin, d.base_dir);
}

/// The extensions of a run folder's files (the names rule's part for folders without a marker).
const std::vector<std::string> kRunFolderExtensions = {".json", ".csv", ".html"};

struct FlyCliOptions {
  ScenarioOptions scenario;
  std::string out;
  bool ground_truth = false;
  bool json = false;
  bool timing = false;
};

void run_fly(const FlyCliOptions& o, std::ostream& out) {
  ScenarioDocument document = read_scenario_document(o.scenario);
  if (o.ground_truth && document.doc.is_object()) document.doc["controller_reads"] = "ground-truth";
  const pipeline::Scenario s = resolve_scenario(document);
  // The run folder replaces its contents whole: it must hold none of the scenario's inputs,
  // checked before any work (REQ-CLI-003).
  const std::string run_dir = o.out.empty() ? pipeline::default_run_folder(s) : o.out;
  // The default folder gets --out's own check, before the flight (eighteenth campaign F16: it
  // was refused only after the whole flight, exit 1).
  if (o.out.empty()) {
    std::string folder = run_dir;
    if (const std::string problem = output_folder_for(pipeline::run_folder_marker(), kRunFolderExtensions)(folder);
        !problem.empty())
      throw CLI::ValidationError("--out", "the default run folder " + problem);
  }
  if (!o.scenario.scenario.empty())
    if (const auto input = pipeline::run_folder_conflict(run_dir, document.doc, document.base_dir))
      throw CLI::ValidationError("--out", run_dir + " holds " + *input + ", which the scenario reads: the run folder would replace it");
  const pipeline::ReferencePlan reference = pipeline::build_reference(s);
  // pipeline::fly flies on the truth when the scenario says so (--ground-truth, above).
  const auto t0 = std::chrono::steady_clock::now();
  const flight::FlightResult r = pipeline::fly(s, reference);
  auto stage_ms = reference.stage_ms;
  stage_ms.emplace_back("flight", elapsed_ms(t0));
  // The run folder holds wall-clock times only when asked: same scenario and seed, same bytes
  // (issue 20, ninth campaign C2: summary.json and report.html differed in stage_ms).
  const std::vector<std::pair<std::string, double>> recorded = o.timing ? stage_ms : decltype(stage_ms){};

  pipeline::RunFolder folder(run_dir,
                             o.scenario.scenario.empty() ? document.doc
                                                         : pipeline::self_contained_scenario(document.doc, document.base_dir),
                             s, reference, r, recorded);
  folder.add_page("report.html", report::render_flight_report({s, reference, r, recorded}), "report");
  folder.write();
  const Json& summary = folder.summary();
  const std::string& dir = folder.dir();
  const std::vector<std::string> names = folder.names();

  if (o.json) {
    out << dump_json(summary);
  } else {
    out << "flew " << s.name << " (seed " << s.seed << ", controller on the "
        << (s.controller_reads_truth ? "GROUND TRUTH (diagnostic)" : "EKF estimate") << "): reference from "
        << reference.source;
    if (reference.region) out << " (MINER RRT* on the " << reference.region->source() << " region)";
    out << ", " << reference.trajectory.segments() << " segments, " << std::fixed << std::setprecision(2)
        << reference.trajectory.total_duration() << " s\n"
        << flight::tracking_table(s.name, r) << std::setprecision(3) << "max position error " << r.max_position_error
        << " m, estimate RMSE " << r.estimation_rmse << " m, collisions " << r.collisions << ", goal "
        << (r.goal_reached ? "reached" : "NOT reached") << " (" << r.final_position_error << " m off)\n"
        << "stages (ms):";
    for (const auto& [name, ms] : stage_ms) out << " " << name << " " << std::setprecision(1) << ms;
    out << "\nwrote " << dir << "/ (";
    for (std::size_t i = 0; i < names.size(); ++i) out << (i ? ", " : "") << names[i];
    out << ")\nreport: " << dir << "/report.html\n";
  }
  // What ended the flight first: an empty battery stops the rotors (eighth campaign W3).
  const std::string depleted =
      r.battery_depleted_s ? "; the battery was depleted at t = " + short_number(*r.battery_depleted_s) + " s (" +
                                 short_number(s.battery.capacity_wh * s.battery.initial_charge) +
                                 " Wh stored: battery.capacity_wh x battery.initial_charge)"
                           : "";
  if (r.left_world)
    throw NoSolution("the vehicle left the map at t = " + short_number(r.left_world_time_s) + " s at " +
                     format_point(r.left_world_position) + " (bounds " + format_point(s.map->bounds().min) + " to " +
                     format_point(s.map->bounds().max) + "): the flight stopped there, collisions " +
                     std::to_string(r.collisions) + depleted);
  if (!r.goal_reached)
    throw NoSolution("the flight did not reach the goal (final error " + std::to_string(r.final_position_error) +
                     " m, speed " + std::to_string(r.final_speed) + " m/s, collisions " +
                     std::to_string(r.collisions) + ")" + depleted);
}

struct SimBenchCliOptions {
  ScenarioOptions scenario;
  bench::SimBenchOptions bench;
  OutputOptions output;
};

}  // namespace

void add_fly_commands(CLI::App& app, std::ostream& out) {
  auto o = std::make_shared<FlyCliOptions>();
  CLI::App* fly = app.add_subcommand("fly", "fly a scenario in closed loop: reference -> SE(3) PID -> N3 -> CVODE -> EKF");
  add_scenario_options(fly, o->scenario);
  fly->add_option("--out", o->out, "run folder (default runs/<scenario>-seed<seed>)")->check(output_folder_for(pipeline::run_folder_marker(), kRunFolderExtensions));
  fly->add_flag("--ground-truth", o->ground_truth, "diagnostic: the controller reads the true state, not the EKF");
  fly->add_flag("--json", o->json, "print the summary as JSON");
  fly->add_flag("--timing", o->timing,
                "record the stages' wall-clock times in summary.json and report.html (makes the run folder "
                "non-deterministic; they are printed either way)");
  fly->callback([o, &out] { run_fly(*o, out); });

  CLI::App* bench_cmd = app.get_subcommand("bench");
  auto b = std::make_shared<SimBenchCliOptions>();
  CLI::App* sim = bench_cmd->add_subcommand("sim", "real-time factor of the full flight loop on one core");
  add_scenario_options(sim, b->scenario);
  sim->add_option("--runs", b->bench.runs, "flights to time")->capture_default_str()->check(integer_in(1, 100));
  // CVODE refuses (and leaks) below ~1e-15; above 1e-2 the flight is not integrated at all.
  sim->add_option("--rtol", b->bench.relative_tolerance, "CVODE relative tolerance")->capture_default_str()
      ->check(finite_in(1e-12, 1e-2));
  add_output_options(sim, b->output);
  sim->callback([b, &out] {
    const auto r = bench::run_sim_bench(resolve_scenario(read_scenario_document(b->scenario)), b->bench);
    std::ostringstream table;
    bench::print_table(r, table);
    emit(b->output, bench::to_json(r), table.str(), out);
  });
}

}  // namespace miner::cli
