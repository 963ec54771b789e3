#include "cli/cli.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <new>
#include <regex>
#include <sstream>

#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <unistd.h>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/shard.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/map_generator.hpp"

namespace miner::cli {

namespace {
/// A finite decimal number (no hex, inf or nan, which strtod also reads): every floating-point
/// option goes through it.
bool read_finite_decimal(const std::string& text, double& v) {
  if (!(is_decimal_number(text) && CLI::detail::lexical_cast(text, v) && std::isfinite(v))) return false;
  // A non-zero number too small for a double (1e-400 read as 0, 1e-310 as a subnormal) is
  // refused, not rounded (issue 20: astar --radius 1e-400 became radius 0).
  const std::string mantissa = text.substr(0, text.find_first_of("eE"));
  const bool nonzero = mantissa.find_first_of("123456789") != std::string::npos;
  return !(nonzero && (v == 0.0 || std::fpclassify(v) == FP_SUBNORMAL));
}
}  // namespace


const CLI::Validator kUnsigned64(
    [](std::string& text) -> std::string {
      static const std::string kMax = "18446744073709551615";  // 2^64 - 1
      const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
      if (!digits) return "must be a non-negative integer (decimal digits only), got " + text;
      const std::string trimmed = text.substr(std::min(text.find_first_not_of('0'), text.size() - 1));
      if (trimmed.size() > kMax.size() || (trimmed.size() == kMax.size() && trimmed > kMax))
        return "must be at most 18446744073709551615 (2^64 - 1), got " + text;
      return {};
    },
    "UINT64");

const CLI::Validator kIterationsRange = integer_in(1, static_cast<long long>(kMaxIterations));
const CLI::Validator kRunsRange = integer_in(1, static_cast<long long>(kMaxRuns));

const CLI::Validator kDecimalInteger(
    [](std::string& text) -> std::string {
      const std::size_t sign = !text.empty() && text[0] == '-' ? 1 : 0;
      const std::string digits = text.substr(sign);
      if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
        return "must be a decimal integer, got " + text;
      // CLI11 converts with strtoll(..., 0): a leading zero would make "010" octal 8.
      const std::string trimmed = digits.substr(std::min(digits.find_first_not_of('0'), digits.size() - 1));
      text = (sign && trimmed != "0" ? "-" : "") + trimmed;
      return {};
    },
    "");

namespace {

/// Whether a file can be created in `folder`: a real probe (create, then remove, a hidden file),
/// because access(W_OK) says yes to root in /proc and on read-only mounts (issue 20: `--out
/// /proc/x` passed and failed after the work). Empty when it can, else the reason.
std::string probe_writable(const std::filesystem::path& folder) {
  const std::filesystem::path probe = folder / (".miner-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY, 0600);
  if (fd < 0) return "the folder " + folder.string() + " is not writable";
  ::close(fd);
  ::unlink(probe.c_str());
  return {};
}

/// The nearest existing ancestor of `p` (p itself if it exists).
std::filesystem::path nearest_existing(std::filesystem::path p) {
  std::error_code ec;
  while (!p.empty() && !std::filesystem::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
  return p;
}

/// What makes an output file path unusable whatever its folder: a name over the file-system
/// limit (checked before the work, not when the write fails after it), or an existing thing
/// that is not a regular file (a device, FIFO or socket would be replaced by the write's
/// rename; issue 20). A symbolic link is judged by what it points to (the write goes through
/// it). Empty when usable.
std::string output_file_problem(const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path p(text);
  if (p.filename().string().size() > kMaxFileName)
    return text.substr(0, 40) + "...: the file name is longer than " + std::to_string(kMaxFileName) + " bytes";
  std::error_code ec;
  const auto st = fs::status(p, ec);
  if (fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st))
    return text + " exists and is not a regular file (a device, FIFO or socket): outputs are written as regular files, "
                  "which would replace it";
  // An output is written through a symbolic link into its target (REQ-CORE-004), and the name's
  // suffix chooses what is written (.json, .bt, .md ...): a link whose target has another suffix
  // would put one kind of file under another's name (issue 20: `--out x.json` linking to y.png).
  fs::path target;
  try {
    target = link_target(text);
  } catch (const Error& e) {
    return e.what();
  }
  if (target != p && target.extension() != p.extension())
    return text + " is a symbolic link to " + target.string() + ": the file written there would hold what the name " +
           (p.extension().empty() ? std::string("without a suffix") : "ending in " + p.extension().string()) +
           " asks for, under a name " +
           (target.extension().empty() ? std::string("without one") : "ending in " + target.extension().string()) +
           " (give the target's own name, or a link with the same suffix)";
  return {};
}

}  // namespace

const CLI::Validator kOutputFile(
    [](std::string& text) -> std::string {
      namespace fs = std::filesystem;
      if (text.empty()) return "an output file needs a name";
      const fs::path p(text);
      std::error_code ec;
      if (fs::is_directory(p, ec)) return text + " is a folder, not a file";
      if (std::string problem = output_file_problem(text); !problem.empty()) return problem;
      // Written through a link into its target, dangling or not (REQ-CORE-004): the target's folder.
      fs::path real;
      try {
        real = output_target(text);
      } catch (const Error& e) {
        return e.what();
      }
      const fs::path parent = real.parent_path().empty() ? fs::path(".") : real.parent_path();
      if (!fs::is_directory(parent, ec)) return "the folder " + parent.string() + " does not exist";
      return probe_writable(parent);
    },
    "OUTPUT FILE");

const CLI::Validator kOutputFolder(
    [](std::string& text) -> std::string {
      namespace fs = std::filesystem;
      if (text.empty()) return "an output folder needs a name";
      std::error_code ec;
      // The writer's own rules, before the work (nineteenth campaign F19: `--out .` was refused
      // after a whole dataset run; F18: a dangling link's missing folders were created).
      if (std::string problem = folder_name_problem(text); !problem.empty()) return problem;
      try {
        (void)output_target(named_folder(text).string());
      } catch (const Error& e) {
        return e.what();
      }
      fs::path p = fs::absolute(fs::path(text), ec);
      if (fs::exists(p, ec) && !fs::is_directory(p, ec)) return text + " is a file, not a folder";
      // The folder is written beside itself and moved in place; missing parents are created
      // in the nearest existing ancestor.
      const fs::path ancestor = nearest_existing(p.parent_path());
      if (!fs::is_directory(ancestor, ec)) return ancestor.string() + " is not a folder";
      return probe_writable(ancestor);
    },
    "OUTPUT FOLDER");

CLI::Validator output_folder_for(const FolderMarker& marker, const std::vector<std::string>& extensions) {
  return CLI::Validator(
      [marker, extensions](std::string& text) -> std::string {
        namespace fs = std::filesystem;
        if (std::string problem = kOutputFolder(text); !problem.empty()) return problem;
        std::error_code ec;
        const fs::path p(text);
        if (!fs::is_directory(p, ec) || fs::is_empty(p, ec)) return {};
        // The command's own rule (write_folder_atomic) needs the names it writes, known only
        // after the work; this is its part that can be told now, so that a user's folder is
        // refused before the work rather than after it (issue 20).
        // Nothing in it may be a file the command never writes (seventeenth campaign F31) ...
        if (std::string problem =
                foreign_entry_problem(text, marker, {}, std::set<std::string>(extensions.begin(), extensions.end()));
            !problem.empty())
          return problem;
        // ... and what the folder is goes by its marker's content, not its name (seventh campaign D1).
        return folder_marker_problem(text, marker);
      },
      "OUTPUT FOLDER");
}

CLI::Validator suffix_output(const std::string& suffix, const std::string& what) {
  return CLI::Validator(
      [suffix, what](std::string& text) -> std::string {
        // An option taken as the value ("--out --json") is named as such by the parse-complete
        // check, not blamed on its suffix.
        if (text.rfind("--", 0) == 0) return "";
        if (ends_with(text, suffix)) return "";
        return text + " must end in " + suffix + " (" + what + ")";
      },
      "FILE" + suffix);
}

const CLI::Validator kOutputFileNewFolder(
    [](std::string& text) -> std::string {
      namespace fs = std::filesystem;
      if (text.empty()) return "an output file needs a name";
      std::error_code ec;
      if (fs::is_directory(fs::path(text), ec)) return text + " is a folder, not a file";
      if (std::string problem = output_file_problem(text); !problem.empty()) return problem;
      const fs::path folder = fs::absolute(fs::path(text), ec).parent_path();
      if (fs::exists(folder, ec) && !fs::is_directory(folder, ec)) return folder.string() + " is a file, not a folder";
      const fs::path ancestor = nearest_existing(folder);
      if (!fs::is_directory(ancestor, ec)) return ancestor.string() + " is not a folder";
      return probe_writable(ancestor);
    },
    "OUTPUT FILE");

CLI::Validator finite_in(double lo, double hi) {
  const std::string text_range = "[" + exact_number(lo) + ", " + exact_number(hi) + "]";
  return CLI::Validator(
      [lo, hi, text_range](std::string& text) -> std::string {
        double v = 0.0;
        if (!read_finite_decimal(text, v) || v < lo || v > hi)
          return "must be a finite decimal number in " + text_range + ", got " + text;
        return {};
      },
      "in " + text_range);
}

CLI::Validator integer_in(long long lo, long long hi) {
  const std::string text_range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, text_range](std::string& text) -> std::string {
        long long v = 0;
        if (!CLI::detail::lexical_cast(text, v) || v < lo || v > hi)
          return "must be an integer in " + text_range + ", got " + text;
        return {};
      },
      "in " + text_range);
}

