#pragma once
/// \file
/// The closed loop (REQ-FLIGHT-008): reference -> SE(3) controller (100 Hz, on the EKF
/// estimate) -> N3 (latency, timeout, 400 Hz attitude loop and mixing) -> CVODE rigid
/// body -> IMU (400 Hz) and delayed pose (50 Hz) -> EKF -> controller. One tick of the
/// N3 loop is the simulation's time base; every sensor and loop runs on its ticks.
///
/// The controller reads the EKF. `use_ground_truth` exists only as a diagnostic (to
/// separate estimation from control error); the summary says which one it flew on.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "miner/core/json_io.hpp"
#include "miner/flight/controller.hpp"
#include "miner/flight/disturbances.hpp"
#include "miner/flight/dynamics.hpp"
#include "miner/flight/ekf.hpp"
#include "miner/flight/n3.hpp"
#include "miner/flight/sensors.hpp"
#include "miner/flight/vehicle.hpp"
#include "miner/traj/polynomial_trajectory.hpp"

namespace miner::flight {

inline constexpr const char* kSummaryFormat = "miner-flight-summary-v1";

/// What a closed-loop flight of a given trajectory needs: the vehicle, its sensors, N3,
/// controller and estimator, where it starts and should end, the seed of every noise
/// stream, and what counts as touching the world. The simulator knows no map, planner or
/// network (docs/layout.md): pipeline::Scenario extends this with them.
struct FlightSetup {
  std::string name = "scenario";
  VehicleParams vehicle;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  std::uint64_t seed = 1;
  double hover_after_s = 3.0;  ///< hover after the reference ends, s
  double goal_tolerance = 0.3;  ///< m
  ImuParams imu;
  PoseParams pose;
  n3::Config n3;
  ControllerParams controller;
  EkfParams ekf;  ///< imu and pose are copies of the above
  /// The world and vehicle a real flight meets (issue 23; each off unless given): wind and
  /// gusts, the plant's mismatch against `vehicle` (which the controller, N3 and EKF
  /// assume), the battery's sag, and the reference's yaw.
  WindParams wind;
  MismatchParams mismatch;
  BatteryParams battery;
  YawParams yaw;
  /// The companion computer stays silent in [t0, t1) s (the N3's stream-timeout failsafe).
  std::optional<std::pair<double, double>> command_dropout;
  /// Whether the vehicle at a position touches an obstacle (counted as a collision); empty:
  /// nothing to touch.
  std::function<bool(const Eigen::Vector3d&)> collides;
  /// The world the flight happens in: the flight stops the first tick the vehicle is outside
  /// it (FlightResult::left_world); empty: unbounded.
  std::optional<Eigen::AlignedBox3d> world;
};

/// The trajectory a flight follows, and what the flight's summary says of it.
struct ReferenceTrajectory {
  traj::PolynomialTrajectory trajectory;
  Eigen::MatrixX3d path;        ///< the waypoints MINCO went through (after repair)
  std::string source;           ///< "waypoints", "planner" or "file"
  double time_scale = 1.0;      ///< durations were stretched by this to meet the limits
  double max_speed = 0.0, max_acceleration = 0.0;  ///< of the trajectory
};

struct FlyOptions {
  bool use_ground_truth = false;  ///< diagnostic: the controller reads the true state
  bool record_log = true;         ///< keep the flight log rows
  bool record_consistency = false;  ///< NEES at the EKF horizon every control tick
  IntegratorOptions integrator;
  /// Called every kPollTicks N3 ticks, if set; it may throw to abandon the flight (the Python
  /// module raises KeyboardInterrupt through it: eleventh campaign P1).
  std::function<void()> poll;
};

/// How often FlyOptions::poll is called: 4000 ticks are 10 s of flight at the N3's 400 Hz.
inline constexpr long kPollTicks = 4000;

/// Column names of the flight log (one row per controller tick) and their units.
const std::vector<std::string>& flight_log_columns();
const std::vector<std::string>& flight_log_units();

struct FlightResult {
  std::vector<std::vector<double>> log;
  Eigen::Vector3d position_mse = Eigen::Vector3d::Zero();  ///< m^2, truth vs reference, t <= T
  Eigen::Vector3d velocity_mse = Eigen::Vector3d::Zero();  ///< (m/s)^2
  double max_position_error = 0.0;                        ///< m
  double position_rmse = 0.0;                             ///< m (norm)
  double estimation_rmse = 0.0;                           ///< m, EKF current() vs truth
  int collisions = 0;             ///< entries into the map inflated by the vehicle radius
  double collision_time_s = 0.0;
  bool goal_reached = false;
  /// The vehicle left FlightSetup::world: the flight stopped there (never goal_reached).
  bool left_world = false;
  double left_world_time_s = 0.0;                        ///< simulated seconds
  Eigen::Vector3d left_world_position = Eigen::Vector3d::Zero();
  double final_position_error = 0.0;
  double final_speed = 0.0;
  double flight_time = 0.0;       ///< simulated seconds
  long ticks = 0;                 ///< N3 loop ticks simulated
  long fused = 0, rejected = 0, stale = 0;
  long outliers_injected = 0, outliers_rejected = 0;
  int n3_timeouts = 0;
  // Time (s, counted per control tick) with the thrust or tilt saturated (the controller's
  // or the battery's limit), the speed limit binding, the pose stream lost, the N3 in its
  // failsafe.
  double saturation_time_s = 0.0, speed_limited_time_s = 0.0, pose_lost_time_s = 0.0, failsafe_time_s = 0.0;
  long pose_losses = 0;
  double wind_rms = 0.0, wind_max = 0.0;     ///< m/s, |w| over the flight
  double battery_min_voltage = 0.0;          ///< V (0 without a battery model)
  double battery_used_wh = 0.0;
  /// Simulated time the battery was depleted (Battery::depleted), if it was.
  std::optional<double> battery_depleted_s;
  Eigen::Vector3d pose_drift = Eigen::Vector3d::Zero();  ///< the VIO frame's drift at the end (m)
  long n3_rejected_commands = 0;
  long rhs_evaluations = 0;
  std::vector<double> nees;       ///< with record_consistency
  Vector15 final_sigma = Vector15::Zero();  ///< sqrt(diag P) at the end
  NavState final_estimate, final_truth;     ///< at the EKF horizon / now
  std::vector<double> nis;        ///< of the accepted pose measurements
  Json summary;
};

/// Longest simulated flight (reference + hover, s): bounds the work and the log of one
/// flight (~4 x 10^5 N3 ticks, a ~100 MB log at most). fly() refuses more, whoever calls it
/// (REQ-FLIGHT-007; tenth campaign L12b: a library caller's 10^7 s hover ran unbounded).
inline constexpr double kMaxFlightSeconds = 1000.0;
/// Arrival within 5 m: a wider tolerance no longer says the vehicle reached its goal.
inline constexpr double kMaxGoalTolerance = 5.0;  ///< m

/// Flies `reference` from setup.start in closed loop until it ends plus the hover; the same
/// setup (seed included) gives the same bytes.
FlightResult fly(const FlightSetup& setup, const ReferenceTrajectory& reference, const FlyOptions& options = {});

/// The log as CSV with a header row naming each column with its unit, "t[s],ref_x[m],...",
/// numbers printed with 9 significant digits (the same bytes for the same flight).
std::string flight_log_csv(const FlightResult& result);

/// The tracking MSE as the paper's table (Env., Pos. Err. x/y/z, Vel. Err. x/y/z).
std::string tracking_table(const std::string& env, const FlightResult& result);

}  // namespace miner::flight
