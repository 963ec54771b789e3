#include <regex>
#include <string>

#include <catch2/catch.hpp>

#include "miner/report/flight_report.hpp"

using Catch::Matchers::Contains;
using namespace miner;

namespace {

/// One short flight of the default scenario with the A* region (fast under sanitizers).
struct Fixture {
  pipeline::Scenario scenario = [] {
    auto s = pipeline::default_scenario();
    s.region = "astar";
    s.planner_iterations = 800;
    return s;
  }();
  pipeline::ReferencePlan reference = pipeline::build_reference(scenario);
  flight::FlightResult result = pipeline::fly(scenario, reference);
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

}  // namespace

TEST_CASE("the scene holds every layer and agrees with the run's products to 1 mm", "[REQ-REPORT-002]") {
  const auto& f = fixture();
  const report::FlightReportInput in{f.scenario, f.reference, f.result, {}};
  const Json scene = report::scene_json(in);
  CHECK(scene["obstacles"].size() == f.scenario.map->obstacles().size());
  REQUIRE(f.reference.region);
  CHECK(scene["region"]["centres"].size() == 3 * f.reference.region->cells().size());
  // One edge per non-root vertex.
  CHECK(scene["tree"].size() == 6 * (f.reference.tree_vertices.size() - 1));
  CHECK(scene["path"].size() == 3 * static_cast<std::size_t>(f.reference.path.rows()));
  CHECK(scene["planned_path"].size() == 3 * static_cast<std::size_t>(f.reference.planned_path.rows()));
  for (int a = 0; a < 3; ++a) {
    CHECK(scene["path"][static_cast<std::size_t>(a)].get<double>() == Approx(f.reference.path(0, a)).margin(5e-4));
    CHECK(scene["start"][static_cast<std::size_t>(a)].get<double>() == Approx(f.scenario.start[a]).margin(5e-4));
  }
  const double T = f.reference.trajectory.total_duration();
  CHECK(scene["trajectory"].size() / 3 == static_cast<std::size_t>(std::ceil(T / report::kTrajectoryStep)) + 1);
  const auto& tr = scene["trajectory"];
  const Eigen::Vector3d end = f.reference.trajectory.evaluate(T);
  for (int a = 0; a < 3; ++a) CHECK(tr[tr.size() - 3 + static_cast<std::size_t>(a)].get<double>() == Approx(end[a]).margin(5e-4));
  CHECK(scene["flown"].size() >= 3 * static_cast<std::size_t>(f.result.flight_time / report::kFlownStep));
}

TEST_CASE("the report is self-contained with plots, tables and timings", "[REQ-REPORT-002]") {
  const auto& f = fixture();
  const std::string html = report::render_flight_report(
      {f.scenario, f.reference, f.result, {{"region", 1.5}, {"plan", 2.5}, {"trajectory", 3.0}, {"flight", 4.0}}});
  CHECK_THAT(html, Contains("<!DOCTYPE html>") && Contains("</html>"));
  // Nothing fetched from elsewhere.
  CHECK_FALSE(std::regex_search(html, std::regex(R"((src|href)\s*=\s*["']?(https?:)?//)")));
  CHECK_FALSE(std::regex_search(html, std::regex(R"(<link\b)")));
  CHECK_THAT(html, Contains("REVISION=\"111\"") && Contains("OrbitControls") && Contains("miner-status"));
  CHECK_THAT(html, Contains("Tracking and estimation error") && Contains("Speed") && Contains("Thrust"));
  CHECK_THAT(html, Contains("Pos. Err. x") && Contains("<td>region</td><td>1.50</td>") && Contains("<th>11.00</th>"));
  // The scene text cannot close its script element early.
  const auto open = html.find("<script id=\"miner-scene\"");
  const auto close = html.find("</script>", open);
  CHECK(html.substr(open, close - open).find("</") == std::string::npos);
}

namespace {
long column_index(const std::string& name) {
  const auto& c = flight::flight_log_columns();
  for (std::size_t i = 0; i < c.size(); ++i)
    if (c[i] == name) return static_cast<long>(i);
  return -1;
}
std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("the viewer's flight data: the log every 0.05 s by column name, to 1 mm, with the events",
          "[REQ-REPORT-010][REQ-REPORT-012]") {
  const auto& f = fixture();
  flight::FlightResult r = f.result;
  // Events by hand: a collision from the 100th to the 150th row, a failsafe to the end.
  const auto collision = static_cast<std::size_t>(column_index("collision"));
  const auto failsafe = static_cast<std::size_t>(column_index("failsafe"));
  // Every event column the log has cleared first (the flight may have had some).
  for (const char* name : {"failsafe", "saturated", "pose_lost", "collision"})
    if (const long c = column_index(name); c >= 0)
      for (auto& row : r.log) row[static_cast<std::size_t>(c)] = 0.0;
  for (std::size_t i = 100; i < 150; ++i) r.log[i][collision] = 1.0;
  for (std::size_t i = r.log.size() - 20; i < r.log.size(); ++i) r.log[i][failsafe] = 1.0;
  const Json fj = report::flight_json(r);
  const auto& c = fj["columns"];
  const std::size_t n = c["t"].size();
  CHECK(n >= static_cast<std::size_t>(r.flight_time / report::kFlownStep));
  for (const char* name : {"t", "ref_x", "ref_y", "ref_z", "true_x", "true_y", "true_z", "est_x", "est_y", "est_z",
                           "true_vx", "true_vy", "true_vz", "true_roll", "true_pitch", "true_yaw"}) {
    INFO(name);
    REQUIRE(c.contains(name));
    CHECK(c[name].size() == n);
  }
  // Samples 0.05 s apart (to one log tick) and equal to the log's rows to 1 mm.
  const auto tx = static_cast<std::size_t>(column_index("true_x"));
  for (std::size_t k = 1; k < n; ++k) {
    const double dt = c["t"][k].get<double>() - c["t"][k - 1].get<double>();
    if (k + 1 < n) CHECK(dt == Approx(report::kFlownStep).margin(0.011));
  }
  std::size_t row = 0;
  for (std::size_t k = 0; k < n; k += 37) {
    while (r.log[row][0] < c["t"][k].get<double>() - 5e-4) ++row;
    CHECK(c["true_x"][k].get<double>() == Approx(r.log[row][tx]).margin(5e-4));
  }
  const auto& ev = fj["events"];
  REQUIRE(ev.size() == 2);
  CHECK(ev[0]["kind"] == "failsafe");
  CHECK(ev[0]["t0"].get<double>() == Approx(r.log[r.log.size() - 20][0]).margin(5e-4));
  CHECK(ev[0]["t1"].get<double>() == Approx(r.log.back()[0]).margin(5e-4));
  CHECK(ev[1]["kind"] == "collision");
  CHECK(ev[1]["t0"].get<double>() == Approx(r.log[100][0]).margin(5e-4));
  CHECK(ev[1]["t1"].get<double>() == Approx(r.log[150][0]).margin(5e-4));
  const std::string html = report::render_flight_report({f.scenario, f.reference, r, {}});
  CHECK_THAT(html, Contains("<script id=\"miner-flight\" type=\"application/json\">") && Contains("id=\"playback-slider\"") &&
                       Contains("id=\"error-scale\""));
  // The timeline: the two bars, and the lanes of the columns the log has.
  const auto t0 = html.find("id=\"plot-events\"");
  REQUIRE(t0 != std::string::npos);
  const std::string timeline = html.substr(t0, html.find("</svg>", t0) - t0);
  CHECK(count(timeline, "class=\"event\"") == 2);
  CHECK_THAT(timeline, Contains("collision: 1, ") && Contains("failsafe: 1, "));
  CHECK((timeline.find("pose dropout") != std::string::npos) == (column_index("pose_lost") >= 0));
  CHECK((timeline.find("saturation") != std::string::npos) == (column_index("saturated") >= 0));
}

TEST_CASE("the report plots every axis, attitude, EKF error, rotors: optional columns only when logged",
          "[REQ-REPORT-011]") {
  const auto& f = fixture();
  const std::string html = report::render_flight_report({f.scenario, f.reference, f.result, {}});
  for (const char* id : {"plot-position-x", "plot-position-y", "plot-position-z", "plot-velocity-x", "plot-velocity-y",
                         "plot-velocity-z", "plot-attitude-roll", "plot-attitude-pitch", "plot-attitude-yaw", "plot-ekf-x",
                         "plot-ekf-y", "plot-ekf-z", "plot-rotors", "plot-thrust", "plot-error", "plot-tracking-axes",
                         "plot-speed"}) {
    INFO(id);
    const auto at = html.find(std::string("id=\"") + id + "\"");
    REQUIRE(at != std::string::npos);
    const std::string svg = html.substr(at, html.find("</svg>", at) - at);
    CHECK_THAT(svg, Contains("<path d=\"M") && Contains("class=\"cursor\"") && Contains("data-px1="));
  }
  const auto section = [&](const char* id) {
    const auto at = html.find(std::string("id=\"") + id + "\"");
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</svg>", at) - at);
  };
  // Reference, truth and estimate on a position plot; truth, estimate and command on roll.
  CHECK(count(section("plot-position-x"), "<path d=\"M") == 3);
  CHECK(count(section("plot-attitude-roll"), "<path d=\"M") == 3);
  CHECK(count(section("plot-rotors"), "<path d=\"M") == 4);
  CHECK(count(section("plot-tracking-axes"), "<path d=\"M") == 3);
  // Optional columns: a plot or band exactly when the log has them.
  CHECK((section("plot-ekf-x").find("class=\"band\"") != std::string::npos) == (column_index("est_sigma_x") >= 0));
  // The battery plot only when the flight modelled a battery (its column is 0 otherwise).
  CHECK(section("plot-battery").empty() == !f.scenario.battery.enabled);
  if (column_index("battery_v") >= 0) {
    auto with_battery = f.result;
    for (auto& row : with_battery.log) row[static_cast<std::size_t>(column_index("battery_v"))] = 15.5;
    const std::string page = report::render_flight_report({f.scenario, f.reference, with_battery, {}});
    CHECK(page.find("id=\"plot-battery\"") != std::string::npos);
  }
  CHECK(section("plot-wind").empty() == (column_index("wind_x") < 0));
  CHECK(section("plot-yaw-rate").empty() == (column_index("cmd_yaw_rate") < 0));
  CHECK((count(section("plot-attitude-yaw"), "<path d=\"M") == 4) == (column_index("ref_yaw") >= 0));
  // The same flight, the same bytes.
  CHECK(html == report::render_flight_report({f.scenario, f.reference, f.result, {}}));
}

TEST_CASE("the per-axis tracking error is plotted as truth minus reference with its sign", "[REQ-REPORT-011]") {
  // Held-out audit 9, h9-flight-05: the per-axis tracking error plot showed reference - truth, the curve
  // mirrored about zero.
  const auto& f = fixture();
  // The flown x is set to the reference's x plus 0.5 m + 0.1 m/s * t; y and z to the reference's:
  // truth - reference on x runs from +0.5 m upwards and is 0 on y and z.
  auto shifted = f.result;
  const auto col = [](const char* name) { return static_cast<std::size_t>(column_index(name)); };
  for (auto& row : shifted.log) {
    row[col("true_x")] = row[col("ref_x")] + 0.5 + 0.1 * row[col("t")];
    row[col("true_y")] = row[col("ref_y")];
    row[col("true_z")] = row[col("ref_z")];
  }
  const std::string html = report::render_flight_report({f.scenario, f.reference, shifted, {}});
  const auto at = html.find("id=\"plot-tracking-axes\"");
  REQUIRE(at != std::string::npos);
  const std::string svg = html.substr(at, html.find("</svg>", at) - at);
  // The y axis' tick labels: from 0 (y and z) up past +0.5 m, none negative.
  std::vector<double> ticks;
  const std::regex tick("text-anchor=\"end\">([^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), tick); it != std::sregex_iterator(); ++it)
    ticks.push_back(std::stod((*it)[1].str()));
  REQUIRE(ticks.size() >= 2);
  CAPTURE(ticks);
  CHECK(*std::min_element(ticks.begin(), ticks.end()) >= 0.0);
  CHECK(*std::max_element(ticks.begin(), ticks.end()) >= 0.5);
  // The x curve (the first path) rises: its last point is drawn above (smaller SVG y than) its first.
  const std::regex first_path("<path d=\"M[0-9.]+ ([0-9.]+)[^\"]*L[0-9.]+ ([0-9.]+)\"");
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, first_path));
  CHECK(std::stod(m[2].str()) < std::stod(m[1].str()));
}