CLI::Validator one_of(const std::string& what, const std::vector<std::string>& names) {
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
  return CLI::Validator(
      [what, names, known](std::string& text) -> std::string {
        if (std::find(names.begin(), names.end(), text) != names.end()) return {};
        const std::string nearest = nearest_name(text, names);
        return "unknown " + what + " \"" + text + "\"" + (nearest.empty() ? "" : ", did you mean \"" + nearest + "\"?") +
               " (known: " + known + ")";
      },
      "one of " + known);
}

const CLI::Validator kMapPreset = one_of("map preset", world::generator_preset_names());

const CLI::Validator kShard(
    [](std::string& text) -> std::string {
      try {
        (void)parse_shard(text);
      } catch (const Error&) {
        return "expected i/N with 0 <= i < N (e.g. 0/4), got \"" + text + "\"";
      }
      return {};
    },
    "i/N");

const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      double v = 0.0;
      if (!read_finite_decimal(text, v)) {
        return "must be a finite decimal number, got " + text;
      }
      return {};
    },
    "FINITE");

void add_query_options(CLI::App* cmd, QueryOptions& q) {
  cmd->add_option("--map", q.map, "map file (.json, or an OctoMap .bt/.ot)")->required();
  cmd->add_option("--unknown", q.unknown,
                  "voxel maps: unknown space is 'occupied' (the default, safe) or 'free' (default: the map's own)")
      ->check(CLI::IsMember({"occupied", "free"}));
  cmd->add_option("--start", q.start, "start x y z in m (default: the map's query)")->expected(3)->check(kFinite);
  cmd->add_option("--goal", q.goal, "goal x y z in m (default: the map's query)")->expected(3)->check(kFinite);
  cmd->add_option("--radius", q.radius, "robot radius in m (default: the map's query radius or 0)")
      ->check(finite_in(0.0, world::kMaxRobotRadius));
}

