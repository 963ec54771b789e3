#pragma once
/// \file
/// The run folder of one `miner fly` (REQ-FLIGHT-009): what a run keeps, file by file, and
/// how it is written (as a whole: a failed run leaves an earlier folder as it was, REQ-CLI-003).
///
///   scenario.json    the scenario as flown, self-contained (map and vehicle inlined, other
///                    paths absolute), so `miner fly --scenario RUN/scenario.json` repeats it
///   map.json         the map
///   region.json      the heuristic region the planner sampled   (planner references only)
///   tree.json        the planner's final tree                    (planner references only)
///   path.json        the path MINCO went through ("points"), and the planned one ("planned")
///   trajectory.json  the MINCO answer (`miner traj solve`'s format)
///   flight_log.csv   the 100 Hz flight log, units in its header
///   ...              pages others add (the report module's report.html)
///   summary.json     the flight's summary + run_folder, stage_ms and the pages' paths: last

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "miner/core/json_io.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"

namespace miner::pipeline {

/// What tells an earlier run folder (REQ-CORE-004): summary.json of flight::kSummaryFormat,
/// and nothing in it but the names above (report.html the one page added). A user's notes.json
/// kept in it makes `fly --out` refuse the folder rather than delete the file (seventeenth
/// campaign F31).
FolderMarker run_folder_marker();

/// The folder `dir` names, as the run folder records it: "run/", "run/." and "run//" name run
/// (seventeenth campaign F7: summary.json said "runA//report.html" for --out runA/).
std::string run_folder_name(const std::string& dir);

/// runs/<scenario name>-seed<seed>: where a run goes unless told otherwise.
std::string default_run_folder(const Scenario& s);

/// The first file the scenario document reads that lies in (or is) `dir`: a run folder
/// replaces its contents whole, so it must hold none of its inputs. Empty when none does.
std::optional<std::string> run_folder_conflict(const std::string& dir, const Json& scenario_document,
                                               const std::string& base_dir);

class RunFolder {
 public:
  /// The run's files. `scenario_as_flown` is stored as scenario.json: the embedded default's
  /// document, or a file's self_contained_scenario().
  RunFolder(std::string dir, const Json& scenario_as_flown, const Scenario& scenario,
            const ReferencePlan& reference, const flight::FlightResult& flight,
            std::vector<std::pair<std::string, double>> stage_ms);
  /// Adds a page (e.g. "report.html"); the summary names it under `key`.
  void add_page(const std::string& name, std::string content, const std::string& key);
  const std::string& dir() const { return dir_; }
  const Json& summary() const { return summary_; }
  /// Every file name in writing order (summary.json last).
  std::vector<std::string> names() const;
  /// Writes the folder atomically.
  void write() const;

 private:
  std::string dir_;
  std::vector<std::pair<std::string, std::string>> files_;
  Json summary_;
};

}  // namespace miner::pipeline
