// `miner plan` and `miner region astar` (REQ-PLAN-*, REQ-CLI-004).
#include <cctype>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "cli/cli.hpp"
#include "miner/core/error.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"

namespace miner::cli {

namespace {

struct RegionGridOptions {
  std::vector<int> dims = std::vector<int>(3, plan::HeuristicRegion::kGridSide);
  int dilation = 1;
};

void add_region_grid_options(CLI::App* cmd, RegionGridOptions& r) {
  cmd->add_option("--dims", r.dims, "heuristic grid size nx ny nz (the sGAN's grid)")
      ->expected(3)
      ->check(integer_in(1, 4096))
      ->capture_default_str();
  cmd->add_option("--dilation", r.dilation, "cells added around each path cell (1: 3x3x3 cubes)")
      ->check(integer_in(0, plan::HeuristicRegion::kMaxDilation))
      ->capture_default_str();
}

struct PlanCliOptions {
  QueryOptions query;
  std::string planner = "miner";
  std::string region = "sgan";
  std::string weights;
  bool strict_bridge = false;
  RegionGridOptions grid;
  plan::PlannerOptions planner_options;
  double target_factor = 0.0;
  double target_cost = 0.0;
  bool tree = false;
  bool timing = false;
  OutputOptions output;
};

Json stage_json(const std::optional<plan::StageRecord>& s, bool timing) {
  if (!s) return nullptr;
  Json j = {{"iteration", s->iteration}, {"nodes", s->nodes}, {"cost", s->cost}};
  if (timing) j["time_ms"] = s->time_ms;
  return j;
}

void run_plan(PlanCliOptions o, std::ostream& out) {
  const ResolvedQuery q = resolve_query(o.query);
  const plan::PlanningProblem problem = plan::PlanningProblem::make(q.map, q.start, q.goal, q.radius);
  o.planner_options.planner = plan::planner_from_name(o.planner);

  std::optional<plan::ReferencePath> reference;
  const auto need_reference = [&] {
    if (!reference) reference = plan::astar_reference(problem);
    return *reference;
  };
  if (o.target_cost > 0.0) o.planner_options.target_cost = o.target_cost;
  if (o.target_factor > 0.0) o.planner_options.target_cost = o.target_factor * need_reference().cost;

  std::optional<plan::HeuristicRegion> region;
  std::optional<heuristic::HeuristicQuery> sgan_query;
  if (o.planner_options.planner == plan::PlannerKind::kMiner) {
    if (o.region == "sgan") {
      const heuristic::Sgan sgan = heuristic::Sgan::load_or_builtin(o.weights);
      sgan_query = heuristic::query_region(sgan, q.map, q.start, q.goal, q.radius, o.planner_options.seed, true,
                                           o.strict_bridge);
      region = sgan_query->region;
    } else if (o.region == "astar") {
      const Eigen::Vector3i dims(o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]);
      region = plan::astar_dilated_region(problem, need_reference(), dims, o.grid.dilation);
    } else {
      region = plan::HeuristicRegion::load(o.region);
      region->require_matches(q.map, o.region);  // names the file (issue 20, N14)
    }
  }
  const plan::PlanResult r = plan::plan(problem, o.planner_options, region ? &*region : nullptr);

  Json path = Json::array();
  for (const auto& p : r.path) path.push_back(vec3_json(p));
  Json doc = {{"planner", o.planner},
              {"map", o.query.map},
              {"start", vec3_json(q.start)},
              {"goal", vec3_json(q.goal)},
              {"robot_radius", q.radius},
              {"seed", o.planner_options.seed},
              {"max_iterations", o.planner_options.max_iterations},
              {"steer_step", r.steer_step},
              {"goal_radius", r.goal_radius},
              {"target_cost", o.planner_options.target_cost ? Json(*o.planner_options.target_cost) : Json(nullptr)},
              {"solved", r.solved},
              {"reason", r.reason},
              {"cost", r.solved ? Json(r.cost) : Json(nullptr)},
              {"iterations", r.iterations},
              {"nodes", r.nodes},
              {"first", stage_json(r.first, o.timing)},
              {"target", stage_json(r.target, o.timing)},
              {"path", path}};
  if (region) {
    const bool named = o.region == "sgan" || o.region == "astar";
    doc["region"] = {{"source", named ? region->source() : o.region},
                     {"cells", region->cells().size()},
                     {"volume", region->volume()},
                     {"safeguard", o.planner_options.safeguard},
                     {"samples", r.region_samples},
                     {"trust", r.region_trust}};
    if (sgan_query) {
      doc["region"]["connected"] = sgan_query->report.connected;
      doc["region"]["bridge_cells"] = sgan_query->report.bridge_cells;
      if (o.strict_bridge) {
        doc["region"]["strict_cells"] = sgan_query->report.strict_cells;
        doc["region"]["strict_connected"] = sgan_query->report.strict_connected;
      }
      if (o.timing) doc["region"]["time_ms"] = sgan_query->encode_ms + sgan_query->inference_ms + sgan_query->filter_ms;
    }
  }
  if (o.timing) doc["time_ms"] = r.time_ms;
  if (o.tree) {
    Json vertices = Json::array();
    for (const auto& v : r.tree_vertices) vertices.push_back(vec3_json(v));
    doc["tree"] = {{"vertices", vertices}, {"parents", r.tree_parents}};
  }

