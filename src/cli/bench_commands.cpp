// `miner bench backend` (REQ-TRAJ-009).
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "bench/backend_bench.hpp"
#include "cli/cli.hpp"
#include "miner/core/json_io.hpp"

namespace miner::cli {

namespace {
struct BackendOptions {
  bench::BackendBenchOptions bench;
  OutputOptions output;
};
}  // namespace

void add_bench_commands(CLI::App& app, std::ostream& out) {
  CLI::App* bench_cmd = app.add_subcommand("bench", "benchmarks (figures for docs/)");
  bench_cmd->require_subcommand(1);
  auto o = std::make_shared<BackendOptions>();
  CLI::App* b = bench_cmd->add_subcommand("backend", "MINCO vs dense LU, closed form and KKT QP (paper Table II)");
  b->add_option("--segments", o->bench.segments, "segment counts M")->capture_default_str()->delimiter(',');
  b->add_option("--orders", o->bench.orders, "orders s (3 jerk, 4 snap)")->capture_default_str()->delimiter(',');
  b->add_option("--methods", o->bench.methods, "minco, dense-lu, closed-form, kkt-qp")->capture_default_str()->delimiter(',');
  b->add_option("--max-dense-segments", o->bench.max_dense_segments, "skip the O(M^3) baselines above this M")
      ->capture_default_str();
  b->add_option("--budget", o->bench.budget_s, "seconds per (method, order, M)")->capture_default_str();
  b->add_option("--samples", o->bench.samples, "timed batches (median reported)")->capture_default_str();
  b->add_option("--seed", o->bench.seed, "seed of the waypoints")->capture_default_str();
  add_output_options(b, o->output);
  b->callback([o, &out] {
    const auto records = bench::run_backend_bench(o->bench);
    std::ostringstream table;
    bench::print_table(records, table);
    emit(o->output, bench::to_json(records), table.str(), out);
  });
}

}  // namespace miner::cli
