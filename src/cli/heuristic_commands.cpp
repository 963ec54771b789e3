// `miner dataset` (REQ-HEUR-001..003).
#include <memory>
#include <ostream>

#include <CLI/CLI.hpp>

#include "cli/cli.hpp"
#include "miner/core/progress.hpp"
#include "miner/heuristic/dataset.hpp"

namespace miner::cli {

namespace {
struct DatasetCliOptions {
  heuristic::DatasetOptions dataset;
  std::vector<int> dims = {32, 32, 32};
  std::string out;
};
}  // namespace

void add_heuristic_commands(CLI::App& app, std::ostream& out) {
  auto o = std::make_shared<DatasetCliOptions>();
  CLI::App* d = app.add_subcommand("dataset", "sGAN training data: random maps and queries, A* ground truth, E/S/T grids");
  d->add_option("--count", o->dataset.count, "train + validation samples")->capture_default_str();
  d->add_option("--test-count", o->dataset.test_count, "test samples from unseen map seeds")->capture_default_str();
  d->add_option("--val-fraction", o->dataset.val_fraction, "share of --count kept for validation")->capture_default_str();
  d->add_option("--seed", o->dataset.seed, "master seed")->capture_default_str();
  d->add_option("--preset", o->dataset.preset, "map preset (sim, indoor)")->capture_default_str();
  d->add_option("--dims", o->dims, "heuristic grid nx ny nz")->expected(3)->capture_default_str();
  d->add_option("--dilation", o->dataset.dilation, "cells around start, goal and path cells (1: 3x3x3)")->capture_default_str();
  d->add_option("--shard-size", o->dataset.shard_size, "samples per shard file")->capture_default_str();
  d->add_option("--jobs", o->dataset.jobs, "worker threads (the output does not depend on it)")->capture_default_str();
  d->add_option("--out", o->out, "output folder (written as a whole)")->required();
  d->callback([o, &out] {
    heuristic::DatasetOptions options = o->dataset;
    options.dims = Eigen::Vector3i(o->dims[0], o->dims[1], o->dims[2]);
    const Json doc = heuristic::write_dataset(options, o->out, terminal_stream());
    const Json& s = doc["splits"];
    out << "wrote " << o->out << ": " << s["train"]["count"] << " train, " << s["val"]["count"] << " val, "
        << s["test"]["count"] << " test samples of 3 x " << o->dims[0] << "x" << o->dims[1] << "x" << o->dims[2]
        << " (dataset.json describes the layout)\n";
  });
}

}  // namespace miner::cli
