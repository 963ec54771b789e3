#pragma once
/// \file
/// The `miner` command line (REQ-CLI-001..003). `run_cli` is the whole program, so
/// tests drive it in-process with captured streams; main() only forwards argv.

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/world/map.hpp"

namespace CLI {
class App;
class Validator;
}

namespace miner::cli {

/// Runs `miner <args...>` (args excludes the program name); returns the exit code
/// (miner::ExitCode). Never throws: every error becomes "miner: error: ..." on `err`.
int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// The argument layer alone: parses `miner <args...>` exactly as run_cli does (commands,
/// options, counts, validators, the unknown-command message) but runs no command. Returns
/// run_cli's exit code for a refused line and 0 for a line run_cli would start to run. The
/// fuzz target src/fuzz/fuzz_cli.cpp drives it (REQ-HARNESS-006); never throws, never writes.
int check_cli_arguments(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// check_cli_arguments on one app built once: the same answer for every line, whatever lines
/// came before (CLI11 clears a parse's state when the next begins; test "An argument checker
/// built once answers every line as a fresh one"). Building the ~170 options is most of a
/// line's cost (~7 ms under the fuzz build's sanitizers), so the fuzz target checks this way.
class ArgumentChecker {
 public:
  ArgumentChecker();
  ~ArgumentChecker();
  ArgumentChecker(const ArgumentChecker&) = delete;
  ArgumentChecker& operator=(const ArgumentChecker&) = delete;
  int check(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The option reference of every command, as Markdown, from the commands' own definitions
/// (names, value type and range, default, meaning): docs/cli-reference.md is this text, and
/// a test fails when they differ (issue 22: docs/cli.md had drifted). `miner docs` prints it.
std::string cli_reference_markdown();

/// Every numeric option of every command that has no check of its value besides the decimal
/// form ("plan --goal-bias"): each must declare its range (issue 20: unbounded or silently
/// altered values). The CLI test asserts the list is empty (REQ-CLI-002).
std::vector<std::string> numeric_options_without_checks();

/// The stream progress bars draw to: the terminal (stderr when it is one), or none when the
/// command line said --quiet (every command takes it; issue 22 item 4).
std::ostream* progress_stream();
/// A command whose product is a file: its one-line summary as text, or with --json the same
/// facts as a JSON document on stdout.
void report(bool json, const Json& doc, const std::string& human, std::ostream& out);

/// Options shared by commands that produce a result: --json prints it as JSON instead
/// of the human text, --out also writes the JSON to a file (atomically).
struct OutputOptions {
  bool json = false;
  std::string out;
};
void add_output_options(CLI::App* cmd, OutputOptions& o);
/// Writes `doc` to o.out if set, then prints `doc` (with --json) or `human`.
void emit(const OutputOptions& o, const Json& doc, const std::string& human, std::ostream& out);

/// CLI11 validators: a finite number; a finite number >= 0.
extern const CLI::Validator kFinite;
extern const CLI::Validator kFiniteNonNegative;
/// An unsigned 64-bit integer written as decimal digits only: "-1" is refused (CLI11 would
/// wrap it to 2^64 - 1) and so is anything above 2^64 - 1 (never clamped). REQ-CLI-002.
extern const CLI::Validator kUnsigned64;
/// An integer in decimal digits, with an optional '-': CLI11 reads integers with base 0, so
/// "010" was octal 8, "0x10" 16 and "+3" 3 (issue 20). Leading zeros are dropped ("010" is
/// 10). Every INT/UINT option of every command gets it (run_cli adds it). REQ-CLI-002.
extern const CLI::Validator kDecimalInteger;
/// --shard i/N with 0 <= i < N, checked when the line is parsed (a usage error, exit 2).
extern const CLI::Validator kShard;
/// A finite number in [lo, hi] ("must be a finite number in [1e-06, 3600], got nan"); CLI11's
/// Range lets NaN through and prints its bounds with six decimals. REQ-CLI-002.
CLI::Validator finite_in(double lo, double hi);
/// An integer in [lo, hi], read after kDecimalInteger. REQ-CLI-002.
CLI::Validator integer_in(long long lo, long long hi);
/// One of `names` ("unknown <what> \"x\", did you mean \"y\"? (known: a, b, c)"), a usage error.
CLI::Validator one_of(const std::string& what, const std::vector<std::string>& names);
/// A map generator preset (`map gen --preset`, `dataset --preset`).
extern const CLI::Validator kMapPreset;
/// Resource bounds of the command line (issue 20: bounded work, named in --help). An iteration
/// budget above 1e7 holds a tree of ~1 GB; more than 1e5 runs of a campaign, or 1e4 boxes
/// placed by a generator whose placement is quadratic, run for hours.
inline constexpr int kMaxIterations = 10000000;
inline constexpr int kMaxRuns = 100000;
inline constexpr int kMaxObstacles = 10000;
/// CLI::Range(1, kMaxIterations) and CLI::Range(1, kMaxRuns).
extern const CLI::Validator kIterationsRange;
extern const CLI::Validator kRunsRange;
/// Output paths checked when the command line is parsed, before any work (issue 20: a bad
/// --ompl-log used to fail after the whole campaign). kOutputFile: the folder that will hold
/// the file exists and is writable, and the path is not a folder. kOutputFolder: the path is
/// not a file, and its nearest existing ancestor is a writable folder (missing ones are
/// created). REQ-CLI-003.
extern const CLI::Validator kOutputFile;
extern const CLI::Validator kOutputFolder;
/// kOutputFolder for a folder a command replaces as a whole (run folders, datasets, figure
/// folders): an existing, non-empty one must look like an earlier output of the command, i.e.
/// hold only regular files with one of `extensions` and, if `marker` is not empty, that file.
CLI::Validator output_folder_for(const std::string& marker, const std::vector<std::string>& extensions);
/// The longest file name an output may have (Linux NAME_MAX).
inline constexpr std::size_t kMaxFileName = 255;
/// A file whose missing folders the command creates (bench paper/suite --results): the
/// path is not a folder and the nearest existing ancestor of its folder is writable.
extern const CLI::Validator kOutputFileNewFolder;

/// --map, --start x y z, --goal x y z, --radius: a planning query, where start, goal and
/// radius default to the map's stored "query" (REQ-CLI-004).
struct QueryOptions {
  std::string map;
  std::string unknown;  // empty: the map's own unknown-space policy
  std::vector<double> start, goal;
  double radius = -1.0;
};
void add_query_options(CLI::App* cmd, QueryOptions& q);
/// Loads a map, read under the unknown-space policy `unknown` ("occupied", "free") if not empty.
world::Map load_map(const std::string& path, const std::string& unknown);
struct ResolvedQuery {
  world::Map map;
  Eigen::Vector3d start;
  Eigen::Vector3d goal;
  double radius = 0.0;
};
/// Loads the map and fills start/goal/radius; throws miner::Error if the map has no
/// query and --start/--goal are missing.
ResolvedQuery resolve_query(const QueryOptions& q);

/// Registers `miner map ...` and `miner astar` (map_commands.cpp). The callbacks
/// write to `out`; errors propagate as miner::Error.
void add_map_commands(CLI::App& app, std::ostream& out);
/// Registers `miner traj solve` (traj_commands.cpp).
void add_traj_commands(CLI::App& app, std::ostream& out);
/// Registers `miner bench ...` (bench_commands.cpp).
void add_bench_commands(CLI::App& app, std::ostream& out);
/// Registers `miner plan` and `miner region ...` (plan_commands.cpp).
void add_plan_commands(CLI::App& app, std::ostream& out);
/// Registers `miner fly` and `miner bench sim` (fly_commands.cpp); after the bench commands.
void add_fly_commands(CLI::App& app, std::ostream& out);
/// Registers `miner dataset` (heuristic_commands.cpp).
void add_heuristic_commands(CLI::App& app, std::ostream& out);

}  // namespace miner::cli
