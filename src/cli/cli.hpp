#pragma once
/// \file
/// The `miner` command line (REQ-CLI-001..003). `run_cli` is the whole program, so
/// tests drive it in-process with captured streams; main() only forwards argv.

#include <iosfwd>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace miner::cli {

/// Runs `miner <args...>` (args excludes the program name); returns the exit code
/// (miner::ExitCode). Never throws: every error becomes "miner: error: ..." on `err`.
int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// Registers `miner map ...` and `miner astar` (map_commands.cpp). The callbacks
/// write to `out`; errors propagate as miner::Error.
void add_map_commands(CLI::App& app, std::ostream& out);
/// Registers `miner traj solve` (traj_commands.cpp).
void add_traj_commands(CLI::App& app, std::ostream& out);
/// Registers `miner bench ...` (bench_commands.cpp).
void add_bench_commands(CLI::App& app, std::ostream& out);

}  // namespace miner::cli
