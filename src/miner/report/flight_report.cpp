#include "miner/report/flight_report.hpp"

#include <cmath>
#include <cstdio>
#include <map>

#include "miner/core/error.hpp"
#include "miner/report/svg_plot.hpp"

namespace miner::report {

extern const unsigned char kThreeJs[];
extern const std::size_t kThreeJsSize;
extern const unsigned char kOrbitControlsJs[];
extern const std::size_t kOrbitControlsJsSize;
extern const unsigned char kViewerJs[];
extern const std::size_t kViewerJsSize;

std::string three_js_source() {
  return std::string(reinterpret_cast<const char*>(kThreeJs), kThreeJsSize) + "\n" +
         std::string(reinterpret_cast<const char*>(kOrbitControlsJs), kOrbitControlsJsSize);
}

std::string viewer_js_source() { return std::string(reinterpret_cast<const char*>(kViewerJs), kViewerJsSize); }

namespace {

/// 1 mm: far below anything the view can show, and it keeps the file small.
double mm(double v) { return std::round(v * 1000.0) / 1000.0; }

void push3(Json& flat, const Eigen::Vector3d& p) {
  for (int a = 0; a < 3; ++a) flat.push_back(mm(p[a]));
}

/// Index of a log column by name (the log's layout is flight_log_columns()).
std::size_t column(const std::string& name) {
  const auto& c = flight::flight_log_columns();
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c[i] == name) return i;
  throw Error("flight report: the flight log has no column \"" + name + "\"");
}

Eigen::Vector3d log3(const std::vector<double>& row, std::size_t first) {
  return {row[first], row[first + 1], row[first + 2]};
}

/// Every `step` seconds of the log (and its last row).
std::vector<std::size_t> thin_log(const flight::FlightResult& f, double step) {
  std::vector<std::size_t> rows;
  double next = -1.0;
  for (std::size_t i = 0; i < f.log.size(); ++i)
    if (f.log[i][0] >= next - 1e-9 || i + 1 == f.log.size()) {
      rows.push_back(i);
      next = f.log[i][0] + step;
    }
  return rows;
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string plots(const flight::FlightResult& f) {
  const std::size_t t = column("t"), ref = column("ref_x"), ref_v = column("ref_vx"), truth = column("true_x"),
                    truth_v = column("true_vx"), est = column("est_x"), thrust = column("cmd_thrust_pct");
  Series err{"|p - p_ref| (truth)", "#d62728", {}, {}}, est_err{"|p_est - p| (EKF)", "#9467bd", {}, {}};
  Series v_ref{"reference", "#1f77b4", {}, {}}, v_true{"flown", "#2ca02c", {}, {}};
  Series thr{"thrust command", "#ff7f0e", {}, {}};
  for (std::size_t i : thin_log(f, 0.02)) {
    const auto& row = f.log[i];
    const double time = row[t];
    err.x.push_back(time), err.y.push_back((log3(row, truth) - log3(row, ref)).norm());
    est_err.x.push_back(time), est_err.y.push_back((log3(row, est) - log3(row, truth)).norm());
    v_ref.x.push_back(time), v_ref.y.push_back(log3(row, ref_v).norm());
    v_true.x.push_back(time), v_true.y.push_back(log3(row, truth_v).norm());
    thr.x.push_back(time), thr.y.push_back(row[thrust]);
  }
  return svg_line_plot({"Tracking and estimation error", "time (s)", "error (m)"}, {err, est_err}) +
         svg_line_plot({"Speed", "time (s)", "speed (m/s)"}, {v_ref, v_true}) +
         svg_line_plot({"Thrust", "time (s)", "thrust (% of max)"}, {thr});
}

}  // namespace

Json scene_json(const FlightReportInput& in) {
  const auto& map = *in.scenario.map;
  Json obstacles = Json::array();
  std::vector<world::Box> boxes = map.obstacles();
  int block = 0;
  if (map.voxels()) {
    // A real scan has ~1e5 occupied voxels: the view draws them in coarser blocks.
    constexpr std::size_t kMaxVoxelBoxes = 4000;
    const auto voxels = world::decimated_occupied_boxes(map.voxels()->layer(), kMaxVoxelBoxes, &block);
    boxes.insert(boxes.end(), voxels.begin(), voxels.end());
  }
  for (const auto& b : boxes)
    obstacles.push_back({mm(b.min.x()), mm(b.min.y()), mm(b.min.z()), mm(b.max.x()), mm(b.max.y()), mm(b.max.z())});
  Json scene{{"bounds", {{"min", Json::array()}, {"max", Json::array()}}},
             {"obstacles", obstacles},
             {"radius", in.scenario.vehicle.radius},
             {"start", Json::array()},
             {"goal", Json::array()}};
  if (map.voxels()) scene["voxel_block_m"] = block * map.resolution();
  push3(scene["bounds"]["min"], map.bounds().min);
  push3(scene["bounds"]["max"], map.bounds().max);
  push3(scene["start"], in.scenario.start);
  push3(scene["goal"], in.scenario.goal);
  const auto& r = in.reference;
  if (r.region) {
    Json centres = Json::array();
    const Eigen::Vector3i dims = r.region->dims();
    const Eigen::Vector3d cell = r.region->cell_size();
    for (std::size_t index : r.region->cells()) {
      const auto i = static_cast<int>(index % static_cast<std::size_t>(dims.x()));
      const auto j = static_cast<int>(index / static_cast<std::size_t>(dims.x()) % static_cast<std::size_t>(dims.y()));
      const auto k = static_cast<int>(index / static_cast<std::size_t>(dims.x() * dims.y()));
      push3(centres, r.region->bounds().min + (Eigen::Vector3d(i, j, k) + Eigen::Vector3d::Constant(0.5)).cwiseProduct(cell));
    }
    scene["region"] = {{"source", r.region->source()}, {"cell", {cell.x(), cell.y(), cell.z()}}, {"centres", centres}};
  }
  Json tree = Json::array();
  for (std::size_t v = 0; v < r.tree_vertices.size(); ++v) {
    const long parent = r.tree_parents[v];
    if (parent < 0) continue;
    push3(tree, r.tree_vertices[static_cast<std::size_t>(parent)]);
    push3(tree, r.tree_vertices[v]);
  }
  scene["tree"] = tree;
  Json planned = Json::array(), path = Json::array(), trajectory = Json::array(), flown = Json::array();
  for (Eigen::Index i = 0; i < r.planned_path.rows(); ++i) push3(planned, r.planned_path.row(i).transpose());
  for (Eigen::Index i = 0; i < r.path.rows(); ++i) push3(path, r.path.row(i).transpose());
  const double T = r.trajectory.total_duration();
  const int samples = static_cast<int>(std::ceil(T / kTrajectoryStep));
  for (int k = 0; k <= samples; ++k) push3(trajectory, r.trajectory.evaluate(std::min(T, k * kTrajectoryStep)));
  const std::size_t truth = column("true_x");
  for (std::size_t i : thin_log(in.flight, kFlownStep)) push3(flown, log3(in.flight.log[i], truth));
  scene["planned_path"] = planned;
  scene["path"] = path;
  scene["trajectory"] = trajectory;
  scene["flown"] = flown;
  return scene;
}

std::string render_flight_report(const FlightReportInput& in) {
  const auto& s = in.scenario;
  const auto& f = in.flight;
  const auto& r = in.reference;
  const Json scene_doc = scene_json(in);
  std::string scene = scene_doc.dump();
  // "</" cannot appear inside a <script> element's text.
  for (std::size_t p = scene.find("</"); p != std::string::npos; p = scene.find("</", p + 2)) scene.replace(p, 2, "<\\/");

  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>MINER flight report: " +
       html_escape(s.name) + " (seed " + std::to_string(s.seed) + ")</title>\n";
  h += "<style>\nbody{font-family:sans-serif;margin:16px;color:#222;max-width:1240px}\n"
       "#view3d{width:1200px;height:640px;border:1px solid #ccc;position:relative}\n"
       "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\n"
       "th{background:#f0f0f0}td:first-child,th:first-child{text-align:left}\n"
       ".plots svg{margin:4px;border:1px solid #eee}\n#layers label{margin-right:10px}\n"
       ".legend span{display:inline-block;margin-right:12px}\n</style>\n</head>\n<body>\n";
  h += "<h1>MINER flight report: " + html_escape(s.name) + "</h1>\n";
  h += "<p>Seed " + std::to_string(s.seed) + ", reference from " + html_escape(r.source);
  if (r.region) h += " (MINER RRT* sampling the " + html_escape(r.region->source()) + " region)";
  h += ", minimum-" + std::string(s.order == 3 ? "jerk" : "snap") + " MINCO trajectory, " +
       std::to_string(r.trajectory.segments()) + " segments, " + fixed(r.trajectory.total_duration(), 2) +
       " s. Goal " + (f.goal_reached ? "reached" : "NOT reached") + " (" + fixed(f.final_position_error, 3) +
       " m off), " + std::to_string(f.collisions) + " collisions.</p>\n";
  h += "<h2>3D view</h2>\n<div id=\"layers\"></div>\n<div id=\"view3d\"></div>\n"
       "<p class=\"legend\"><span style=\"color:#8c8c8c\">&#9632; obstacles</span>"
       "<span style=\"color:#f2b134\">&#9632; heuristic region</span><span style=\"color:#6baed6\">&#9632; RRT* tree</span>"
       "<span style=\"color:#9467bd\">&#9632; planned path</span><span style=\"color:#d62728\">&#9632; repaired path</span>"
       "<span style=\"color:#1f77b4\">&#9632; trajectory</span><span style=\"color:#2ca02c\">&#9632; flown (truth)</span>"
       " Drag to orbit, scroll to zoom, right-drag to pan.</p>\n";
  if (const auto* v = s.map->voxels()) {
    const auto& src = *s.map->voxel_source();
    h += "<p>Voxel map " + html_escape(src.file) + " (SHA-256 " + src.sha256.substr(0, 16) + "...), " +
         std::to_string(v->layer().count(world::VoxelState::kOccupied)) + " occupied voxels of " +
         fixed(v->layer().resolution(), 3) + " m, drawn as blocks of " + fixed(scene_doc["voxel_block_m"].get<double>(), 3) +
         " m; unknown space treated as " + world::to_string(v->policy()) + ".</p>\n";
  }
  h += "<p id=\"miner-status\" data-state=\"loading\">loading the 3D view...</p>\n";
  h += "<h2>Tracking (the paper's MSE table)</h2>\n<table><tr><th>Env.</th><th>Pos. Err. x</th><th>Pos. Err. y</th>"
       "<th>Pos. Err. z</th><th>Vel. Err. x</th><th>Vel. Err. y</th><th>Vel. Err. z</th></tr>\n<tr><td>" +
       html_escape(s.name) + "</td>";
  for (int a = 0; a < 3; ++a) h += "<td>" + fixed(f.position_mse[a], 4) + "</td>";
  for (int a = 0; a < 3; ++a) h += "<td>" + fixed(f.velocity_mse[a], 4) + "</td>";
  h += "</tr></table>\n<p>MSE in m<sup>2</sup> and (m/s)<sup>2</sup>, truth against the reference. Maximum position "
       "error " + fixed(f.max_position_error, 3) + " m, EKF estimate RMSE " + fixed(f.estimation_rmse, 3) +
       " m, pose measurements fused " + std::to_string(f.fused) + ", rejected " + std::to_string(f.rejected) + ".</p>\n";
  h += "<h2>Over time</h2>\n<div class=\"plots\">\n" + plots(f) + "</div>\n";
  h += "<h2>Stage timing</h2>\n<table><tr><th>stage</th><th>wall clock (ms)</th></tr>\n";
  double total = 0.0;
  for (const auto& [name, ms] : in.stage_ms) {
    h += "<tr><td>" + html_escape(name) + "</td><td>" + fixed(ms, 2) + "</td></tr>\n";
    total += ms;
  }
  h += "<tr><th>total</th><th>" + fixed(total, 2) + "</th></tr></table>\n";
  if (r.planner_iterations > 0)
    h += "<p>Planner: " + std::to_string(r.planner_iterations) + " iterations, tree of " +
         std::to_string(r.tree_vertices.size()) + " vertices.</p>\n";
  h += "<script id=\"miner-scene\" type=\"application/json\">" + scene + "</script>\n";
  h += "<script>\n" + three_js_source() + "\n</script>\n";
  h += "<script>\n" + viewer_js_source() + "\n</script>\n</body>\n</html>\n";
  return h;
}

}  // namespace miner::report
