#include "miner/report/flight_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "miner/core/error.hpp"
#include "miner/core/units.hpp"
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

/// Index of a log column by name, or -1 when the log has none (flight_log_columns() grows:
/// every plot, band and event looks its columns up and is left out when one is absent).
long find_column(const std::string& name) {
  const auto& c = flight::flight_log_columns();
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c[i] == name) return static_cast<long>(i);
  return -1;
}

/// Index of a column the report cannot do without.
std::size_t column(const std::string& name) {
  const long i = find_column(name);
  if (i < 0) throw Error("flight report: the flight log has no column \"" + name + "\"");
  return static_cast<std::size_t>(i);
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

constexpr double kDeg = rad2deg(1.0);  // degrees per radian (core/units.hpp)

/// The thinned log as named columns: lookups that tolerate an absent column.
struct Log {
  const flight::FlightResult& f;
  std::vector<std::size_t> rows;
  bool has(const std::string& name) const {
    const long i = find_column(name);
    return i >= 0 && !f.log.empty() && static_cast<std::size_t>(i) < f.log.front().size();
  }
  std::vector<double> get(const std::string& name, double scale = 1.0) const {
    std::vector<double> v;
    if (!has(name)) return v;
    const auto c = static_cast<std::size_t>(find_column(name));
    v.reserve(rows.size());
    for (std::size_t i : rows) v.push_back(f.log[i][c] * scale);
    return v;
  }
};

/// An angle in degrees with the line broken where it wraps (+-180).
std::vector<double> unwrap_break(std::vector<double> a) {
  for (std::size_t i = 1; i < a.size(); ++i)
    if (std::abs(a[i] - a[i - 1]) > 180.0) a[i - 1] = NAN;
  return a;
}

/// The plots' colours: reference, flown (truth), EKF estimate, command.
constexpr const char* kRefColor = "#1f77b4";
constexpr const char* kTrueColor = "#2ca02c";
constexpr const char* kEstColor = "#9467bd";
constexpr const char* kCmdColor = "#ff7f0e";

PlotAxes small(const std::string& id, const std::string& title, const std::string& y_label) {
  PlotAxes a{title, "time (s)", y_label};
  a.width = 392;
  a.height = 220;
  a.id = id;
  return a;
}

/// Intervals in which a 0/1 column of the full-rate log is 1.
std::vector<std::pair<double, double>> intervals(const flight::FlightResult& f, const std::string& name) {
  std::vector<std::pair<double, double>> out;
  const long c = find_column(name);
  if (c < 0) return out;
  bool on = false;
  double t0 = 0.0;
  for (const auto& row : f.log) {
    if (static_cast<std::size_t>(c) >= row.size()) return out;
    const bool now = row[static_cast<std::size_t>(c)] > 0.5;
    if (now && !on) t0 = row[0];
    if (!now && on) out.emplace_back(t0, row[0]);
    on = now;
  }
  if (on) out.emplace_back(t0, f.log.back()[0]);
  return out;
}

struct EventKind {
  const char* column;
  const char* name;
  const char* color;
};
/// The event timeline's lanes, in order; a lane whose column the log lacks is left out.
constexpr EventKind kEvents[] = {{"failsafe", "failsafe", "#d62728"},
                                 {"saturated", "thrust/tilt saturation", "#ff7f0e"},
                                 {"pose_lost", "pose dropout", "#9467bd"},
                                 {"collision", "collision", "#000000"}};

std::string plots(const flight::FlightResult& f) {
  const std::size_t ref = column("ref_x"), ref_v = column("ref_vx"), truth = column("true_x"),
                    truth_v = column("true_vx"), est = column("est_x");
  // 600 points at most per line (a plot is ~330 px wide): a long flight keeps the file small.
  const double duration = f.log.empty() ? 0.0 : f.log.back()[0];
  const Log log{f, thin_log(f, std::max(kPlotStep, duration / kMaxPlotPoints))};
  const auto t = log.get("t");
  std::string h;
  auto section = [&](const std::string& title, const std::string& body) {
    if (!body.empty()) h += "<h3>" + title + "</h3>\n<div class=\"plots\">\n" + body + "</div>\n";
  };
  // Reference, flown and estimated position and velocity per axis.
  const char* axis[] = {"x", "y", "z"};
  for (const std::string kind : {"position", "velocity"}) {
    std::string body;
    const bool pos = kind == "position";
    for (int a = 0; a < 3; ++a) {
      const std::string name = pos ? std::string(axis[a]) : std::string("v") + axis[a];
      Series r{"reference", kRefColor, t, log.get("ref_" + name), "5 3"};
      Series tr{"flown (truth)", kTrueColor, t, log.get("true_" + name)};
      Series e{"EKF estimate", kEstColor, t, log.get("est_" + name)};
      std::vector<Series> ss;
      // The estimate first, the reference (dashed) last: where they agree to a pixel the
      // dashes still show the truth between them.
      for (auto* s : {&e, &tr, &r})
        if (!s->y.empty()) ss.push_back(*s);
      if (ss.empty()) continue;
      body += svg_line_plot(small("plot-" + kind + "-" + axis[a], std::string(pos ? "Position " : "Velocity ") + axis[a],
                                  name + (pos ? " (m)" : " (m/s)")),
                            ss);
    }
    section(pos ? "Position: reference vs flown" : "Velocity: reference vs flown", body);
  }
  {  // Attitude in degrees: truth, estimate, command (and the reference yaw when logged).
    std::string body;
    const char* att[] = {"roll", "pitch", "yaw"};
    for (int a = 0; a < 3; ++a) {
      const std::string n = att[a];
      std::vector<Series> ss;
      if (log.has("est_" + n)) ss.push_back({"EKF estimate", kEstColor, t, unwrap_break(log.get("est_" + n, kDeg))});
      if (log.has("true_" + n)) ss.push_back({"truth", kTrueColor, t, unwrap_break(log.get("true_" + n, kDeg))});
      if (log.has("cmd_" + n)) ss.push_back({"command", kCmdColor, t, unwrap_break(log.get("cmd_" + n, kDeg)), "4 2"});
      if (a == 2 && log.has("ref_yaw")) ss.push_back({"reference", kRefColor, t, unwrap_break(log.get("ref_yaw", kDeg)), "5 3"});
      if (!ss.empty()) body += svg_line_plot(small("plot-attitude-" + n, "Attitude: " + n, n + " (deg)"), ss);
    }
    if (log.has("cmd_yaw_rate"))
      body += svg_line_plot(small("plot-yaw-rate", "Yaw rate command", "yaw rate (deg/s)"),
                            {{"command", kCmdColor, t, log.get("cmd_yaw_rate", kDeg)}});
    section("Attitude", body);
  }
  {  // EKF: estimate error per axis against its +-3 sigma (when the log has the EKF's sigma).
    std::string body;
    for (int a = 0; a < 3; ++a) {
      const std::string n = axis[a];
      const auto e = log.get(std::string("est_") + n), tr = log.get(std::string("true_") + n);
      if (e.empty() || tr.empty()) continue;
      std::vector<double> err(e.size());
      for (std::size_t i = 0; i < e.size(); ++i) err[i] = e[i] - tr[i];
      std::vector<Series> ss;
      std::string title = "EKF error " + n;
      if (log.has("est_sigma_" + n)) {
        auto hi = log.get("est_sigma_" + n, 3.0), lo = hi;
        for (double& v : lo) v = -v;
        ss.push_back({"+-3 sigma", kEstColor, t, hi, {}, lo});
        title += " and +-3 sigma";
      }
      ss.push_back({"estimate - truth", "#d62728", t, err});
      body += svg_line_plot(small("plot-ekf-" + n, title, "error (m)"), ss);
    }
    section("State estimate (EKF)", body);
  }
  {  // The vehicle: rotor speeds, thrust, battery, wind.
    std::string body;
    std::vector<Series> rotors;
    const char* rotor_colors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"};
    for (int k = 0; k < 4; ++k) {
      const std::string n = "rotor_" + std::to_string(k);
      if (log.has(n)) rotors.push_back({"rotor " + std::to_string(k), rotor_colors[k], t, log.get(n)});
    }
    if (!rotors.empty()) body += svg_line_plot(small("plot-rotors", "Rotor speeds", "speed (rad/s)"), rotors);
    if (log.has("cmd_thrust_pct"))
      body += svg_line_plot(small("plot-thrust", "Thrust", "thrust (% of max)"),
                            {{"thrust command", kCmdColor, t, log.get("cmd_thrust_pct")}});
    // The battery's voltage when the flight modelled one (the column is 0 without a battery).
    if (log.has("battery_v")) {
      const auto volts = log.get("battery_v");
      if (std::any_of(volts.begin(), volts.end(), [](double v) { return v > 0.0; }))
        body += svg_line_plot(small("plot-battery", "Battery", "voltage (V)"), {{"battery", "#17becf", t, volts}});
    }
    std::vector<Series> wind;
    for (int a = 0; a < 3; ++a)
      if (log.has(std::string("wind_") + axis[a]))
        wind.push_back({std::string("wind ") + axis[a], rotor_colors[a], t, log.get(std::string("wind_") + axis[a])});
    if (!wind.empty()) body += svg_line_plot(small("plot-wind", "Wind", "wind (m/s)"), wind);
    section("Vehicle", body);
  }
  {  // Error and speed norms.
    Series err{"|p - p_ref| (truth)", "#d62728", t, {}}, est_err{"|p_est - p| (EKF)", kEstColor, t, {}};
    Series v_ref{"reference", kRefColor, t, {}, "5 3"}, v_true{"flown", kTrueColor, t, {}};
    for (std::size_t i : log.rows) {
      const auto& row = f.log[i];
      err.y.push_back((log3(row, truth) - log3(row, ref)).norm());
      est_err.y.push_back((log3(row, est) - log3(row, truth)).norm());
      v_ref.y.push_back(log3(row, ref_v).norm());
      v_true.y.push_back(log3(row, truth_v).norm());
    }
    // The tracking error per axis: what the position plots cannot show at their scale.
    std::vector<Series> per_axis;
    const char* axis_colors[] = {"#d62728", "#2ca02c", "#1f77b4"};
    for (std::size_t a = 0; a < 3; ++a) {
      Series e{std::string(axis[a]) + " - " + axis[a] + "_ref", axis_colors[a], t, {}};
      for (std::size_t i : log.rows) e.y.push_back(f.log[i][truth + a] - f.log[i][ref + a]);
      per_axis.push_back(std::move(e));
    }
    section("Errors and speed",
            svg_line_plot(small("plot-error", "Tracking and estimation error", "error (m)"), {err, est_err}) +
                svg_line_plot(small("plot-tracking-axes", "Tracking error per axis (truth - reference)", "error (m)"),
                              per_axis) +
                svg_line_plot(small("plot-speed", "Speed", "speed (m/s)"), {v_ref, v_true}));
  }
  return h;
}

std::string timeline(const flight::FlightResult& f) {
  std::vector<EventLane> lanes;
  for (const auto& k : kEvents)
    if (find_column(k.column) >= 0) lanes.push_back({k.name, k.color, intervals(f, k.column)});
  if (lanes.empty() || f.log.empty()) return {};
  PlotAxes a{"Events", "time (s)", ""};
  a.width = 1200;
  a.id = "plot-events";
  return svg_event_timeline(a, lanes, f.log.back()[0]);
}

/// A column of the thinned log rounded for the viewer (1 mm, 1e-4 rad, 1 ms).
Json json_column(const Log& log, const std::string& name, double quantum) {
  Json v = Json::array();
  for (double x : log.get(name)) v.push_back(std::isfinite(x) ? std::round(x / quantum) * quantum : 0.0);
  return v;
}

/// JSON text made safe inside a <script> element: "</" cannot appear there.
std::string script_text(std::string text) {
  for (std::size_t p = text.find("</"); p != std::string::npos; p = text.find("</", p + 2)) text.replace(p, 2, "<\\/");
  return text;
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

Json flight_json(const flight::FlightResult& f) {
  const Log log{f, thin_log(f, kFlownStep)};
  Json columns = Json::object();
  for (const char* n : {"t"}) columns[n] = json_column(log, n, 1e-3);
  for (const char* p : {"ref_", "true_", "est_"})
    for (const char* a : {"x", "y", "z"})
      if (log.has(std::string(p) + a)) columns[std::string(p) + a] = json_column(log, std::string(p) + a, 1e-3);
  for (const char* n : {"true_vx", "true_vy", "true_vz"})
    if (log.has(n)) columns[n] = json_column(log, n, 1e-3);
  for (const char* n : {"true_roll", "true_pitch", "true_yaw"})
    if (log.has(n)) columns[n] = json_column(log, n, 1e-4);
  Json events = Json::array();
  for (const auto& k : kEvents)
    for (const auto& [t0, t1] : intervals(f, k.column))
      events.push_back({{"kind", k.column}, {"name", k.name}, {"color", k.color}, {"t0", mm(t0)}, {"t1", mm(t1)}});
  return {{"step", kFlownStep}, {"columns", columns}, {"events", events}};
}

std::string render_flight_report(const FlightReportInput& in) {
  const auto& s = in.scenario;
  const auto& f = in.flight;
  const auto& r = in.reference;
  const Json scene_doc = scene_json(in);
  const std::string scene = script_text(scene_doc.dump());

  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>MINER flight report: " +
       html_escape(s.name) + " (seed " + std::to_string(s.seed) + ")</title>\n";
  h += "<style>\nbody{font-family:sans-serif;margin:16px;color:#222;max-width:1240px}\n"
       "#view3d{width:1200px;height:640px;border:1px solid #ccc;position:relative}\n"
       "#view3d canvas{display:block}\n"
       "#view-overlay{position:absolute;left:8px;top:6px;font-size:12px;background:rgba(255,255,255,0.8);"
       "padding:2px 6px;pointer-events:none}\n"
       "table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\n"
       "th{background:#f0f0f0}td:first-child,th:first-child{text-align:left}\n"
       ".plots svg{margin:2px;border:1px solid #eee}\n#layers label{margin-right:10px}\n"
       "#playback{margin:6px 0;font-size:14px}#playback input[type=range]{width:760px;vertical-align:middle}\n"
       "#playback-time{display:inline-block;min-width:120px;font-weight:bold;font-family:monospace}\n"
       "#playback-readout{font-family:monospace;font-size:12px;color:#444}\n"
       "#error-scale{display:inline-block;width:160px;height:10px;vertical-align:middle;margin:0 4px;"
       "background:linear-gradient(to right,#1a9850,#fee08b,#d73027)}\n"
       ".legend span{display:inline-block;margin-right:12px}\n</style>\n</head>\n<body>\n";
  h += "<h1>MINER flight report: " + html_escape(s.name) + "</h1>\n";
  h += "<p>Seed " + std::to_string(s.seed) + ", reference from " + html_escape(r.source);
  if (r.region) h += " (MINER RRT* sampling the " + html_escape(r.region->source()) + " region)";
  h += ", minimum-" + std::string(s.order == 3 ? "jerk" : "snap") + " MINCO trajectory, " +
       std::to_string(r.trajectory.segments()) + " segments, " + fixed(r.trajectory.total_duration(), 2) +
       " s. Goal " + (f.goal_reached ? "reached" : "NOT reached") + " (" + fixed(f.final_position_error, 3) +
       " m off), " + std::to_string(f.collisions) + " collisions." +
       (f.left_world ? " The vehicle left the map at " + fixed(f.left_world_time_s, 2) + " s: the flight stopped there." : "") +
       "</p>\n";
  h += "<h2>3D view</h2>\n<div id=\"layers\"></div>\n<div id=\"view3d\"><div id=\"view-overlay\"></div></div>\n"
       "<div id=\"playback\"><button id=\"playback-play\" type=\"button\">play</button> "
       "<input id=\"playback-slider\" type=\"range\" min=\"0\" max=\"" + fixed(f.log.empty() ? 0.0 : f.log.back()[0], 2) +
       "\" step=\"" + fixed(kFlownStep, 2) + "\" value=\"0\"> <span id=\"playback-time\">t = 0.00 s</span><br>"
       "<span id=\"playback-readout\"></span></div>\n"
       "<p class=\"legend\"><span style=\"color:#8c8c8c\">&#9632; obstacles</span>"
       "<span style=\"color:#f2b134\">&#9632; heuristic region</span><span style=\"color:#6baed6\">&#9632; RRT* tree</span>"
       "<span style=\"color:#9467bd\">- - planned path</span><span style=\"color:#d62728\">&#9472; repaired path</span>"
       "<span style=\"color:#1f77b4\">&#9644; trajectory (wide, translucent)</span>"
       "<span>flown (truth), coloured by tracking error |p - p_ref|: 0<span id=\"error-scale\"></span>"
       "<span id=\"error-scale-max\">max</span> m</span>"
       "<span>&#9679; vehicle at the slider's time (arms: attitude, red: front), &#9675; reference there</span>"
       "<span>&#9670; where an event began (the timeline's colours)</span>"
       "<br>Drag to orbit, scroll to zoom, right-drag to pan. Ground grid in the map's x-y plane at its floor, "
       "axes at the map's lower corner (x red, y green, z blue); the grid's spacing is written on the view.</p>\n";
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
  h += "<h2>Events</h2>\n<div class=\"plots\">\n" + timeline(f) + "</div>\n";
  h += "<h2>Over time</h2>\n<p>Every plot against time (s); the black line marks the playback slider's time.</p>\n" +
       plots(f);
  if (in.stage_ms.empty()) {
    h += "<h2>Stage timing</h2>\n<p>Not recorded: wall-clock times would make the page differ between two runs "
         "of the same scenario and seed (<code>miner fly --timing</code> records them).</p>\n";
  } else {
    h += "<h2>Stage timing</h2>\n<table><tr><th>stage</th><th>wall clock (ms)</th></tr>\n";
    double total = 0.0;
    for (const auto& [name, ms] : in.stage_ms) {
      h += "<tr><td>" + html_escape(name) + "</td><td>" + fixed(ms, 2) + "</td></tr>\n";
      total += ms;
    }
    h += "<tr><th>total</th><th>" + fixed(total, 2) + "</th></tr></table>\n";
  }
  if (r.planner_iterations > 0)
    h += "<p>Planner: " + std::to_string(r.planner_iterations) + " iterations, tree of " +
         std::to_string(r.tree_vertices.size()) + " vertices.</p>\n";
  h += "<script id=\"miner-scene\" type=\"application/json\">" + scene + "</script>\n";
  h += "<script id=\"miner-flight\" type=\"application/json\">" + script_text(flight_json(f).dump()) + "</script>\n";
  h += "<script>\n" + three_js_source() + "\n</script>\n";
  h += "<script>\n" + viewer_js_source() + "\n</script>\n</body>\n</html>\n";
  return h;
}

}  // namespace miner::report
