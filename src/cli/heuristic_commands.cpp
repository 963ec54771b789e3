// `miner dataset` (REQ-HEUR-001..003) and `miner heuristic` (REQ-HEUR-008).
#include <algorithm>
#include <iomanip>
#include <memory>
#include <tuple>
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "cli/cli.hpp"
#include "miner/core/shard.hpp"
#include "miner/core/error.hpp"
#include "miner/core/progress.hpp"
#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/rrt_star.hpp"

namespace miner::cli {

namespace {
struct DatasetCliOptions {
  heuristic::DatasetOptions dataset;
  std::vector<int> dims = std::vector<int>(3, plan::HeuristicRegion::kGridSide);
  std::string out;
  std::string shard;
  std::vector<std::string> merge;
  bool json = false;
};

struct HeuristicCliOptions {
  QueryOptions query;
  std::string weights;
  std::uint64_t seed = 1;
  bool raw = false;
  bool strict_bridge = false;
  std::string region_out;
  OutputOptions output;
};

Json report_json(const heuristic::FilterReport& r) {
  return {{"threshold", r.threshold},         // step 1's, by the weights' rule (REQ-HEUR-016)
          {"raw_cells", r.raw_cells},         {"raw_connected", r.raw_connected}, {"raw_safe", r.raw_safe},
          {"solid_dropped", r.solid_dropped}, {"island_dropped", r.island_dropped}, {"bridge_cells", r.bridge_cells},
          {"cells", r.cells},                 {"connected", r.connected},           {"safe", r.safe}};
}

/// Step 5's part of the report (REQ-HEUR-014), when it ran.
Json strict_json(const heuristic::HeuristicQuery& h) {
  const heuristic::FilterReport& r = h.report;
  Json witness = Json::array();
  for (const Eigen::Vector3d& p : h.strict_witness) witness.push_back({p.x(), p.y(), p.z()});
  return {{"searched", r.strict_searched}, {"connected", r.strict_connected}, {"cells", r.strict_cells},
          {"expansions", r.strict_expansions}, {"budget_exhausted", r.strict_budget_exhausted}, {"witness", witness}};
}

void run_heuristic(const HeuristicCliOptions& o, std::ostream& out) {
  if (o.raw && o.strict_bridge)
    throw Error("--strict-bridge: is a filter step, --raw writes the unfiltered output", ExitCode::kUsage);
  const ResolvedQuery q = resolve_query(o.query);
  plan::PlanningProblem::make(q.map, q.start, q.goal, q.radius);  // start/goal checks, named errors
  const heuristic::Sgan sgan = heuristic::Sgan::load_or_builtin(o.weights);
  const heuristic::HeuristicQuery h =
      heuristic::query_region(sgan, q.map, q.start, q.goal, q.radius, o.seed, !o.raw, o.strict_bridge);
  h.region.save(o.region_out);
  Json doc = {{"region", o.region_out},
              {"source", h.region.source()},
              {"weights", sgan.path()},
              {"seed", o.seed},
              {"dims", {h.region.dims().x(), h.region.dims().y(), h.region.dims().z()}},
              {"filter", report_json(h.report)},
              {"encode_ms", h.encode_ms},
              {"inference_ms", h.inference_ms},
              {"filter_ms", h.filter_ms}};
  if (o.strict_bridge) doc["strict_bridge"] = strict_json(h);
  std::ostringstream s;
  const auto& r = h.report;
  s << "wrote " << o.region_out << " (" << h.region.source() << "): " << h.region.cells().size() << " of "
    << h.region.dims().prod() << " cells\n"
    << "raw output: " << r.raw_cells << " cells, " << (r.raw_connected ? "connected" : "not connected") << ", "
    << (r.raw_safe ? "safe" : "unsafe") << "\n"
    << "filter: -" << r.solid_dropped << " solid, -" << r.island_dropped << " island, +" << r.bridge_cells
    << " bridge -> " << r.cells << " cells, " << (r.connected ? "connected" : "not connected") << ", "
    << (r.safe ? "safe" : "unsafe") << "\n";
  if (o.strict_bridge)
    s << "strict bridge: +" << r.strict_cells << " cells, "
      << (r.strict_connected ? "a collision-free way inside H (" + std::to_string(h.strict_witness.size()) + " vertices)"
                             : std::string(r.strict_budget_exhausted ? "no way found within the work bound"
                                                                     : "no way found near H"))
      << ", " << r.strict_expansions << " nodes\n";
  s << std::fixed << std::setprecision(2) << "time: encode " << h.encode_ms << " ms, inference " << h.inference_ms
    << " ms, filter " << h.filter_ms << " ms\n";
  emit(o.output, doc, s.str(), out);
}

}  // namespace

void add_heuristic_commands(CLI::App& app, std::ostream& out) {
  auto o = std::make_shared<DatasetCliOptions>();
  CLI::App* d = app.add_subcommand("dataset", "sGAN training data: random maps and queries, A* ground truth, E/S/T grids");
  d->add_option("--count", o->dataset.count, "train + validation samples")->capture_default_str()
      ->check(integer_in(1, 10000000));
  d->add_option("--test-count", o->dataset.test_count, "test samples from unseen map seeds")->capture_default_str()
      ->check(integer_in(0, 10000000));
  d->add_option("--val-fraction", o->dataset.val_fraction, "share of --count kept for validation")->capture_default_str()
      ->check(finite_in(0.0, 0.99));
  d->add_option("--seed", o->dataset.seed, "master seed")->capture_default_str()->check(kUnsigned64);
  d->add_option("--preset", o->dataset.preset, "map preset (sim, indoor, cluttered, rooms, forest, multilevel, mixed, scan)")->capture_default_str()->check(kMapPreset);
  d->add_option("--dims", o->dims, "heuristic grid nx ny nz")->expected(3)->capture_default_str()->check(integer_in(4, 256));
  d->add_option("--dilation", o->dataset.dilation, "cells around start, goal and path cells (1: 3x3x3)")->capture_default_str()
      ->check(integer_in(0, plan::HeuristicRegion::kMaxDilation));
  d->add_option("--shard-size", o->dataset.shard_size, "samples per shard file")->capture_default_str()
      ->check(integer_in(1, 1000000));
  d->add_option("--jobs", o->dataset.jobs, "worker threads (the output does not depend on it)")->capture_default_str()
      ->check(integer_in(1, 256));
  d->add_option("--shard", o->shard, "i/N: write only part i of N (shard files j with j % N == i); join with --merge")
      ->check(kShard);
  d->add_option("--merge", o->merge, "join these part folders (made with --shard) into --out instead of generating");
  d->add_option("--out", o->out, "output folder (written as a whole)")->required()->check(output_folder_for(heuristic::dataset_folder_marker(), {".json", ".bin"}));
  d->add_flag("--json", o->json, "print the summary as JSON");
  d->callback([o, d, &out] {
    if (!o->merge.empty()) {
      // The parts carry their own options: generation options beside --merge would be ignored.
      for (const char* name : {"--count", "--test-count", "--val-fraction", "--seed", "--preset", "--dims", "--dilation",
                               "--shard-size", "--jobs", "--shard"})
        if (d->get_option(name)->count() > 0)
          throw CLI::ValidationError(name, "does not apply to --merge (the parts carry their own options)");
      const Json doc = heuristic::merge_dataset_parts(o->merge, o->out);
      if (o->json) {
        out << dump_json({{"out", o->out}, {"merged_parts", o->merge.size()}, {"train", doc["splits"]["train"]["count"]},
                          {"val", doc["splits"]["val"]["count"]}, {"test", doc["splits"]["test"]["count"]}});
        return;
      }
      out << "merged " << o->merge.size() << " parts into " << o->out << ": " << doc["splits"]["train"]["count"]
          << " train, " << doc["splits"]["val"]["count"] << " val, " << doc["splits"]["test"]["count"] << " test samples\n";
      return;
    }
    heuristic::DatasetOptions options = o->dataset;
    if (!o->shard.empty()) std::tie(options.shard_index, options.shard_count) = parse_shard(o->shard);
    options.dims = Eigen::Vector3i(o->dims[0], o->dims[1], o->dims[2]);
    const Json doc = heuristic::write_dataset(options, o->out, progress_stream());
    const Json& s = doc["splits"];
    // A part holds only its shards' samples: the summary counts those, beside the dataset's
    // (issue 20, sixth campaign U12: a part that held none said "4 train, 0 val, 2 test").
    const auto here = [&](const char* split) {
      long long n = 0;
      for (const Json& shard : s[split]["shards"]) n += shard["count"].get<long long>();
      return n;
    };
    if (o->json) {
      Json summary = {{"out", o->out}, {"train", s["train"]["count"]}, {"val", s["val"]["count"]},
                      {"test", s["test"]["count"]}, {"dims", o->dims}};
      if (doc.contains("part"))
        summary["part"] = {{"index", doc["part"]["index"]}, {"count", doc["part"]["count"]},
                           {"train", here("train")}, {"val", here("val")}, {"test", here("test")}};
      out << dump_json(summary);
      return;
    }
    out << "wrote " << o->out;
    if (doc.contains("part"))
      out << ": part " << doc["part"]["index"] << " of " << doc["part"]["count"] << ", holding " << here("train")
          << " train, " << here("val") << " val, " << here("test") << " test samples (of the dataset's "
          << s["train"]["count"] << ", " << s["val"]["count"] << ", " << s["test"]["count"] << ")";
    else
      out << ": " << s["train"]["count"] << " train, " << s["val"]["count"] << " val, " << s["test"]["count"]
          << " test samples";
    out << " of " << heuristic::kDatasetChannels << " x " << o->dims[0] << "x" << o->dims[1] << "x" << o->dims[2]
        << " (dataset.json describes the layout)\n";
  });

  auto h = std::make_shared<HeuristicCliOptions>();
  CLI::App* c = app.add_subcommand("heuristic", "the sGAN's heuristic region for a map and query (Alg. 1 lines 2-3)");
  add_query_options(c, h->query);
  c->add_option("--weights", h->weights, "sGAN weights file (default: the shipped fixtures/sgan/sgan.bin)");
  c->add_option("--seed", h->seed, "seed of the generator's noise")->capture_default_str()->check(kUnsigned64);
  c->add_flag("--raw", h->raw, "write the thresholded network output's probabilities, unfiltered");
  c->add_flag("--strict-bridge", h->strict_bridge,
              "filter step 5: add the cells a collision-free way from start to goal needs (REQ-HEUR-014)");
  c->add_option("--out", h->region_out, "region file to write (miner-region-v1 JSON, .json)")->required()
      ->check(kOutputFile & suffix_output(".json", "a region is JSON"));
  c->add_flag("--json", h->output.json, "print the summary as JSON");
  c->callback([h, &out] { run_heuristic(*h, out); });

  struct CheckOptions {
    std::string weights, reference;
    bool json = false;
  };
  auto k = std::make_shared<CheckOptions>();
  CLI::App* sg = app.add_subcommand("sgan", "sGAN weights tools");
  sg->require_subcommand(1);
  CLI::App* chk = sg->add_subcommand("check", "C++ inference against PyTorch's reference tensors (max |diff| <= 1e-4)");
  chk->add_option("--weights", k->weights, "weights file (default: the shipped fixtures/sgan/sgan.bin)");
  chk->add_option("--reference", k->reference, "reference.bin written by train.py")->required();
  chk->add_flag("--json", k->json, "print the result as JSON");
  chk->callback([k, &out] {
    const heuristic::Sgan sgan = heuristic::Sgan::load_or_builtin(k->weights);
    const std::vector<double> errors = heuristic::reference_errors(sgan, k->reference);
    const double worst = *std::max_element(errors.begin(), errors.end());
    const bool ok = worst <= heuristic::kReferenceTolerance;
    std::ostringstream s;
    s << sgan.path() << " vs " << k->reference << ": " << errors.size() << " samples, max |C++ - PyTorch| = "
      << worst << (ok ? " (<= 1e-4)\n" : "\n");
    emit(OutputOptions{k->json, ""},
         {{"weights", sgan.path()}, {"reference", k->reference}, {"max_abs_error", errors}, {"agrees", ok}}, s.str(), out);
    if (!ok)
      throw Error(k->reference + ": C++ and PyTorch disagree by " + std::to_string(worst) +
                  " (> 1e-4): the weights and the reference do not belong together");
  });
}

}  // namespace miner::cli