  std::ostringstream h;
  h << o.planner << " on " << o.query.map << ": " << format_point(q.start) << " -> " << format_point(q.goal)
    << " (seed " << o.planner_options.seed << ")\n";
  if (region) {
    h << "heuristic region: "
      << (o.region == "astar" ? "astar-dilated (A* oracle)" : o.region == "sgan" ? "sGAN, filtered" : o.region) << ", "
      << region->cells().size() << " cells";
    if (sgan_query)
      h << " (" << std::fixed << std::setprecision(1)
        << sgan_query->encode_ms + sgan_query->inference_ms + sgan_query->filter_ms << " ms"
        << (sgan_query->report.bridge_cells ? ", bridged" : "") << ")";
    h << "\n";
  }
  if (r.first) {
    h << "first solution: iteration " << r.first->iteration << ", " << r.first->nodes << " nodes, cost "
      << std::fixed << std::setprecision(3) << r.first->cost << " m\n" << std::defaultfloat;
  }
  if (o.planner_options.target_cost) {
    h << "target cost " << std::fixed << std::setprecision(3) << *o.planner_options.target_cost << " m: "
      << std::defaultfloat;
    if (r.target) h << "reached at iteration " << r.target->iteration << " (" << r.target->nodes << " nodes)\n";
    else h << "not reached\n";
  }
  if (r.solved) {
    h << "path: " << r.path.size() << " points, cost " << std::fixed << std::setprecision(3) << r.cost
      << " m after " << std::defaultfloat << r.iterations << " iterations, " << r.nodes << " nodes\n";
  }
  emit(o.output, doc, h.str(), out);
  if (!r.solved) throw NoSolution(r.reason);
}

struct RegionCliOptions {
  QueryOptions query;
  RegionGridOptions grid;
  std::string out;
  bool json = false;
};

void run_region_astar(const RegionCliOptions& o, std::ostream& out) {
  const ResolvedQuery q = resolve_query(o.query);
  const plan::PlanningProblem problem = plan::PlanningProblem::make(q.map, q.start, q.goal, q.radius);
  const plan::ReferencePath reference = plan::astar_reference(problem);
  const Eigen::Vector3i dims(o.grid.dims[0], o.grid.dims[1], o.grid.dims[2]);
  const auto region = plan::astar_dilated_region(problem, reference, dims, o.grid.dilation);
  region.save(o.out);
  std::ostringstream human;
  human << "wrote " << o.out << ": " << region.cells().size() << " of " << dims.prod()
        << " cells around the A* path (cost " << std::fixed << std::setprecision(3) << reference.cost << " m)\n";
  report(o.json, {{"out", o.out}, {"cells", region.cells().size()}, {"dims", {dims.x(), dims.y(), dims.z()}},
                  {"astar_cost", reference.cost}},
         human.str(), out);
}

}  // namespace