world::Map load_map(const std::string& path, const std::string& unknown) {
  world::Map map = world::Map::load(path);
  if (unknown.empty()) return map;
  // A box map has no unknown space: the option would change nothing (issue 20, fourth
  // campaign: `--unknown free` on a box map was accepted and ignored).
  if (!map.voxel_source())
    throw Error("--unknown: " + path + " is a map of boxes, with no voxels and so no unknown space: the option "
                "applies to voxel maps only",
                ExitCode::kUsage);
  return map.with_unknown(world::parse_unknown_policy(unknown, "--unknown"));
}

ResolvedQuery resolve_query(const QueryOptions& q) {
  world::Map map = load_map(q.map, q.unknown);
  if ((q.start.empty() || q.goal.empty()) && !map.query()) {
    throw Error(q.map + ": has no \"query\"; give --start x y z and --goal x y z");
  }
  const auto vec = [](const std::vector<double>& v, const char* field) {
    Eigen::Vector3d p(v.at(0), v.at(1), v.at(2));
    require_finite(p, field);
    return p;
  };
  const Eigen::Vector3d start = q.start.empty() ? map.query()->start : vec(q.start, "--start");
  const Eigen::Vector3d goal = q.goal.empty() ? map.query()->goal : vec(q.goal, "--goal");
  const double radius = q.radius >= 0.0 ? q.radius : (map.query() ? map.query()->robot_radius : 0.0);
  // A stored query's fault names the map file and the field (issue 20, fourth campaign: "start
  // ... lies inside obstacle 0" named neither).
  const std::string start_name = q.start.empty() ? q.map + ": query.start" : "--start";
  const std::string goal_name = q.goal.empty() ? q.map + ": query.goal" : "--goal";
  // Both ends, given or stored, named as given (issue 20, sixth campaign: `plan --start` inside
  // an obstacle named neither the option nor the map).
  map.require_free(start, radius, start_name);
  map.require_free(goal, radius, goal_name);
  return {std::move(map), start, goal, radius, start_name, goal_name};
}

void add_output_options(CLI::App* cmd, OutputOptions& o) {
  cmd->add_flag("--json", o.json, "print the result as JSON");
  cmd->add_option("--out", o.out, "also write the JSON result to this file (.json)")
      ->check(kOutputFile & suffix_output(".json", "the result is JSON"));
}

void emit(const OutputOptions& o, const Json& doc, const std::string& human, std::ostream& out) {
  if (!o.out.empty()) write_file_atomic(o.out, dump_json(doc));
  if (o.json) {
    out << dump_json(doc);
  } else {
    out << human;
  }
}

namespace {

/// Thrown by the top command's parse-complete callback in Mode::kParseOnly: CLI11 runs it
/// after every option is converted and validated and before any subcommand's callback, so
/// the line is checked whole (check_outputs_against_inputs included) and no command runs. (Replacing the commands' callbacks instead
/// would free the option structs they own while CLI11 still writes into them.)
struct ParsedOnly {};

/// A real option written as a negative zero ("-0", "-0.0e3") reads as 0: "robot radius -0 m" and
/// a JSON -0.0 are no one's intent (issue 20, sixth campaign U6). Other text passes unchanged to
/// the option's own checks.
const CLI::Validator kUnsignedZero(
    [](std::string& text) -> std::string {
      double v = 0.0;
      if (!text.empty() && text[0] == '-' && read_finite_decimal(text, v) && v == 0.0) text.erase(0, 1);
      return {};
    },
    "");

/// Every integer option of `app` and its subcommands reads decimal digits only (kDecimalInteger);
/// every real option reads a negative zero as 0 (kUnsignedZero).
void decimal_numbers(CLI::App* app) {
  for (CLI::Option* o : app->get_options()) {
    const std::string type = o->get_type_name();
    if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) o->transform(kDecimalInteger);  // first, may edit
    if (type.rfind("FLOAT", 0) == 0) o->transform(kUnsignedZero);
  }
  for (CLI::App* sub : app->get_subcommands([](CLI::App*) { return true; })) decimal_numbers(sub);
}

/// The voxel file a map file (JSON) references (Map::voxel_file_path, as the map reads it); empty
/// when `path` is not such a map (or not readable: the command itself says why). Only files
/// that mention "voxels" are parsed, and none above kMaxMapFileBytes.
std::string referenced_voxel_file(const std::string& path) {
  namespace fs = std::filesystem;
  constexpr std::uintmax_t kMaxMapFileBytes = 64u << 20;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) > kMaxMapFileBytes) return {};
  try {
    const std::string text = read_file_bytes(path);
    if (text.find("\"voxels\"") == std::string::npos) return {};
    const Json doc = parse_json(text, path);
    if (!doc.is_object() || !doc.contains("voxels") || !doc["voxels"].is_object() ||
        !doc["voxels"].contains("file") || !doc["voxels"]["file"].is_string())
      return {};
    return world::Map::voxel_file_path(path, doc["voxels"]["file"].get<std::string>());
  } catch (const std::exception&) {
    return {};
  }
}

