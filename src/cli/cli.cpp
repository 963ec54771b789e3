#include "cli/cli.hpp"

#include <iostream>
#include <new>

#include <CLI/CLI.hpp>

#include "miner/core/error.hpp"

namespace miner::cli {

void add_output_options(CLI::App* cmd, OutputOptions& o) {
  cmd->add_flag("--json", o.json, "print the result as JSON");
  cmd->add_option("--out", o.out, "also write the JSON result to this file");
}

void emit(const OutputOptions& o, const Json& doc, const std::string& human, std::ostream& out) {
  if (!o.out.empty()) write_file_atomic(o.out, dump_json(doc));
  if (o.json) {
    out << dump_json(doc);
  } else {
    out << human;
  }
}

int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  CLI::App app{"miner — MINER-RRT* quadrotor planning and flight stack", "miner"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "miner 0.1.0");
  add_map_commands(app, out);
  add_traj_commands(app, out);
  add_bench_commands(app, out);

  // CLI11 parses in reverse order of the vector it is given.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    out << app.help();
    return 0;
  } catch (const CLI::CallForAllHelp& e) {
    out << app.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::CallForVersion& e) {
    out << e.what() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    err << "miner: usage error: " << e.what() << "\n";
    err << "run 'miner --help' (or 'miner <command> --help') for usage\n";
    return static_cast<int>(ExitCode::kUsage);
  } catch (const Error& e) {
    err << "miner: error: " << e.what() << "\n";
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    err << "miner: error: out of memory\n";
    return static_cast<int>(ExitCode::kInvalidInput);
  } catch (const std::exception& e) {
    err << "miner: internal error: " << e.what() << "\n";
    return static_cast<int>(ExitCode::kInvalidInput);
  }
  return 0;
}

}  // namespace miner::cli
