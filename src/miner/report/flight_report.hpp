#pragma once
/// \file
/// The self-contained HTML report of one `miner fly` run (REQ-REPORT-002, 009..013): an
/// interactive 3D view (three.js, embedded) of the map, the heuristic region, the RRT*
/// tree, the path, the MINCO trajectory and the flown path coloured by tracking error, with
/// a ground grid, axes, layer toggles and a playback slider (a 2D top view where WebGL is
/// missing); an event timeline and SVG plots over time (per-axis position and velocity,
/// attitude, EKF error and 3 sigma, rotors, thrust, battery, wind, error and speed); the
/// stage timings and the paper's tracking table. The file opens offline: every script and
/// datum is inside it.

#include <string>
#include <utility>
#include <vector>

#include "miner/core/json_io.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"

namespace miner::report {

struct FlightReportInput {
  const pipeline::Scenario& scenario;
  const pipeline::ReferencePlan& reference;
  const flight::FlightResult& flight;
  /// Wall-clock time of each stage in order (ms): region, plan, trajectory, flight.
  std::vector<std::pair<std::string, double>> stage_ms;
};

/// What the 3D view draws, in the map's metres: bounds, obstacles [min, max], start,
/// goal, region cells (centres, with the cell size), tree edges, the path (planned and
/// repaired), the trajectory sampled every `kTrajectoryStep` s and the flown path
/// (truth) from the log every `kFlownStep` s. Coordinates rounded to 1 mm.
Json scene_json(const FlightReportInput& in);

/// What the viewer script's playback, error colouring and top view need, from the log
/// thinned to every `kFlownStep` s: {"step", "columns": {name: [values]}, "events": [{kind,
/// name, color, t0, t1}]}. Columns (each only when the log has it): t, ref_x/y/z,
/// true_x/y/z, est_x/y/z, true_vx/vy/vz (1 mm, 1 ms), true_roll/pitch/yaw (1e-4 rad). Events
/// are the intervals of the full-rate log in which failsafe, saturated, pose_lost or
/// collision is 1.
Json flight_json(const flight::FlightResult& flight);

std::string render_flight_report(const FlightReportInput& in);

/// Sampling of the drawn curves: fine enough that a 1 m/s trajectory is drawn within a few
/// centimetres, coarse enough that a minute of flight stays a few hundred kilobytes.
inline constexpr double kTrajectoryStep = 0.05;  // s
inline constexpr double kFlownStep = 0.05;       // s
/// Sampling of the SVG plots over time: every kPlotStep s, coarser where a line would
/// have more than kMaxPlotPoints points.
inline constexpr double kPlotStep = 0.05;        // s
inline constexpr double kMaxPlotPoints = 600;

/// The three.js build and orbit controls embedded in every report (Debian libjs-three).
std::string three_js_source();
/// The report's own viewer script (src/miner/report/viewer.js).
std::string viewer_js_source();

}  // namespace miner::report