/// No output may be, or hold, one of the command's inputs (issue 20: `astar --map m.json --out
/// m.json` replaced the map with the answer; `dataset --merge d/a d/b --out d` deleted the
/// parts). Outputs are the options checked by kOutputFile/kOutputFolder/kOutputFileNewFolder;
/// inputs are the values of every other option that name an existing file or folder.
/// `app` and the subcommands this command line chose, outermost first.
std::vector<CLI::App*> parsed_commands(CLI::App* app) {
  std::vector<CLI::App*> chain{app};
  for (std::size_t i = 0; i < chain.size(); ++i)
    for (CLI::App* sub : chain[i]->get_subcommands()) chain.push_back(sub);
  return chain;
}

void check_outputs_against_inputs(CLI::App* app) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::string>> outputs, inputs;  // (option, path)
  const std::vector<CLI::App*> chain = parsed_commands(app);
  std::error_code ec;
  for (CLI::App* cmd : chain)
    for (const CLI::Option* o : cmd->get_options()) {
      if (o->count() == 0) continue;
      const bool output = o->get_type_name().find("OUTPUT") != std::string::npos;
      for (const std::string& value : o->results()) {
        if (value.empty()) continue;
        if (output) {
          outputs.emplace_back(o->get_name(), value);
        } else if (fs::exists(fs::path(value), ec)) {
          inputs.emplace_back(o->get_name(), value);
          // A map file reads its voxels from the file it references (issue 20: `astar --map m.json
          // --out m.bt` replaced m.json's voxels, and the map no longer loaded).
          const std::string voxels = referenced_voxel_file(value);
          if (!voxels.empty()) inputs.emplace_back(o->get_name() + " (its voxels.file)", voxels);
        }
      }
    }
  // Two outputs of one command on one path: the second write would replace the first (issue
  // 20: `map scan --out a.bt --map-out a.bt` left a map that references itself).
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (is_same_or_inside(outputs[j].second, outputs[i].second) || is_same_or_inside(outputs[i].second, outputs[j].second))
        throw CLI::ValidationError(outputs[i].first, outputs[i].second + " is, holds or lies in " + outputs[j].second + " (" +
                                                         outputs[j].first + "): two outputs of one command need two places");
  for (const auto& [out_name, out] : outputs)
    for (const auto& [in_name, in] : inputs) {
      if (is_same_or_inside(out, in))
        throw CLI::ValidationError(out_name, out + " is, or holds, the input " + in + " (" + in_name +
                                                 "): the command would replace its own input");
      // ... nor lies inside an input folder (seventeenth campaign F15: `dataset --merge p0 p1
      // --out p0/sub` put the merged dataset inside a part folder).
      if (fs::is_directory(fs::path(in), ec) && is_same_or_inside(in, out))
        throw CLI::ValidationError(out_name, out + " lies inside the input folder " + in + " (" + in_name +
                                                 "): the command would write into its own input");
    }
}

/// A list option names each value once (issue 20, third campaign: `map import --cloud a a`
/// fused one scan twice, `bench paper --maps m,m` ran a map twice). Options of a fixed count
/// (coordinates, grid dims: `--size 10 10 3`) are tuples, not lists, and may repeat a value;
/// two spellings of one existing file (`m.json`, `./m.json`) are one value.
void check_list_values_distinct(CLI::App* app) {
  namespace fs = std::filesystem;
  const std::vector<CLI::App*> chain = parsed_commands(app);
  std::error_code ec;
  for (CLI::App* cmd : chain)
    for (const CLI::Option* o : cmd->get_options()) {
      if (o->count() == 0 || o->get_items_expected_max() <= o->get_items_expected_min()) continue;
      const std::vector<std::string>& values = o->results();
      for (std::size_t i = 0; i < values.size(); ++i)
        for (std::size_t j = 0; j < i; ++j) {
          if (values[i] == values[j])
            throw CLI::ValidationError(o->get_name(), "lists " + values[i] + " twice (each value once)");
          if (fs::exists(values[i], ec) && fs::exists(values[j], ec) && fs::equivalent(values[i], values[j], ec))
            throw CLI::ValidationError(o->get_name(), "lists " + values[j] + " and " + values[i] +
                                                          ", one file twice (each value once)");
        }
    }
}

/// An option's value that is another option of the command line (`--out --json`) was an
/// option left without its value: CLI11 takes it as the value (issue 20, fourth campaign: a
/// file named "--json" was written and the text printed).
void check_no_option_as_value(CLI::App* app) {
  const std::vector<CLI::App*> chain = parsed_commands(app);
  std::vector<std::string> names;
  for (CLI::App* cmd : chain)
    for (const CLI::Option* o : cmd->get_options()) {
      for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
      for (const std::string& n : o->get_snames()) names.push_back("-" + n);
    }
  for (CLI::App* cmd : chain)
    for (const CLI::Option* o : cmd->get_options())
      for (const std::string& value : o->results()) {
        if (std::find(names.begin(), names.end(), value) != names.end())
          throw CLI::ValidationError(o->get_name(), "needs a value, got the option " + value);
        // "--" ends the options; as a value (`--out=--`) it names nothing (nineteenth campaign F6).
        if (value == "--") throw CLI::ValidationError(o->get_name(), "needs a value, got \"--\" (the end of the options)");
        // An empty value names nothing (issue 20, fourth campaign: `--map ''` was answered
        // ": cannot open file"); no option of MINER takes one.
        if (value.empty() && o->get_expected_max() > 0)
          throw CLI::ValidationError(o->get_name(), "needs a value, got an empty one");
      }
}

