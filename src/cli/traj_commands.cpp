// `miner traj solve` (REQ-TRAJ-006).
#include <optional>
#include <ostream>

#include <CLI/CLI.hpp>

#include "cli/cli.hpp"
#include "miner/core/text.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/traj/problem_io.hpp"

namespace miner::cli {

namespace {
struct SolveOptions {
  std::string problem;
  std::string out;
  std::string allocate;
  std::optional<double> rho;
  bool json = false;
};

void run_solve(const SolveOptions& o, std::ostream& out) {
  const auto request = traj::request_from_json(read_json_file(o.problem), o.problem, o.allocate, o.rho);
  const auto& problem = request.problem;
  Json answer;
  std::optional<double> solve_ms;  // said on the terminal, never in the file (deterministic bytes)
  try {
    if (request.optimise) {
      const traj::AllocationResult a = traj::optimise_allocation(problem, *request.optimise);
      solve_ms = a.solve_ms;
      answer = traj::answer_to_json(a, *request.optimise);
    } else {
      answer = traj::answer_to_json(traj::solve_minco(problem));
    }
  } catch (const Error& e) {
    // The solver names the rule the problem breaks; the message names the problem file too
    // (issue 20, fourth campaign: "allocation: \"optimise\" needs ..." named no file).
    throw Error(o.problem + ": " + e.what(), e.code());
  }
  if (o.out.empty()) {
    out << dump_json(answer);
  } else {
    write_file_atomic(o.out, dump_json(answer));
    if (o.json) {
      out << dump_json(answer);
      return;
    }
    out << "wrote " << o.out << ": " << answer["durations"].size() << " segments, order "
        << problem.order << ", cost " << answer["cost"].get<double>();
    if (solve_ms) out << ", allocation solved in " << short_number(*solve_ms) << " ms";
    out << "\n";
  }
}
}  // namespace

void add_traj_commands(CLI::App& app, std::ostream& out) {
  CLI::App* traj = app.add_subcommand("traj", "minimum-jerk/snap trajectories (MINCO)");
  traj->require_subcommand(1);
  auto solve = std::make_shared<SolveOptions>();
  CLI::App* s = traj->add_subcommand("solve", "solve a trajectory problem file (docs/traj.md)");
  s->add_option("--problem", solve->problem, "problem JSON: order, points, head, tail, durations or limits")->required();
  s->add_option("--out", solve->out, "write the answer JSON here (.json; default: stdout)")
      ->check(kOutputFile & suffix_output(".json", "the answer is JSON"));
  s->add_option("--allocate", solve->allocate,
                "durations from the limits: trapezoid (default) or optimise (min J + rho sum T within the limits, Ceres)")
      ->check(CLI::IsMember({"trapezoid", "optimise"}));
  s->add_option("--rho", solve->rho, "weight of the total time with --allocate optimise (default 1, or the file's)")
      ->check(finite_in(1e-9, 1e9));
  s->add_flag("--json", solve->json, "print the answer JSON on stdout (what it prints without --out; with --out, as well)");
  s->callback([solve, &out] { run_solve(*solve, out); });
}

}  // namespace miner::cli