void add_plan_commands(CLI::App& app, std::ostream& out) {
  auto po = std::make_shared<PlanCliOptions>();
  CLI::App* p = app.add_subcommand("plan", "find a path with an RRT* planner (rrtstar, informed, guided, miner)");
  add_query_options(p, po->query);
  p->add_option("--planner", po->planner, "rrtstar | informed | guided | miner")
      ->check(CLI::IsMember({"rrtstar", "informed", "guided", "miner"}))
      ->capture_default_str();
  p->add_option("--seed", po->planner_options.seed, "random seed")->capture_default_str()->check(kUnsigned64);
  p->add_option("--region", po->region,
                "miner's region: sgan (the network, filtered), astar (the A*-dilated oracle) or a "
                "miner-region-v1 file")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            // "ASTAR" or "Sgan" is a source in the wrong case, not a file that cannot be opened
            // (fifth campaign). A file of that name, if there is one, is still read.
            std::string lower = text;
            for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
            std::error_code ec;
            if (lower != text && (lower == "astar" || lower == "sgan") && !std::filesystem::exists(text, ec))
              return text + " is neither a region file nor a source: the sources are written in lower case (" +
                     lower + ")";
            // The keyword beside a file of its name is ambiguous (seventeenth campaign F25: a region
            // file named astar was ignored for the oracle without a word).
            if ((text == "astar" || text == "sgan") && std::filesystem::exists(text, ec))
              return text + " names the " + text + " source, and a file " + text +
                     " is here too: write ./" + text + " for the file, or run from another folder for the source";
            return "";
          },
          "sgan|astar|FILE"));
  p->add_option("--weights", po->weights, "sGAN weights file (default: the shipped fixtures/sgan/sgan.bin)");
  p->add_flag("--strict-bridge", po->strict_bridge,
              "miner, --region sgan: filter step 5, a collision-free way from start to goal inside the region "
              "(REQ-HEUR-014)");
  add_region_grid_options(p, po->grid);
  p->add_option("--iterations", po->planner_options.max_iterations, "iteration budget (Alg. 1's N)")
      ->check(kIterationsRange)
      ->capture_default_str();
  p->add_flag("--first", po->planner_options.stop_at_first, "stop at the first solution (Alg. 1 Line 24)");
  CLI::Option* target_cost = p->add_option("--target-cost", po->target_cost, "stop once the path cost is <= this (m)")
      ->check(finite_in(1e-9, 1e9));
  p->add_option("--target-factor", po->target_factor,
                "stop once the cost is <= this x the A* reference cost (e.g. 1.05)")
      ->check(finite_in(0.01, 100.0))
      ->excludes(target_cost);
  p->add_option("--step", po->planner_options.steer_step, "steering step eta in m (default: 0.1 x map diagonal)")
      ->check(finite_in(1e-6, 1e6));
  p->add_option("--goal-radius", po->planner_options.goal_radius, "goal region radius in m (default: 2 x resolution)")
      ->check(finite_in(1e-6, 1e6));
  p->add_option("--goal-bias", po->planner_options.goal_bias, "probability of sampling the goal")
      ->check(finite_in(0.0, 0.999999))
      ->capture_default_str();
  p->add_option("--mu1", po->planner_options.mu_1, "miner: P(sample region) after the first solution, < 1")
      ->check(finite_in(0.0, 0.999999))
      ->capture_default_str();
  p->add_option("--mu2", po->planner_options.mu_2, "miner: P(sample region) before the first solution, < 1")
      ->check(finite_in(0.0, 0.999999))
      ->capture_default_str();
  p->add_flag("!--no-safeguard", po->planner_options.safeguard,
              "miner: the paper's fixed mu_1/mu_2, without the online trust of REQ-PLAN-020");
  p->add_option("--safeguard-iterations", po->planner_options.safeguard_iterations,
                "miner safeguard: k_0, iterations without a solution after which mu decays as k_0 / t")
      ->check(integer_in(1, kMaxIterations))
      ->capture_default_str();
  p->add_option("--rewire-factor", po->planner_options.rewire_factor, "rewiring radius factor (>= 1)")
      ->check(finite_in(1.0, 100.0))
      ->capture_default_str();
  p->add_flag("--tree", po->tree, "include the final tree (vertices, parents) in the JSON");
  p->add_flag("--timing", po->timing, "include wall-clock times (makes the output non-deterministic)");
  add_output_options(p, po->output);
  p->callback([po, p, &out] {
    // The region, its grid and the safeguard belong to miner: given to another planner they
    // would be ignored without a word (issue 20).
    if (po->planner != "miner")
      for (const char* name : {"--region", "--weights", "--strict-bridge", "--dims", "--dilation", "--mu1", "--mu2",
                               "--no-safeguard", "--safeguard-iterations"})
        if (p->get_option(name)->count() > 0)
          throw CLI::ValidationError(name, std::string("applies to --planner miner only, not ") + po->planner);
    if (po->strict_bridge && po->region != "sgan")
      throw CLI::ValidationError("--strict-bridge", "is a step of the sGAN region's filter, not of --region " + po->region);
    // Each region source reads only its own options (issue 20, third campaign: `--dims` with the
    // sGAN, whose grid is its weights', and `--weights` with the A* region were ignored).
    const auto given = [&](const char* name) { return p->get_option(name)->count() > 0; };
    if (po->region != "astar")
      for (const char* name : {"--dims", "--dilation"})
        if (given(name))
          throw CLI::ValidationError(name, "applies to --region astar only (the sGAN's grid is its weights'; a region "
                                           "file has its own), not --region " + po->region);
    if (po->region != "sgan" && given("--weights"))
      throw CLI::ValidationError("--weights", "applies to --region sgan only, not --region " + po->region);
    if (!po->planner_options.safeguard && given("--safeguard-iterations"))
      throw CLI::ValidationError("--safeguard-iterations", "tunes the safeguard, which --no-safeguard turns off");
    // --tree and --timing add to the JSON result; the text summary has neither (issue 20,
    // fourth campaign: both were accepted and ignored without --json or --out).
    for (const char* name : {"--tree", "--timing"})
      if (given(name) && !po->output.json && po->output.out.empty())
        throw CLI::ValidationError(name, "adds to the JSON result, which only --json or --out produce");
    check_region_dims(p, po->grid.dims);
    po->planner_options.record_tree = po->tree;
    run_plan(*po, out);
  });

  CLI::App* region = app.add_subcommand("region", "heuristic regions for the miner planner");
  region->require_subcommand(1);
  auto ro = std::make_shared<RegionCliOptions>();
  CLI::App* ra = region->add_subcommand("astar", "the A*-dilated ground-truth region (paper Sec. V-A.1)");
  add_query_options(ra, ro->query);
  add_region_grid_options(ra, ro->grid);
  ra->add_option("--out", ro->out, "output region file (miner-region-v1 JSON, .json)")->required()
      ->check(kOutputFile & suffix_output(".json", "a region is JSON"));
  ra->add_flag("--json", ro->json, "print the summary as JSON");
  ra->callback([ro, ra, &out] {
    check_region_dims(ra, ro->grid.dims);
    run_region_astar(*ro, out);
  });
}

}  // namespace miner::cli