/// The hint for a word led by a dash look-alike (an autocorrected en dash, em dash or minus
/// sign): "W starts with a dash look-alike, not "-": did you mean --name?" (-1 for a number);
/// empty for any other word.
std::string dash_lookalike_hint(const std::string& word) {
  for (const char* dash : {"\xE2\x80\x93", "\xE2\x80\x94", "\xE2\x88\x92"}) {
    if (word.rfind(dash, 0) != 0) continue;
    std::string meant = word;
    while (!meant.empty() && (meant[0] == '-' || meant.rfind(dash, 0) == 0))
      meant.erase(0, meant[0] == '-' ? 1 : std::strlen(dash));
    // A number's minus sign autocorrected is meant as -1, not as an option.
    const bool number = !meant.empty() && (std::isdigit(static_cast<unsigned char>(meant[0])) || meant[0] == '.');
    return word + " starts with a dash look-alike, not \"-\": did you mean " + (number ? "-" : "--") + meant + "?";
  }
  return {};
}

/// "unexpected argument(s) "a", "b": the command takes none", each word quoted alone, with the
/// "--" note when the line has one (seventeenth campaign F30) and the first dash look-alike's
/// hint (dash_lookalike_hint).
std::string unexpected_arguments_text(const std::vector<std::string>& words, bool separator) {
  std::string line, hint;
  for (const std::string& w : words) {
    line += (line.empty() ? "\"" : ", \"") + w + "\"";
    if (hint.empty() && !dash_lookalike_hint(w).empty()) hint = "; " + dash_lookalike_hint(w);
  }
  return std::string("unexpected argument") + (words.size() > 1 ? "s " : " ") + line + ": the command takes none" +
         (separator ? " (after \"--\" every word is an argument, not an option)" : "") + hint;
}

/// CLI11's count messages in plain words (issue 20, third campaign: "--radius: At Most 1
/// required but received 2", "--planners: 1 required TEXT:PLANNER missing").
std::string plain_usage_text(const std::string& text, bool separator) {
  static const std::regex at_most(R"(^(\S+): At Most (\d+) required but received (\d+)$)");
  static const std::regex at_least(R"(^(\S+): At least (\d+) required but received (\d+)$)");
  static const std::regex missing(R"(^(\S+): (\d+) required (\S+) missing$)");
  const auto values = [](const std::string& n) { return n + (n == "1" ? " value" : " values"); };
  std::smatch m;
  if (std::regex_match(text, m, at_most))
    return m[1].str() + (m[2] == "1" ? ": given more than once, it takes one value"
                                     : ": takes at most " + values(m[2].str())) + " (got " + m[3].str() + ")";
  if (std::regex_match(text, m, at_least))
    return m[1].str() + ": takes " + values(m[2].str()) + ", got " + m[3].str();
  if (std::regex_match(text, m, missing))
    return m[1].str() + ": needs " + values(m[2].str()) + ", got none";
  // Words no option takes (after "--" every word is positional). CLI11 lists them in the order
  // it met them, which is the line's reversed (parse_line hands it the words reversed).
  static const std::regex extras(R"(^The following arguments? (?:was|were) not expected: (.*)$)");
  if (std::regex_match(text, m, extras)) {
    std::istringstream words(m[1].str());
    const std::vector<std::string> list{std::istream_iterator<std::string>(words), std::istream_iterator<std::string>()};
    return unexpected_arguments_text({list.rbegin(), list.rend()}, separator);
  }
  return text;
}

enum class Mode { kRun, kParseOnly };

/// --quiet of the command line being run (run_cli resets it).
thread_local bool g_quiet = false;

/// Every command takes --quiet (no progress on stderr) and, where its result is a summary, --json.
/// `app` and every command below it, parents first.
std::vector<CLI::App*> command_tree(CLI::App* app) {
  std::vector<CLI::App*> chain{app};
  for (std::size_t i = 0; i < chain.size(); ++i)
    for (CLI::App* sub : chain[i]->get_subcommands([](CLI::App*) { return true; })) chain.push_back(sub);
  return chain;
}

/// A command that runs (no subcommands of its own), below the top one.
bool is_leaf_command(CLI::App* cmd) {
  return cmd->get_parent() != nullptr && cmd->get_subcommands([](CLI::App*) { return true; }).empty();
}

void quiet_everywhere(CLI::App* app) {
  for (CLI::App* cmd : command_tree(app))
    if (is_leaf_command(cmd) && cmd->get_option_no_throw("--quiet") == nullptr)
      cmd->add_flag("--quiet", g_quiet, "no progress on stderr");
}

/// Every command of `miner` registered on `app` (their callbacks write to `out`).
void add_commands(CLI::App& app, std::ostream& out) {
  app.require_subcommand(1);
  app.set_version_flag("--version", "miner 0.1.0");
  add_map_commands(app, out);
  add_traj_commands(app, out);
  add_bench_commands(app, out);
  add_plan_commands(app, out);
  add_fly_commands(app, out);
  add_heuristic_commands(app, out);
  // Hidden: the generated option reference (docs/cli-reference.md).
  app.add_subcommand("docs", "print the generated option reference (docs/cli-reference.md)")
      ->group("")
      ->callback([&out] { out << cli_reference_markdown(); });
  quiet_everywhere(&app);
  decimal_numbers(&app);
}

