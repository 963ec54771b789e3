#include "miner/pipeline/run_folder.hpp"

#include <filesystem>
#include <set>

#include "miner/traj/problem_io.hpp"

namespace miner::pipeline {

FolderMarker run_folder_marker() {
  static const std::set<std::string> kNames = {"scenario.json", "map.json",       "region.json",    "tree.json", "path.json",
                                               "trajectory.json", "flight_log.csv", "report.html", "summary.json"};
  FolderMarker marker{"summary.json", flight::kSummaryFormat};
  marker.own_name = [](const std::string& name) { return kNames.count(name) > 0; };
  return marker;
}

std::string run_folder_name(const std::string& dir) {
  const std::filesystem::path p = named_folder(dir);
  // "." normalises to itself, "./" to "."; an empty result is not a folder name, left to the writer.
  return p.empty() ? dir : p.string();
}

std::string default_run_folder(const Scenario& s) { return "runs/" + s.name + "-seed" + std::to_string(s.seed); }

std::optional<std::string> run_folder_conflict(const std::string& dir, const Json& scenario_document,
                                               const std::string& base_dir) {
  for (const std::string& input : scenario_inputs(scenario_document, base_dir))
    if (is_same_or_inside(dir, input)) return input;
  return std::nullopt;
}

namespace {
Json points(const Eigen::MatrixX3d& m) {
  Json p = Json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) p.push_back(vec3_json(m.row(i).transpose()));
  return p;
}
}  // namespace

RunFolder::RunFolder(std::string dir, const Json& scenario_as_flown, const Scenario& s, const ReferencePlan& reference, const flight::FlightResult& flight,
                     std::vector<std::pair<std::string, double>> stage_ms)
    : dir_(run_folder_name(dir)) {
  summary_ = flight.summary;
  summary_["run_folder"] = dir_;
  // Wall-clock times only when given (`fly --timing`): without them the folder's bytes are the
  // scenario's and the seed's alone.
  if (!stage_ms.empty()) {
    Json stages = Json::object();
    for (const auto& [name, ms] : stage_ms) stages[name] = ms;
    summary_["stage_ms"] = stages;
  }

  Json path{{"source", reference.source}, {"points", points(reference.path)}};
  files_.emplace_back("scenario.json", dump_json(scenario_as_flown));
  files_.emplace_back("map.json", dump_json(s.map->to_json()));
  if (reference.region) {
    files_.emplace_back("region.json", dump_json(reference.region->to_json()));
    path["planned"] = points(reference.planned_path);
    Json vertices = Json::array();
    for (const auto& v : reference.tree_vertices) vertices.push_back(vec3_json(v));
    files_.emplace_back("tree.json", dump_json(Json{{"vertices", vertices}, {"parents", reference.tree_parents}}));
  }
  files_.emplace_back("path.json", dump_json(path));
  files_.emplace_back("trajectory.json", dump_json(traj::answer_to_json(reference.trajectory)));
  files_.emplace_back("flight_log.csv", flight::flight_log_csv(flight));
}

void RunFolder::add_page(const std::string& name, std::string content, const std::string& key) {
  files_.emplace_back(name, std::move(content));
  summary_[key] = dir_ + "/" + name;
}

std::vector<std::string> RunFolder::names() const {
  std::vector<std::string> n;
  for (const auto& f : files_) n.push_back(f.first);
  n.emplace_back("summary.json");
  return n;
}

void RunFolder::write() const {
  auto files = files_;
  files.emplace_back("summary.json", dump_json(summary_));
  write_folder_atomic(dir_, files, run_folder_marker());
}

}  // namespace miner::pipeline
