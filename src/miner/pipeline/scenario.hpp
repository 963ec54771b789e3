#pragma once
/// \file
/// A flight scenario (`miner-scenario-v1`, REQ-FLIGHT-007): the map, the vehicle, the
/// query, where the reference trajectory comes from, the sensors, the N3, the controller
/// and the seed — everything a flight depends on, so a scenario and a seed fix the bytes
/// of the flight log.
///
///   {"format": "miner-scenario-v1", "name": "...",
///    "map": "path relative to this file" | {inline miner-map-v1},
///    "vehicle": "path" | {inline miner-vehicle-v1}        (optional: the N3-class default),
///    "start": [x,y,z], "goal": [x,y,z]                     (optional: the map's query),
///    "waypoints": [[x,y,z], ...]                           (optional interior waypoints;
///                                                           absent: plan with MINER RRT*),
///    "trajectory": {"order": 4, "v_max": 0.8, "a_max": 0.5} | {"file": "answer.json"},
///    "seed": 1, "hover_after_s": 3, "goal_tolerance_m": 0.3, "planning_margin_m": 0.1,
///    "controller_reads": "ekf" (or "ground-truth": a diagnostic, fly --ground-truth),
///    "imu": {...}, "pose": {...}, "n3": {...}, "controller": {...}, "ekf": {...},
///    "command_dropout_s": [t0, t1]                         (optional: the companion
///                                                           computer stays silent then)}

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/traj/polynomial_trajectory.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"
#include "miner/world/map.hpp"