/// The command a line addresses and its path of command names from `app` ("miner plan").
/// `unknown` is the first word that should name a command (its command has subcommands) but
/// names none of them; empty otherwise.
CLI::App* addressed_command(CLI::App* app, const std::vector<std::string>& args, std::string& path,
                            std::string& unknown) {
  CLI::App* current = app;
  path = "miner";
  unknown.clear();
  for (const std::string& a : args) {
    if (a.empty() || a[0] == '-') break;
    const auto subs = current->get_subcommands([](CLI::App*) { return true; });
    if (subs.empty()) break;  // the rest are the command's own arguments
    CLI::App* next = nullptr;
    for (CLI::App* sub : subs)
      if (sub->get_name() == a) next = sub;
    if (!next) {
      unknown = a;
      break;
    }
    current = next;
    path += " " + a;
  }
  return current;
}

/// "miner bench frontend" for the command `cmd` below the top one.
std::string command_path(const CLI::App* cmd) {
  std::string path = cmd->get_name();
  for (const CLI::App* p = cmd->get_parent(); p != nullptr && p->get_parent() != nullptr; p = p->get_parent())
    path = p->get_name() + " " + path;
  return path;
}

/// An option-like argument of `cmd` that names no option of it (issue 20: `--mapp x` was
/// answered "--map is required" and `--planer` with no suggestion). Negative numbers are
/// values, not options; everything after "--" is positional. Empty when every option is
/// known, else the message naming it and the nearest option of the command.
std::string unknown_option(CLI::App* cmd, const std::string& path, const std::vector<std::string>& args) {
  std::vector<std::string> names{"--help", "-h"};
  if (cmd->get_parent() == nullptr) names.push_back("--version");
  for (const CLI::Option* o : cmd->get_options()) {
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : o->get_snames()) names.push_back("-" + n);
  }
  for (const std::string& a : args) {
    if (a == "--") break;
    // Option names start with a letter after their dashes; "-1" and "-1/2" are values.
    const std::size_t dashes = a.rfind("--", 0) == 0 ? 2 : 1;
    if (a.size() <= dashes || a[0] != '-' || !std::isalpha(static_cast<unsigned char>(a[dashes]))) continue;
    const std::string name = a.substr(0, a.find('='));
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    const std::string nearest = nearest_name(name, names);
    return "unknown option " + name + " for `" + path + "`" +
           (nearest.empty() ? "" : ", did you mean " + nearest + "?");
  }
  return {};
}

/// A word meant as an option but not read as one: led by a dash look-alike (an autocorrected en
/// dash, em dash or minus sign) before "--", or any word after "--" where the command takes no
/// arguments. Named first, before CLI11's complaint about what it then missed ("--map is
/// required"; eighteenth campaign F9). Empty when none.
std::string stray_option_word(CLI::App* cmd, const std::vector<std::string>& args) {
  const bool positional = !cmd->get_options([](const CLI::Option* o) { return o->get_positional(); }).empty();
  const auto separator = std::find(args.begin(), args.end(), "--");
  if (separator != args.end() && separator + 1 != args.end() && !positional)
    return unexpected_arguments_text({separator + 1, args.end()}, true);
  for (auto a = args.begin(); a != separator; ++a) {
    // "--out=" is an option given an empty value, not one waiting for the next word (eighteenth
    // campaign F24: "--out: needs a value, got the option --json").
    if (a->size() > 3 && a->rfind("--", 0) == 0 && a->back() == '=' && a->find('=') == a->size() - 1)
      return a->substr(0, a->size() - 1) + ": needs a value, got an empty one (nothing after \"=\")";
    // --version prints the version and nothing else: a word beside it is a mistake (F24).
    if (*a == "--version" && args.size() > 1)
      return "--version prints the version and takes no other argument, got " +
             std::to_string(args.size() - 1) + " more (\"" + (a == args.begin() ? args[1] : args[0]) + "\")";
  }
  for (auto a = args.begin(); a != separator; ++a)
    if (const std::string hint = dash_lookalike_hint(*a); !hint.empty()) return "unexpected argument \"" + *a + "\"; " + hint;
  return {};
}

/// A list option's value with an empty piece ("5,", ",5", "5,,6"): CLI11 drops the empty piece,
/// so `--segments 5,` ran as `--segments 5` (issue 20, seventh campaign C10). Empty when none.
std::string empty_list_piece(CLI::App* cmd, const std::vector<std::string>& args) {
  const CLI::Option* list = nullptr;  // the delimited option whose values follow
  for (const std::string& a : args) {
    if (a == "--") break;
    const std::size_t dashes = a.rfind("--", 0) == 0 ? 2 : 1;
    const bool option = a.size() > dashes && a[0] == '-' && std::isalpha(static_cast<unsigned char>(a[dashes]));
    std::string value = a;
    if (option) {
      const std::size_t eq = a.find('=');
      const CLI::Option* o = cmd->get_option_no_throw(a.substr(0, eq));
      list = o != nullptr && o->get_delimiter() != '\0' ? o : nullptr;
      if (list == nullptr || eq == std::string::npos) continue;
      value = a.substr(eq + 1);
    }
    if (list == nullptr) continue;
    const char d = list->get_delimiter();
    if (value.find(d) == std::string::npos) continue;
    if (value.front() == d || value.back() == d || value.find(std::string(2, d)) != std::string::npos)
      return list->get_name() + ": \"" + value + "\" has an empty value between its '" + std::string(1, d) +
             "' separators (give each value once, e.g. 5,12)";
  }
  return {};
}

}  // namespace

