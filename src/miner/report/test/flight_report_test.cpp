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
