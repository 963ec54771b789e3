// Closed-loop tracking bounds over random feasible trajectories (REQ-FLIGHT-008) and
// the paper-speed tracking table (REQ-FLIGHT-011).
#include <catch2/catch.hpp>

#include <cmath>

#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"
#include "miner/testing/flight_scenarios.hpp"
#include "miner/testing/property.hpp"
#include "miner/traj/time_allocation.hpp"

using miner::testing::open_room_scenario;
using miner::testing::property;
namespace flight = miner::flight;
namespace pipeline = miner::pipeline;
namespace traj = miner::traj;

namespace {

/// Noise floors (m): the EKF's position error (sigma ~ 1-2 cm) at its extremes over a
/// flight, and as an RMS.
constexpr double kMaxErrorFloor = 0.10;
constexpr double kRmseFloor = 0.05;
/// m per (m/s^3) of reference jerk: tau_eff / K_p = 0.21 s / 2.3 s^-2 ~ 0.09, rounded up.
constexpr double kErrorPerJerk = 0.10;

double max_jerk(const miner::traj::PolynomialTrajectory& t) {
  double j = 0.0;
  for (int i = 0; i < t.segments(); ++i) {
    const double T = t.durations()[static_cast<std::size_t>(i)];
    for (int k = 0; k <= 200; ++k) j = std::max(j, t.evaluate_segment(i, T * k / 200, 3).norm());
  }
  return j;
}

/// A random walk of 2-4 legs of 1-4 m from (10, 10, 5): short legs, so the limits bind.
Eigen::MatrixX3d random_points() {
  const int legs = *rc::gen::inRange(2, 5);
  Eigen::MatrixX3d p(legs + 1, 3);
  p.row(0) << 10, 10, 5;
  for (int i = 1; i <= legs; ++i) {
    Eigen::Vector3d d(*rc::gen::inRange(-100, 101), *rc::gen::inRange(-100, 101), *rc::gen::inRange(-50, 51));
    if (d.norm() < 1.0) d = Eigen::Vector3d(1, 0, 0);
    const double len = *rc::gen::inRange(10, 41) / 10.0;
    p.row(i) = p.row(i - 1) + len * d.normalized().transpose();
  }
  return p;
}

}  // namespace

TEST_CASE("Tracking error stays under the derived bound on random feasible trajectories", "[REQ-FLIGHT-008]") {
  // Each case is a closed-loop flight of ~10 s (5000 CVODE ticks, ~1.3 s under the
  // sanitizers); the `long` label runs 1000.
  const miner::testing::Cases cases{40, "one closed-loop flight per case"};
  property("random legs, v <= 2 m/s, a <= 2 m/s^2 reached exactly, sensor noise on", cases, [] {
    const Eigen::MatrixX3d points = random_points();
    const double v_max = *rc::gen::inRange(5, 21) / 10.0;
    const double a_max = *rc::gen::inRange(5, 21) / 10.0;
    const auto seed = static_cast<std::uint64_t>(*rc::gen::inRange(1, 1000000));
    pipeline::Scenario s = open_room_scenario(points, v_max, a_max, seed);
    s.hover_after_s = 2.0;
    pipeline::ReferencePlan ref = pipeline::build_reference(s);
    // Re-time so the tighter of the two limits is met with equality (build_reference
    // only ever stretches): the property covers trajectories at their limits.
    const double k = std::max(ref.max_speed / v_max, std::sqrt(ref.max_acceleration / a_max));
    miner::traj::scale_time(ref.trajectory, k);
    const auto [v, a] = traj::trajectory_extremes(ref.trajectory, 1e-3);
    RC_ASSERT(v <= v_max * (1 + 1e-6));
    RC_ASSERT(a <= a_max * (1 + 1e-6));
    flight::FlyOptions options;
    options.record_log = false;
    const flight::FlightResult r = pipeline::fly(s, ref, options);
    const double j = max_jerk(ref.trajectory);
    RC_LOG() << "v_max " << v_max << " a_max " << a_max << " max jerk " << j << " max error "
             << r.max_position_error << " rmse " << r.position_rmse << "\n";
    // docs/flight.md derives these: a noise floor plus tau_eff / K_p per m/s^3 of jerk
    // (tau_eff ~ 0.21 s of latency and attitude lag, K_p = 2.3 1/s^2).
    RC_ASSERT(r.max_position_error <= kMaxErrorFloor + kErrorPerJerk * j);
    RC_ASSERT(r.position_rmse <= kRmseFloor + 0.5 * kErrorPerJerk * j);
    RC_ASSERT(r.goal_reached);
  });
}

TEST_CASE("At the paper's speeds the tracking MSE is at or below the paper's real-flight table", "[REQ-FLIGHT-011]") {
  // Paper Table "Trajectory Tracking Error (MSE)", the smaller of Map1 / Map2 per column:
  // position x, y, z (m^2), velocity x, y, z ((m/s)^2).
  const Eigen::Vector3d paper_position(0.0513, 0.0919, 0.0003);
  const Eigen::Vector3d paper_velocity(0.0222, 0.0115, 0.0006);
  for (const char* map : {"indoor-1", "indoor-2"}) {
    miner::Json doc = miner::read_json_file(std::string(MINER_SOURCE_DIR) + "/fixtures/scenarios/default.json");
    doc["map"] = std::string("../maps/") + map + ".json";
    doc["trajectory"]["v_max"] = 0.5;  // paper: 1.73 and 1.45 km/h average,
    doc["trajectory"]["a_max"] = 0.2;  // 0.2 and 0.15 m/s^2 maximum
    const pipeline::Scenario s = pipeline::scenario_from_json(doc, map, std::string(MINER_SOURCE_DIR) + "/fixtures/scenarios");
    const pipeline::ReferencePlan ref = pipeline::build_reference(s);
    const flight::FlightResult r = pipeline::fly(s, ref);
    INFO(map << "\n" << flight::tracking_table(map, r));
    CHECK(r.goal_reached);
    CHECK(r.collisions == 0);
    for (int i = 0; i < 3; ++i) {
      CHECK(r.position_mse[i] <= paper_position[i]);
      CHECK(r.velocity_mse[i] <= paper_velocity[i]);
    }
  }
}

TEST_CASE("Planned with the tracking margin, fixture-map flights never touch the inflated map", "[REQ-FLIGHT-007]") {
  // Without the margin (planning at the bare vehicle radius) 3 of 20 seeds of the default
  // scenario grazed the inflated map by a few centimetres of tracking error.
  for (const char* map : {"indoor-1", "indoor-2"}) {
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      miner::Json doc = miner::read_json_file(std::string(MINER_SOURCE_DIR) + "/fixtures/scenarios/default.json");
      doc["map"] = std::string("../maps/") + map + ".json";
      doc["seed"] = seed;
      const pipeline::Scenario s = pipeline::scenario_from_json(doc, map, std::string(MINER_SOURCE_DIR) + "/fixtures/scenarios");
      flight::FlyOptions options;
      options.record_log = false;
      const flight::FlightResult r = pipeline::fly(s, pipeline::build_reference(s), options);
      INFO(map << " seed " << seed << ": max error " << r.max_position_error);
      CHECK(r.collisions == 0);
      CHECK(r.goal_reached);
    }
  }
}