std::string cli_reference_markdown() {
  std::ostringstream sink;
  CLI::App app{"miner", "miner"};
  add_commands(app, sink);
  const auto escape = [](std::string text) {
    std::string out;
    for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
  };
  std::ostringstream md;
  md << "# `miner` options, generated\n\n"
     << "Generated from the command line's own definitions by `miner docs` (do not edit: the ctest\n"
     << "`cli reference is current` fails when this file and the program disagree). Every number's\n"
     << "range is enforced (REQ-CLI-002); prose, examples and file formats: [cli.md](cli.md).\n";
  for (CLI::App* cmd : command_tree(&app)) {
    if (!is_leaf_command(cmd) || cmd->get_group().empty()) continue;
    md << "\n## miner " << command_path(cmd) << "\n\n" << cmd->get_description() << "\n\n"
       << "| option | value | default | meaning |\n|---|---|---|---|\n";
    for (const CLI::Option* o : cmd->get_options()) {
      if (o->get_name() == "--help") continue;
      std::string names;
      for (const std::string& n : o->get_lnames()) names += (names.empty() ? "" : ", ") + ("`--" + n + "`");
      if (names.empty()) names = "`" + o->get_name() + "`";
      const std::string type = o->get_type_name();
      std::string value = type.empty() ? "flag" : type;
      if (o->get_expected_max() > 1 && o->get_expected_max() < 100) value += " x " + std::to_string(o->get_expected_max());
      else if (o->get_expected_max() >= 100) value += " ...";
      md << "| " << names << (o->get_required() ? " (required)" : "") << " | " << escape(value) << " | "
         << escape(o->get_default_str()) << " | " << escape(o->get_description()) << " |\n";
    }
  }
  return md.str();
}

std::vector<std::string> numeric_options_without_checks() {
  std::ostringstream sink;
  CLI::App app{"miner", "miner"};
  add_commands(app, sink);
  std::vector<std::string> unchecked;
  for (CLI::App* cmd : command_tree(&app)) {
    for (const CLI::Option* o : cmd->get_options()) {
      const std::string type = o->get_type_name();
      const bool integer = type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0;
      const bool real = type.rfind("FLOAT", 0) == 0;
      if (!integer && !real) continue;
      // Integer options carry kDecimalInteger and real ones kUnsignedZero (added by
      // decimal_numbers): a range is a second check.
      int checks = 0;
      for (int k = 0;; ++k) {
        try {
          (void)const_cast<CLI::Option*>(o)->get_validator(k);
          ++checks;
        } catch (const CLI::OptionNotFound&) {
          break;
        }
      }
      if (checks < 2) unchecked.push_back(command_path(cmd) + " " + o->get_name());
    }
  }
  return unchecked;
}

void check_region_dims(const CLI::App* cmd, const std::vector<int>& dims) {
  const CLI::Option* o = cmd->get_option("--dims");
  if (o->count() == 0 || dims.size() != 3) return;
  try {
    (void)plan::HeuristicRegion::cell_count(Eigen::Vector3i(dims[0], dims[1], dims[2]));
  } catch (const Error& e) {
    throw CLI::ValidationError(o->get_name(), e.what());
  }
}

std::string command_line(const CLI::App* cmd, const std::vector<std::string>& always) {
  // A value a shell would split or expand is quoted, so the line can be pasted back.
  const auto word = [](const std::string& v) {
    if (!v.empty() && v.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./,:=+@%") ==
                          std::string::npos)
      return v;
    std::string quoted = "'";
    for (const char c : v) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
  };
  std::string line = "miner " + command_path(cmd);
  for (const CLI::Option* o : cmd->get_options()) {
    const std::string name = o->get_name();
    if (name == "--help" || name == "--quiet" || name == "--json") continue;  // no effect on the result
    const bool given = o->count() > 0;
    if (!given && std::find(always.begin(), always.end(), name) == always.end()) continue;
    if (o->get_expected_max() == 0) {  // a flag: its name says it
      if (given) line += " " + name;
      continue;
    }
    std::vector<std::string> values = given ? o->results() : std::vector<std::string>{o->get_default_str()};
    line += " " + name;
    if (o->get_delimiter() != '\0' && values.size() > 1) {
      std::string joined;
      for (const auto& v : values) joined += (joined.empty() ? "" : std::string(1, o->get_delimiter())) + v;
      line += " " + word(joined);
    } else {
      for (const auto& v : values) line += " " + word(v);
    }
  }
  return line;
}