namespace miner::pipeline {

inline constexpr const char* kScenarioFormat = "miner-scenario-v1";
/// Longest simulated flight (reference + hover, s): bounds the work and the log of one
/// `miner fly` (~4 x 10^5 N3 ticks, a ~100 MB log at most). A scenario asking for more (a
/// long hover, or limits so low that the reference lasts hours) is refused before any
/// sampling or simulation (REQ-FLIGHT-007).
using flight::kMaxFlightSeconds;
/// Ranges of a scenario's values (REQ-FLIGHT-007; issue 20: a goal tolerance of 1e9 m made any
/// flight "reach" its goal, v_max 1e308 was accepted). Speed and acceleration limits: from
/// 1 cm/s (below it the reference outlasts kMaxFlightSeconds on any map) to what a racing
/// quadrotor reaches; the tilt check below narrows a_max further.
inline constexpr double kMinLimit = 0.01;
inline constexpr double kMaxSpeed = 50.0;          ///< m/s
inline constexpr double kMaxAcceleration = 50.0;   ///< m/s^2
using flight::kMaxGoalTolerance;
/// The planning margin grows the robot radius; 10 m is the largest robot radius a map takes.
inline constexpr double kMaxPlanningMargin = 10.0;  ///< m
/// The planner's iteration budget (plan::kMaxIterations, the CLI's --iterations bound).
inline constexpr long long kMaxPlannerIterations = static_cast<long long>(plan::kMaxIterations);

/// A whole run as the paper's system does it: the world, how the reference is found (given
/// waypoints, a trajectory file, or MINER RRT* on the sGAN's region), its limits, and the
/// flight setup (vehicle, sensors, N3, controller, EKF, seed) the simulator flies it with.
struct Scenario : flight::FlightSetup {
  std::string origin;                       ///< where it was read from (messages)
  std::shared_ptr<const world::Map> map;  ///< never null after loading
  std::optional<Eigen::MatrixX3d> waypoints;  ///< interior waypoints, one per row
  /// "controller_reads": "ground-truth": the controller reads the true state (a diagnostic,
  /// `fly --ground-truth`); default "ekf", the estimate.
  bool controller_reads_truth = false;
  int order = 4;                            ///< s: 3 jerk, 4 snap
  traj::Limits limits{0.8, 0.5};
  /// "trapezoid" or "optimise" (REQ-TRAJ-011: J + rho sum T within the limits, by Ceres).
  std::string allocation = "trapezoid";
  double rho = 1.0;
  std::optional<traj::PolynomialTrajectory> trajectory_file;
  /// Added to the vehicle radius when planning and repairing the reference (m): room for
  /// the tracking error (REQ-FLIGHT-008's noise floor is 0.10 m).
  double planning_margin = 0.1;
  /// How the path is found when the scenario gives neither waypoints nor a trajectory
  /// file: MINER RRT* (Alg. 1) sampling the sGAN's filtered region ("sgan", the paper's
  /// system) or the A*-dilated oracle region ("astar").
  std::string region = "sgan";
  std::string weights;                      ///< sGAN weights file; empty: the built-in ones
  std::size_t planner_iterations = 5000;
};

/// Parses and validates a scenario; relative paths resolve against `base_dir`. Checks
/// before any flight: every parameter, rates that divide the N3's loop rate, start and
/// goal inside the map and clear of obstacles by the vehicle radius, limits within what
/// the vehicle can fly (kEnvelopeMargin of its tilt and thrust).
Scenario scenario_from_json(const Json& doc, const std::string& origin, const std::string& base_dir);
Scenario load_scenario(const std::string& path);

/// Throws miner::Error naming the field unless the struct is a scenario a file could say:
/// its map set, and every field within the reader's ranges and cross-checks (the struct is
/// written back with scenario_document and read again, so the rules are the reader's; the EKF's
/// imu/pose must be the scenario's). build_reference() and fly() call it, so fields changed in
/// C++ after reading are checked like a file's (issue 20, tenth campaign L12).
void check_scenario(const Scenario& s);
/// The scenario as a document of the scenario format, without its map (a Map has no single
/// document: a voxel map names its file) and without a trajectory file's path (the struct holds
/// the trajectory itself): what check_scenario reads back.
Json scenario_document(const Scenario& s);

/// The embedded default scenario (fixtures/scenarios/default.json with its map and
/// vehicle inlined at build time), so `miner fly` runs with no argument anywhere.
Scenario default_scenario();
/// Its text, as shipped.
const char* default_scenario_text();

/// A scenario document that runs from any folder: the map (JSON) and the vehicle inlined,
/// other file references (an OctoMap map, a trajectory file, sGAN weights) made absolute
/// against `base_dir`. What `miner fly` stores as its run folder's scenario.json.
Json self_contained_scenario(Json doc, const std::string& base_dir);
/// Every file a scenario document reads (map, the map's voxel file, vehicle, trajectory file,
/// sGAN weights), absolute: a run folder must not hold any of them (issue 20: `fly --out` the
/// map's folder replaced the map with the run's path.json).
std::vector<std::string> scenario_inputs(const Json& doc, const std::string& base_dir);
/// The default scenario as such a document.
Json default_scenario_document();

/// The share of the vehicle's tilt limit and thrust that a reference trajectory may use;
/// the rest is left to the feedback loop.
inline constexpr double kEnvelopeMargin = 0.8;

/// The reference the vehicle flies, where it came from and what each stage did.
struct ReferencePlan : flight::ReferenceTrajectory {
  std::optional<traj::AllocationResult> allocation;  ///< with "allocation": "optimise"
  std::size_t planner_iterations = 0;
  /// With source "planner": the heuristic region the planner sampled, its final tree
  /// (vertices, parent indices, -1 for the root) and the path it returned (before repair).
  std::optional<plan::HeuristicRegion> region;
  std::vector<Eigen::Vector3d> tree_vertices;
  std::vector<long> tree_parents;
  Eigen::MatrixX3d planned_path;
  /// Wall-clock time of each stage (ms, not deterministic): "region", "plan", "trajectory".
  std::vector<std::pair<std::string, double>> stage_ms;
  /// What it was built from (reference_fields of its scenario, set by build_reference): fly()
  /// refuses it in a scenario whose fields differ. Empty in a reference assembled by hand.
  Json built_from;
};

/// The fields of a scenario that build_reference reads, as a document: its map's fingerprint,
/// vehicle radius, start, goal, planning margin, waypoints, trajectory (limits, order, allocation,
/// or the file's SHA-256), and the planner and seed when it plans (without waypoints or a file;
/// otherwise the seed draws only the flight's noise). Two scenarios with equal fields build the
/// same reference
/// (seventeenth campaign F18: from Python, a reference of another seed or region flew as this
/// scenario's).
Json reference_fields(const Scenario& s);

/// Builds the reference: the file as is, or MINCO through start-waypoints-goal (or a
/// MINER RRT* path when there are no waypoints) with collision repair, uniformly
/// time-stretched if it exceeds v_max / a_max (rest to rest, so the curve is unchanged).
/// Throws miner::Error if the result starts or ends away from start / goal or needs more
/// tilt or thrust than the vehicle's envelope allows.
ReferencePlan build_reference(const Scenario& s);

/// Throws miner::Error naming the scenario unless `reference` is one of its own: from its
/// start to its goal at rest, no longer than a flight may last, within its trajectory limits
/// and the vehicle's envelope, clear of its map by the vehicle radius, and no disturbance
/// window (command dropout, gust) opening after the flight ends. fly() calls it.
void check_reference(const Scenario& s, const ReferencePlan& reference);

/// Flies the reference with the scenario's flight setup, a collision being the vehicle's
/// radius touching the scenario's map (flight::fly with FlightSetup::collides from the map),
/// after check_reference.
flight::FlightResult fly(const Scenario& scenario, const ReferencePlan& reference, const flight::FlyOptions& options = {});

}  // namespace miner::pipeline