namespace {

constexpr const char* kAppDescription = "miner — MINER-RRT* quadrotor planning and flight stack";

/// Every command and option on `app`; commands print to `out`.
void build_app(CLI::App& app, std::ostream& out, Mode mode) {
  add_commands(app, out);
  app.parse_complete_callback([&app, mode] {
    check_no_option_as_value(&app);
    check_list_values_distinct(&app);
    check_outputs_against_inputs(&app);
    if (mode == Mode::kParseOnly) throw ParsedOnly{};
  });
}

/// One command line on a built app. CLI11 clears an app's parse state (option results,
/// counts, chosen subcommands) at the start of every parse, so an app may parse many lines.
int parse_line(CLI::App& app, const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  g_quiet = false;
  std::vector<std::string> line = args;  // as CLI11 is given it
  {
    std::string path, unknown_command;
    CLI::App* cmd = addressed_command(&app, args, path, unknown_command);
    // An unknown command is named, with the commands there are and the nearest one (CLI11
    // alone says only "A subcommand is required").
    std::vector<std::string> names;  // the commands below cmd
    std::string list;
    for (CLI::App* sub : cmd->get_subcommands([](CLI::App*) { return true; })) {
      names.push_back(sub->get_name());
      list += (list.empty() ? "" : ", ") + sub->get_name();
    }
    if (!unknown_command.empty()) {
      const std::string nearest = nearest_name(unknown_command, names);
      err << "miner: usage error: unknown command \"" << unknown_command << "\" for `" << path << "`"
          << (nearest.empty() ? "" : ", did you mean \"" + nearest + "\"?") << " (commands: " << list << ")\n"
          << "run '" << path << " --help' for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    // --help anywhere before "--" prints the command's help, whatever else the line holds
    // (issue 20, fourth campaign: `astar --help --radius -5` was a usage error about --radius,
    // since CLI11 checks values before it looks for the help flag).
    for (const std::string& a : args) {
      if (a == "--") break;
      if (a == "--help" || a == "-h") {
        app.clear();  // an earlier line's chosen subcommands would take over help()
        out << cmd->help();
        return 0;
      }
    }
    // A group without its command (`miner map`) is named with the commands it has (eighteenth
    // campaign F24: CLI11's "A subcommand is required").
    if (cmd != &app && !names.empty()) {
      err << "miner: usage error: `" << path << "` needs a command (commands: " << list << ")\n"
          << "run '" << path << " --help' for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    const std::string unknown = unknown_option(cmd, path, args);
    if (!unknown.empty()) {
      err << "miner: usage error: " << unknown << "\nrun '" << path << " --help' for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    if (const std::string empty = empty_list_piece(cmd, args); !empty.empty()) {
      err << "miner: usage error: " << empty << "\nrun '" << path << " --help' for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    if (const std::string stray = stray_option_word(cmd, args); !stray.empty()) {
      err << "miner: usage error: " << stray << "\nrun '" << path << " --help' for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    // After "--" every word is an argument (`bench merge p1.json -- -p0.json`): CLI11 leaves
    // such words unread once the positional has values (eighteenth campaign F19: "the command
    // takes none"), so the separator is dropped and a word that looks like an option is given
    // as the path it names (./-p0.json).
    if (const auto separator = std::find(line.begin(), line.end(), "--"); separator != line.end()) {
      for (auto it = separator + 1; it != line.end(); ++it)
        if (!it->empty() && (*it)[0] == '-') *it = "./" + *it;
      line.erase(separator);
    }
  }
  // CLI11 parses in reverse order of the vector it is given.
  std::vector<std::string> reversed(line.rbegin(), line.rend());
  try {
    app.parse(reversed);
  } catch (const ParsedOnly&) {
    return 0;
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
    // An option left without its value took the next option as it (`dataset --merge --out d`),
    // and a requirement CLI11 checks before the parse completes then blamed the option taken:
    // "--out is required" (issue 20, sixth campaign U11). The option without a value is the fault.
    std::string text = e.what();
    try {
      check_no_option_as_value(&app);
    } catch (const CLI::ParseError& first) {
      text = first.what();
    }
    err << "miner: usage error: "
        << plain_usage_text(text, std::find(args.begin(), args.end(), "--") != args.end()) << "\n";
    err << "run 'miner --help' (or 'miner <command> --help') for usage\n";
    return static_cast<int>(ExitCode::kUsage);
  } catch (const Error& e) {
    // A command-line fault found by the command (exit 2) reads as one, like the parser's.
    if (e.code() == ExitCode::kUsage) {
      err << "miner: usage error: " << e.what() << "\n"
          << "run 'miner --help' (or 'miner <command> --help') for usage\n";
      return static_cast<int>(ExitCode::kUsage);
    }
    err << "miner: error: " << e.what() << "\n";
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    err << "miner: error: out of memory\n";
    return static_cast<int>(ExitCode::kInvalidInput);
  } catch (const std::exception& e) {
    err << "miner: internal error: " << json_error_text(e) << "\n";
    return static_cast<int>(ExitCode::kInvalidInput);
  }
  return 0;
}

int cli_main(const std::vector<std::string>& args, std::ostream& out, std::ostream& err, Mode mode) {
  CLI::App app{kAppDescription, "miner"};
  build_app(app, out, mode);
  return parse_line(app, args, out, err);
}

}  // namespace

struct ArgumentChecker::Impl {
  std::ostringstream unused;  // what a command would print: none runs in this mode
  CLI::App app{kAppDescription, "miner"};
  Impl() { build_app(app, unused, Mode::kParseOnly); }
};

ArgumentChecker::ArgumentChecker() : impl_(std::make_unique<Impl>()) {}
ArgumentChecker::~ArgumentChecker() = default;

int ArgumentChecker::check(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  return parse_line(impl_->app, args, out, err);
}

std::ostream* progress_stream() { return g_quiet ? nullptr : terminal_stream(); }

void report(bool json, const Json& doc, const std::string& human, std::ostream& out) {
  if (json) out << dump_json(doc);
  else out << human;
}

int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  // Standard output is text (JSON, tables, "wrote <path>"): a control byte in a path or name
  // the user gave reaches the terminal as \xNN, as on stderr (issue 20, eighth campaign U4: an
  // escape sequence in --out was echoed raw). JSON escapes its own control bytes already.
  std::ostringstream text;
  const int code = cli_main(args, text, err, Mode::kRun);
  out << printable_text(text.str());
  return code;
}

int check_cli_arguments(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  return cli_main(args, out, err, Mode::kParseOnly);
}

}  // namespace miner::cli
