#include "miner/pipeline/scenario.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/sha256.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/core/text.hpp"
#include "miner/flight/flatness.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/traj/collision_repair.hpp"
#include "miner/traj/problem_io.hpp"
#include "miner/traj/time_allocation.hpp"

namespace miner::pipeline {

// The flight setup's parameter readers (vehicle, sensors, N3, controller) are the simulator's.
using namespace flight;

namespace {

std::string resolve(const std::string& base_dir, const std::string& path) {
  const std::filesystem::path p(path);
  if (p.is_absolute() || base_dir.empty()) return path;
  // Not lexically normalised: the system resolves "..", so a path through a folder that is not
  // there (or through a file) is refused, as a shell would (ninth campaign recheck of P16:
  // "nodir/../../maps/indoor-1.json" loaded the map).
  return (std::filesystem::path(base_dir) / p).string();
}

/// A rate that must be an integer fraction of the N3 loop rate; returns the ratio.
int ticks_per(const JsonField& where, double loop_rate, double rate, const char* what) {
  const double ratio = loop_rate / rate;
  const double rounded = std::round(ratio);
  // Exact up to the rounding of a decimal rate (400/3 Hz written with 12 digits): 400.0000004 Hz
  // was taken as 400 (eleventh campaign C2), and the message rounded 49.9999999 to "50".
  constexpr double kRateRounding = 1e-12;
  if (rounded < 1.0 || std::abs(ratio - rounded) > kRateRounding * ratio) {
    std::ostringstream os;
    os << std::setprecision(15) << what << " " << rate << " Hz must divide the N3 loop rate " << loop_rate
       << " Hz (all sensors and loops run on its ticks)";
    where.fail(os.str());
  }
  return static_cast<int>(rounded);
}

/// The scenario's speed limit, kSpeedLimitHeadroom v_max, reaches the controller (the velocity
/// its feedback may ask for, REQ-FLIGHT-016; only when no cap was set, i.e. it is infinite) and
/// the N3's VELOCITY mode (its failsafe brake): what the reader does to a file's scenario and
/// fly() to a struct built in C++, so both fly the N3 a run folder's scenario.json describes.
void apply_speed_limit(flight::FlightSetup& f, const traj::Limits& limits) {
  const double speed_limit = kSpeedLimitHeadroom * limits.v_max;
  if (!std::isfinite(f.controller.max_speed)) f.controller.max_speed = speed_limit;
  f.n3.max_horizontal_speed = std::min(f.n3.max_horizontal_speed, speed_limit);
  f.n3.max_vertical_speed = std::min(f.n3.max_vertical_speed, speed_limit);
}

/// Everything of a scenario document but its format and map (s.map is set): every field's
/// range and the cross-checks. scenario_from_json reads files with it, and check_scenario
/// checks a struct by writing it back as a document, so one set of rules holds both.
/// The field a cross-field rule blames: the first of `paths` ("block.key" or "key") the file sets,
/// else the top level (sixteenth campaign F12: every such rule blamed "(top level)", and named
/// the user's own change only as "the N3's").
JsonField blamed(const JsonField& root, std::initializer_list<const char*> paths) {
  for (const char* path : paths) {
    const std::string p(path);
    const std::size_t dot = p.find('.');
    if (dot == std::string::npos) {
      if (root.has(p)) return root.at(p);
    } else if (root.has(p.substr(0, dot)) && root.at(p.substr(0, dot)).value().is_object() &&
               root.at(p.substr(0, dot)).has(p.substr(dot + 1))) {
      return root.at(p.substr(0, dot)).at(p.substr(dot + 1));
    }
  }
  return root;
}

/// A value in a cross-field message: exact, marked "(default)" when the file does not set it.
std::string value_of(const JsonField& root, const char* path, double v, const char* unit) {
  const JsonField f = blamed(root, {path});
  return std::string(path) + " " + exact_number(v) + " " + unit + (&f.value() == &root.value() ? " (default)" : "");
}

/// A file the scenario names by path, against the SHA-256 that a run folder's scenario.json
/// records beside it (`<key>_sha256`): a file changed since the flight would fly another
/// flight without a word (sixteenth campaign F11: sGAN weights recorded by path only).
void check_recorded_sha256(const JsonField& block, const std::string& key, const std::string& path,
                           const std::string& what) {
  const std::string hash_key = key + "_sha256";
  if (!block.has(hash_key)) return;
  const std::string recorded = sha256_field(block.at(hash_key));
  std::string bytes;
  try {
    bytes = read_file_bytes(path, what);
  } catch (const Error& e) {
    block.at(key).fail(e.what());
  }
  if (const std::string now = sha256_hex(bytes); now != recorded)
    block.at(hash_key).fail("the " + what + " " + path + " has SHA-256 " + now +
                            ", not the recorded one: the file changed since this scenario was written");
}

/// `trajectory_given`: the route is a trajectory already in s (a file's, or a struct's).
void read_scenario_fields(const JsonField& root, const std::string& origin, const std::string& base_dir,
                          bool trajectory_given, Scenario& s) {
  if (root.has("name")) {
    // The name becomes the default run folder runs/<name>-seed<seed>: one plain, visible name
    // (issue 20: "../../x" wrote outside runs/, "" made runs/-seed1).
    s.name = root.at("name").string();
    if (!is_plain_name(s.name))
      // Quoted as JSON writes it, so a newline in the name is shown as \n (seventh campaign C7).
      root.at("name").fail(std::string(kPlainNameRule) + ", got " + quoted_excerpt(s.name));
  }

  if (root.has("vehicle")) {
    const JsonField v = root.at("vehicle");
    if (v.value().is_string()) {
      // A vehicle file that cannot be read is named as the scenario's field, as the map is
      // (seventh campaign C3: "nope.json: cannot open file" named neither).
      try {
        s.vehicle = load_vehicle(resolve(base_dir, v.string()));
      } catch (const Error& e) {
        v.fail(e.what());
      }
    } else {
      s.vehicle = vehicle_from_json(v.value(), origin + ": vehicle");
    }
  }

  const auto& query = s.map->query();
  if (root.has("start")) s.start = root.at("start").vec3();
  else if (query) s.start = query->start;
  else root.fail("no \"start\" and the map stores no query");
  if (root.has("goal")) s.goal = root.at("goal").vec3();
  else if (query) s.goal = query->goal;
  else root.fail("no \"goal\" and the map stores no query");
  s.map->require_free(s.start, s.vehicle.radius, origin + ": start");
  s.map->require_free(s.goal, s.vehicle.radius, origin + ": goal");

  // The route comes from exactly one source; the keys of the others would be read and then
  // ignored without a word (issue 20, third campaign: an empty "waypoints" flew a straight
  // line through the map, a planner block beside waypoints was never used).
  const bool trajectory_file = trajectory_given || (root.has("trajectory") && root.at("trajectory").has("file"));
  if (trajectory_file) {
    for (const char* key : {"waypoints", "planner"})
      if (root.has(key)) root.at(key).fail("unused: the route is the trajectory file's (trajectory.file)");
    if (root.has("trajectory")) {
      const JsonField t = root.at("trajectory");
      for (const char* key : {"order", "allocation", "rho"})
        if (t.has(key)) t.at(key).fail("unused: the trajectory file fixes the order and the durations");
    }
  }
  if (root.has("waypoints") && root.has("planner"))
    root.at("planner").fail("unused: the route is given by \"waypoints\" (leave them out to plan with MINER RRT*)");
  if (root.has("waypoints")) {
    const JsonField w = root.at("waypoints");
    if (w.array_size() == 0)
      w.fail("empty: give at least one interior point, or leave the key out to plan with MINER RRT*");
    Eigen::MatrixX3d m(static_cast<Eigen::Index>(w.array_size()), 3);
    for (std::size_t i = 0; i < w.array_size(); ++i) {
      m.row(static_cast<Eigen::Index>(i)) = w.at(i).vec3().transpose();
      s.map->require_free(m.row(static_cast<Eigen::Index>(i)).transpose(), s.vehicle.radius,
                         origin + ": waypoints[" + std::to_string(i) + "]");
    }
    s.waypoints = m;
  }
  // The route start, waypoints..., goal has no repeated point: a zero-length leg has no
  // trajectory (issue 20: the refusal came later, naming the pipeline's "points[0]"). A given
  // trajectory file replaces the route.
  if (!trajectory_file) {
    std::vector<std::pair<Eigen::Vector3d, std::string>> route{{s.start, "start"}};
    if (s.waypoints)
      for (Eigen::Index i = 0; i < s.waypoints->rows(); ++i)
        route.emplace_back(s.waypoints->row(i).transpose(), "waypoints[" + std::to_string(i) + "]");
    route.emplace_back(s.goal, "goal");
    // m: closer points are one point. The reference's ends are checked to 1e-6 (m, m/s,
    // m/s^2), so a leg shorter than that has no trajectory those checks can tell from a point
    // (fifteenth campaign F3: a 1e-9 m route was refused as "must start and end at rest").
    constexpr double kCoincident = 1e-6;
    for (std::size_t i = 1; i < route.size(); ++i)
      if ((route[i].first - route[i - 1].first).norm() < kCoincident) {
        const std::string& name = route[i].second;
        // The goal the file leaves to the map's query is not the file's fault: the waypoint
        // before it is (seventeenth campaign F21: blamed on "(top level)").
        const bool goal_from_map = name == "goal" && !root.has("goal") && i >= 2 && s.waypoints;
        const JsonField at = goal_from_map     ? root.at("waypoints").at(i - 2)
                             : name == "goal"  ? blamed(root, {"goal"})
                             : name == "start" ? blamed(root, {"start"})
                                               : root.at("waypoints").at(static_cast<std::size_t>(i - 1));
        at.fail(route[i].second + " " + format_point(route[i].first) + " coincides with " + route[i - 1].second +
                  " (closer than " + short_number(kCoincident) + " m): remove the repeated point");
      }
  }
  if (root.has("trajectory")) {
    const JsonField t = root.at("trajectory");
    if (t.has("file")) {
      const std::string path = resolve(base_dir, t.at("file").string());
      check_recorded_sha256(t, "file", path, "trajectory file");
      s.trajectory_file = traj::trajectory_from_answer_json(read_json_file(path), path);
    } else if (t.has("file_sha256")) {
      t.at("file_sha256").fail("the hash of trajectory.file, which is not given");
    }
    if (t.has("order")) {
      s.order = t.at("order").integer();
      if (s.order != 3 && s.order != 4) t.at("order").fail("must be 3 (jerk) or 4 (snap)");
    }
    if (t.has("v_max")) s.limits.v_max = t.at("v_max").number_in(kMinLimit, kMaxSpeed, "m/s");
    if (t.has("a_max")) s.limits.a_max = t.at("a_max").number_in(kMinLimit, kMaxAcceleration, "m/s^2");
    if (t.has("allocation")) {
      s.allocation = t.at("allocation").string();
      if (s.allocation != "trapezoid" && s.allocation != "optimise")
        t.at("allocation").fail("must be \"trapezoid\" or \"optimise\", got \"" + s.allocation + "\"");
    }
    if (t.has("rho")) {
      if (s.allocation != "optimise") t.at("rho").fail("only used with \"allocation\": \"optimise\"");
      s.rho = t.at("rho").number_in(1e-9, 1e9);
    }
    t.only_keys({"file", "file_sha256", "order", "v_max", "a_max", "allocation", "rho"});
  }
  if (root.has("planner")) {
    const JsonField p = root.at("planner");
    p.only_keys({"region", "weights", "weights_sha256", "iterations"});
    if (p.has("region")) {
      s.region = p.at("region").string();
      if (s.region != "sgan" && s.region != "astar") p.at("region").fail("must be \"sgan\" or \"astar\"");
    }
    if (p.has("weights")) {
      if (s.region != "sgan") p.at("weights").fail("applies to \"region\": \"sgan\" only, not \"" + s.region + "\"");
      s.weights = resolve(base_dir, p.at("weights").string());
      check_recorded_sha256(p, "weights", s.weights, "sGAN weights file");
    } else if (p.has("weights_sha256")) {
      p.at("weights_sha256").fail("the hash of planner.weights, which is not given");
    }
    if (p.has("iterations")) {
      const long long n = p.at("iterations").integer();
      if (n < 1 || n > kMaxPlannerIterations)
        p.at("iterations").fail("must be in [1, " + std::to_string(kMaxPlannerIterations) + "], got " + std::to_string(n));
      s.planner_iterations = static_cast<std::size_t>(n);
    }
  }
  if (root.has("seed")) {
    const JsonField f = root.at("seed");
    // 2^64 and beyond parse as a double: the range, not the sign, is what is wrong with them.
    if (!f.value().is_number_unsigned()) f.fail("must be an integer in [0, 2^64 - 1], got " + f.value().dump());
    s.seed = f.value().get<std::uint64_t>();
  }
  // The diagnostic `fly --ground-truth` is part of what was flown: a run folder's scenario.json
  // records it, so its replay flies the same flight (eighth campaign recheck of W2).
  if (root.has("controller_reads")) {
    const std::string reads = root.at("controller_reads").string();
    if (reads != "ekf" && reads != "ground-truth")
      root.at("controller_reads").fail("must be \"ekf\" (the default) or \"ground-truth\" (a diagnostic), not \"" +
                                       reads + "\"");
    s.controller_reads_truth = reads == "ground-truth";
  }
  if (root.has("hover_after_s")) {
    s.hover_after_s = root.at("hover_after_s").positive_number();
    // Below the longest simulated flight, which the reference shares (fifteenth campaign F13:
    // "at most 1000 s" was documented, but 1000 s of hover leaves no time for any reference;
    // the flight's total is checked against kMaxFlightSeconds once the reference is known).
    if (!(s.hover_after_s < kMaxFlightSeconds))
      root.at("hover_after_s").fail("must be below " + std::to_string(static_cast<int>(kMaxFlightSeconds)) +
                                    " s (the longest simulated flight, reference and hover together), got " +
                                    Json(s.hover_after_s).dump());
  }
  if (root.has("goal_tolerance_m")) {
    s.goal_tolerance = root.at("goal_tolerance_m").number_above(0.0, kMaxGoalTolerance, "m");
  }
  if (root.has("planning_margin_m")) {
    s.planning_margin = root.at("planning_margin_m").number_in(0.0, kMaxPlanningMargin, "m");
    // The planner keeps the vehicle radius + margin clear: it must fit the map's radius bound.
    if (s.vehicle.radius + s.planning_margin > world::kMaxRobotRadius)
      root.at("planning_margin_m").fail("with the vehicle radius " + std::to_string(s.vehicle.radius) +
                                        " m gives a clearance above the " +
                                        std::to_string(static_cast<int>(world::kMaxRobotRadius)) + " m a plan may keep");
  }
  if (root.has("imu")) s.imu = imu_params_from_json(root.at("imu"));
  if (root.has("pose")) s.pose = pose_params_from_json(root.at("pose"));
  if (root.has("n3")) s.n3 = n3::config_from_json(root.at("n3"));
  if (root.has("controller")) s.controller = controller_params_from_json(root.at("controller"));
  if (root.has("ekf")) {
    const JsonField e = root.at("ekf");
    e.only_keys({"gate_probability", "initial_position_sigma", "initial_velocity_sigma", "initial_attitude_sigma"});
    if (e.has("gate_probability")) {
      s.ekf.gate_probability = e.at("gate_probability").positive_number();
      if (s.ekf.gate_probability >= 1.0) e.at("gate_probability").fail("must be below 1");
    }
    // Initial uncertainties: positive (the EKF inverts them) and no wider than the largest map
    // (m, m/s) or a half turn (rad).
    const auto sigma = [&](const char* key, double hi, const char* unit, double& to) {
      if (!e.has(key)) return;
      to = e.at(key).number_above(0.0, hi, unit);
    };
    sigma("initial_position_sigma", 100.0, "m", s.ekf.initial_position_sigma);
    sigma("initial_velocity_sigma", 100.0, "m/s", s.ekf.initial_velocity_sigma);
    sigma("initial_attitude_sigma", kPi, "rad", s.ekf.initial_attitude_sigma);
  }
  s.ekf.imu = s.imu;
  s.ekf.pose = s.pose;
  if (root.has("wind")) s.wind = wind_params_from_json(root.at("wind"));
  if (root.has("mismatch")) {
    s.mismatch = mismatch_params_from_json(root.at("mismatch"));
    try {
      plant_vehicle(s.vehicle, s.mismatch);
    } catch (const Error& e) {
      root.at("mismatch").fail(e.what());
    }
  }
  if (root.has("battery")) s.battery = battery_params_from_json(root.at("battery"));
  if (root.has("yaw")) s.yaw = yaw_params_from_json(root.at("yaw"));
  apply_speed_limit(s, s.limits);  // the controller's cap is infinite unless the file gave one
  if (s.controller.max_tilt_deg > s.n3.max_tilt_deg)
    blamed(root, {"n3.max_tilt_deg", "controller.max_tilt_deg"})
        .fail(value_of(root, "n3.max_tilt_deg", s.n3.max_tilt_deg, "deg") + " is below " +
              value_of(root, "controller.max_tilt_deg", s.controller.max_tilt_deg, "deg") +
              ": the controller may not command more tilt than the N3 allows");
  // A controller capped below the reference's speed falls behind it and cuts corners into
  // obstacles (issue 20, ninth campaign C4: 0.1 m/s under a 0.8 m/s v_max collided twice).
  if (s.controller.max_speed < s.limits.v_max)
    root.at("controller").at("max_speed_m_s").fail(
        short_number(s.controller.max_speed) + " m/s is below trajectory.v_max " + short_number(s.limits.v_max) +
        " m/s: the controller could not keep up with the reference (leave it out for " +
        short_number(kSpeedLimitHeadroom) + " v_max, or lower trajectory.v_max)");
  ticks_per(root.has("controller") ? root.at("controller") : root, s.n3.rate_hz, s.controller.rate_hz, "controller rate");
  ticks_per(root.has("pose") ? root.at("pose") : root, s.n3.rate_hz, s.pose.rate_hz, "pose rate");
  // The N3 drops API control when no command arrived for timeout_s: a timeout shorter than the
  // controller's period, or no longer than the command latency (the first command arrives after
  // it), times out every command and the vehicle never moves (issue 20, sixth campaign: such
  // scenarios were flown and ended in "did not reach the goal").
  // The N3 checks at its own ticks: the longest silence it sees between commands is the
  // controller's period less one N3 tick.
  const double longest_silence = 1.0 / s.controller.rate_hz - 1.0 / s.n3.rate_hz;
  if (s.n3.timeout_s < longest_silence)
    blamed(root, {"n3.timeout_s", "controller.rate_hz", "n3.rate_hz"})
        .fail(value_of(root, "n3.timeout_s", s.n3.timeout_s, "s") + " is shorter than the " + exact_number(longest_silence) +
              " s the N3 sees between commands (" + value_of(root, "controller.rate_hz", s.controller.rate_hz, "Hz") +
              ": its period less one n3 tick): every command would time out");
  if (s.n3.latency_s > s.n3.timeout_s)
    blamed(root, {"n3.latency_s", "n3.timeout_s"})
        .fail(value_of(root, "n3.latency_s", s.n3.latency_s, "s") + " is above " +
              value_of(root, "n3.timeout_s", s.n3.timeout_s, "s") +
              ": the first command would arrive after the N3 dropped API control");
  if (root.has("command_dropout_s")) {
    const JsonField d = root.at("command_dropout_s");
    if (d.array_size() != 2) d.fail("expected [t0, t1]");
    const double t0 = d.at(0).number(), t1 = d.at(1).number();
    if (!(t0 >= 0.0 && t1 > t0 && t1 <= kMaxFlightSeconds))
      d.fail("needs 0 <= t0 < t1 <= " + std::to_string(static_cast<int>(kMaxFlightSeconds)) + " s");
    s.command_dropout = std::make_pair(t0, t1);
  }
  // The limits themselves must be flyable: a horizontal a_max needs atan(a_max / g) of tilt.
  const double tilt_needed = std::atan(s.limits.a_max / kGravity);
  if (tilt_needed > kEnvelopeMargin * deg2rad(s.controller.max_tilt_deg))
    blamed(root, {"trajectory.a_max", "controller.max_tilt_deg"})
        .fail(value_of(root, "trajectory.a_max", s.limits.a_max, "m/s^2") + " needs " + short_number(tilt_needed * 180.0 / kPi) +
              " deg of tilt, more than " + short_number(kEnvelopeMargin * s.controller.max_tilt_deg) + " deg (" +
              short_number(kEnvelopeMargin) + " of " + value_of(root, "controller.max_tilt_deg", s.controller.max_tilt_deg, "deg") +
              ")");
}

}  // namespace

Scenario scenario_from_json(const Json& doc, const std::string& origin, const std::string& base_dir) {
  const JsonField root(doc, "", origin);
  root.require_format(kScenarioFormat);
  root.only_keys({"format", "name", "map", "vehicle", "start", "goal", "waypoints", "trajectory", "planner", "seed",
                  "hover_after_s", "goal_tolerance_m", "planning_margin_m", "imu", "pose", "n3", "controller", "ekf",
                  "command_dropout_s", "wind", "mismatch", "battery", "yaw", "controller_reads"});
  Scenario s;
  s.origin = origin;
  const JsonField map_field = root.at("map");
  if (map_field.value().is_string()) {
    // A map that cannot be read is named as the scenario's field (issue 20: "/tmp: cannot open
    // file" named neither).
    try {
      s.map = std::make_shared<const world::Map>(world::Map::load(resolve(base_dir, map_field.string())));
    } catch (const Error& e) {
      map_field.fail(e.what());
    }
  } else {
    s.map = std::make_shared<const world::Map>(world::Map::from_json(map_field.value(), origin + ": map"));
  }
  read_scenario_fields(root, origin, base_dir, false, s);
  return s;
}

Json scenario_document(const Scenario& s) {
  Json d{{"format", kScenarioFormat},
         {"name", s.name},
         {"vehicle", to_json(s.vehicle)},
         {"start", vec3_json(s.start)},
         {"goal", vec3_json(s.goal)},
         {"seed", s.seed},
         {"hover_after_s", s.hover_after_s},
         {"goal_tolerance_m", s.goal_tolerance},
         {"planning_margin_m", s.planning_margin},
         {"imu", to_json(s.imu)},
         {"n3", to_json(s.n3)},
         {"controller", to_json(s.controller)},
         {"ekf",
          {{"gate_probability", s.ekf.gate_probability},
           {"initial_position_sigma", s.ekf.initial_position_sigma},
           {"initial_velocity_sigma", s.ekf.initial_velocity_sigma},
           {"initial_attitude_sigma", s.ekf.initial_attitude_sigma}}},
         {"mismatch", to_json(s.mismatch)},
         {"controller_reads", s.controller_reads_truth ? "ground-truth" : "ekf"}};
  d["pose"] = to_json(s.pose);
  d["yaw"] = to_json(s.yaw);
  if (s.wind.enabled) d["wind"] = to_json(s.wind);
  if (s.battery.enabled) d["battery"] = to_json(s.battery);
  // A struct's empty waypoint list is the straight leg from start to goal (a file says that
  // with waypoints left out and no planner; an empty list there is refused as ambiguous).
  if (s.waypoints && s.waypoints->rows() > 0) {
    Json w = Json::array();
    for (Eigen::Index i = 0; i < s.waypoints->rows(); ++i) w.push_back(vec3_json(s.waypoints->row(i).transpose()));
    d["waypoints"] = w;
  }
  Json t{{"v_max", s.limits.v_max}, {"a_max", s.limits.a_max}};
  if (!s.trajectory_file) {
    t["order"] = s.order;
    t["allocation"] = s.allocation;
    if (s.allocation == "optimise") t["rho"] = s.rho;
    if (!s.waypoints) {
      Json p{{"region", s.region}, {"iterations", s.planner_iterations}};
      if (!s.weights.empty()) p["weights"] = s.weights;
      d["planner"] = p;
    }
  }
  d["trajectory"] = t;
  if (s.command_dropout) d["command_dropout_s"] = Json::array({s.command_dropout->first, s.command_dropout->second});
  return d;
}

void check_scenario(const Scenario& s) {
  const std::string origin = (s.origin.empty() ? std::string("scenario") : s.origin) + " (the Scenario struct)";
  // Tenth campaign recheck: a scenario whose map was reset to null crashed build_reference.
  if (!s.map) throw Error(origin + ": map: none (a scenario needs its map)");
  // L12: the struct's fields are public; whatever was changed after reading is checked by the
  // reader's own rules, the struct written back as a document.
  const Json doc = scenario_document(s);
  Scenario copy;
  copy.map = s.map;
  read_scenario_fields(JsonField(doc, "", origin), origin, "", s.trajectory_file.has_value(), copy);
  // The emulated N3's own constants are not scenario keys (a file sets only its rate, latency,
  // timeout, failsafe, tilt and yaw-rate limits; its speed limits follow trajectory.v_max): a
  // struct that changed one is not a scenario a file could say, and its run folder's
  // scenario.json would fly another N3.
  flight::FlightSetup flown = s;
  apply_speed_limit(flown, s.limits);
  using N3 = flight::n3::Config;
  for (const auto& [name, field] : {std::pair{"land_speed", &N3::land_speed},
                                    std::pair{"max_horizontal_speed", &N3::max_horizontal_speed},
                                    std::pair{"max_vertical_speed", &N3::max_vertical_speed},
                                    std::pair{"horizontal_velocity_gain", &N3::horizontal_velocity_gain},
                                    std::pair{"vertical_velocity_gain", &N3::vertical_velocity_gain},
                                    std::pair{"horizontal_velocity_integral_gain", &N3::horizontal_velocity_integral_gain},
                                    std::pair{"vertical_velocity_integral_gain", &N3::vertical_velocity_integral_gain},
                                    std::pair{"velocity_integral_limit", &N3::velocity_integral_limit}})
    if (!(flown.n3.*field == copy.n3.*field))
      throw Error(origin + ": n3." + name + ": " + short_number(flown.n3.*field) + " is not the emulated N3's " +
                  short_number(copy.n3.*field) + " (not a scenario key: a run folder could not fly it again)");
  for (const auto& [name, field] : {std::pair{"attitude_gain", &N3::attitude_gain}, std::pair{"rate_gain", &N3::rate_gain}})
    if (!(flown.n3.*field == copy.n3.*field))
      throw Error(origin + ": n3." + name + ": differs from the emulated N3's (not a scenario key: a run folder could not fly it again)");
  // What the reader copies: the EKF models the sensors it is given.
  if (to_json(s.ekf.imu) != to_json(s.imu) || to_json(s.ekf.pose) != to_json(s.pose))
    throw Error(origin + ": ekf.imu / ekf.pose differ from imu / pose: the EKF's noise model is the sensors' " +
                "(set both, as the scenario reader does)");
}

Json self_contained_scenario(Json doc, const std::string& base_dir) {
  const auto absolute = [&](const std::string& path) {
    return std::filesystem::absolute(resolve(base_dir, path)).lexically_normal().string();
  };
  if (!doc.is_object()) return doc;  // scenario_from_json names the fault
  if (doc.contains("map") && doc["map"].is_string()) {
    const std::string map = resolve(base_dir, doc["map"].get<std::string>());
    // `map` is already resolved against base_dir: made absolute as it is (eleventh campaign C1:
    // resolving it a second time recorded "scen/out/m.bt" for "../out/m.bt" of scen/x.json).
    doc["map"] = std::filesystem::path(map).extension() == ".json"
                     ? read_json_file(map)
                     : Json(std::filesystem::absolute(map).lexically_normal().string());
    // An inlined map's voxel file is relative to the map's folder, not the scenario's.
    Json& m = doc["map"];
    if (m.is_object() && m.contains("voxels") && m["voxels"].is_object() && m["voxels"].contains("file") &&
        m["voxels"]["file"].is_string()) {
      const std::string map_dir = std::filesystem::path(map).parent_path().string();
      m["voxels"]["file"] = std::filesystem::absolute(resolve(map_dir, m["voxels"]["file"].get<std::string>()))
                                .lexically_normal()
                                .string();
    }
  }
  if (doc.contains("vehicle") && doc["vehicle"].is_string()) {
    try {
      doc["vehicle"] = read_json_file(resolve(base_dir, doc["vehicle"].get<std::string>()));
    } catch (const Error&) {
      // left as the path: scenario_from_json names the fault through the scenario's field
    }
  }
  // ... and recorded by content: a run folder flies again only with the same files (F11).
  for (const auto& [block, key] : {std::pair{"trajectory", "file"}, std::pair{"planner", "weights"}}) {
    if (doc.contains(block) && doc[block].is_object() && doc[block].contains(key) && doc[block][key].is_string()) {
      const std::string path = absolute(doc[block][key].get<std::string>());
      doc[block][key] = path;
      try {
        doc[block][std::string(key) + "_sha256"] = sha256_hex(read_file_bytes(path));
      } catch (const Error&) {
        // left unrecorded: scenario_from_json names the missing file
      }
    }
  }
  return doc;
}

std::vector<std::string> scenario_inputs(const Json& doc, const std::string& base_dir) {
  std::vector<std::string> files;
  if (!doc.is_object()) return files;
  const auto add = [&](const std::string& dir, const Json& v) {
    if (v.is_string()) files.push_back(std::filesystem::absolute(resolve(dir, v.get<std::string>())).lexically_normal().string());
  };
  if (doc.contains("map")) {
    const Json& m = doc["map"];
    add(base_dir, m);
    // The map's voxel file, relative to the map's own folder (or the scenario's, inlined).
    Json map_doc = m;
    std::string map_dir = base_dir;
    if (m.is_string() && std::filesystem::path(m.get<std::string>()).extension() == ".json") {
      const std::string map_path = resolve(base_dir, m.get<std::string>());
      map_dir = std::filesystem::path(map_path).parent_path().string();
      std::error_code ec;
      if (std::filesystem::is_regular_file(map_path, ec)) {
        try {
          map_doc = read_json_file(map_path);
        } catch (const Error&) {
          map_doc = nullptr;  // scenario_from_json names the fault
        }
      }
    }
    if (map_doc.is_object() && map_doc.contains("voxels") && map_doc["voxels"].is_object() &&
        map_doc["voxels"].contains("file"))
      add(map_dir, map_doc["voxels"]["file"]);
  }
  if (doc.contains("vehicle")) add(base_dir, doc["vehicle"]);
  for (const auto& [block, key] : {std::pair{"trajectory", "file"}, std::pair{"planner", "weights"}})
    if (doc.contains(block) && doc[block].is_object() && doc[block].contains(key)) add(base_dir, doc[block][key]);
  return files;
}

Scenario load_scenario(const std::string& path) {
  return scenario_from_json(read_json_file(path), path, std::filesystem::path(path).parent_path().string());
}


namespace {

/// Sampling step of the thrust and tilt envelope check (the v_max / a_max checks use
/// exact_extremes): 1 ms resolves every polynomial of these orders on segments of tenths of
/// seconds and more.
constexpr double kLimitSampleStep = 1e-3;
/// A trajectory may exceed v_max / a_max by this relative amount (the peaks' rounding).
constexpr double kLimitSlack = 1e-6;
/// Whether sampled peaks v, a break the limits beyond kLimitSlack: the one test of a reference's
/// limits, used where a reference is built and where it is checked before flying (fifteenth
/// campaign F3: the builder stretched time only past sqrt(a / a_max) > 1 + kLimitSlack, which
/// let a exceed a_max (1 + kLimitSlack) by up to 2e-6 relative, and the check then refused the
/// reference it had just built).
/// v and a are exact_extremes(): a 1 ms sampling of a 0.4 s reference missed its peaks by
/// ~1e-5 relative, more than kLimitSlack, and the peak sampled after a time stretch differed.
bool over_limit(double peak, double limit) { return peak > limit * (1 + kLimitSlack); }
bool exceeds_limits(double v, double a, const traj::Limits& limits) {
  return over_limit(v, limits.v_max) || over_limit(a, limits.a_max);
}

/// Start/end states must match to this (m, m/s, m/s^2).
constexpr double kEndpointTolerance = 1e-6;

/// Refuses a reference that, with the hover after it, would fly longer than
/// kMaxFlightSeconds: before its 1 ms sampling or any simulation (issue 20: unbounded work).
/// `from_file`: the durations are the trajectory file's, not allocated from the limits, so the
/// advice names them (fifth campaign: a 1e9 s file was told to raise v_max).
void require_flight_length(const Scenario& s, const traj::PolynomialTrajectory& t, bool from_file = false) {
  const double total = t.total_duration() + s.hover_after_s;
  if (!(total <= kMaxFlightSeconds)) {
    const std::string advice =
        from_file ? "shorten the trajectory file's segment durations or the hover"
                  : "raise trajectory.v_max / a_max (now " + short_number(s.limits.v_max) + " m/s, " +
                        short_number(s.limits.a_max) + " m/s^2) or shorten the route";
    throw Error(s.origin + ": the flight would last " + short_number(total) + " s (reference " +
                short_number(t.total_duration()) + " s + hover " + short_number(s.hover_after_s) + " s), more than the " +
                std::to_string(static_cast<int>(kMaxFlightSeconds)) + " s a simulated flight may; " + advice);
  }
}

/// The reference runs from the scenario's start to its goal, at rest at both ends.
void check_reference_ends(const Scenario& s, const traj::PolynomialTrajectory& t) {
  const double T = t.total_duration();
  if ((t.evaluate(0.0) - s.start).norm() > kEndpointTolerance || (t.evaluate(T) - s.goal).norm() > kEndpointTolerance)
    throw Error(s.origin + ": the reference trajectory must start at start " + format_point(s.start) +
                " and end at goal " + format_point(s.goal) + "; it runs from " + format_point(t.evaluate(0.0)) +
                " to " + format_point(t.evaluate(T)));
  for (int k = 1; k <= 2; ++k)
    if (t.evaluate(0.0, k).norm() > kEndpointTolerance || t.evaluate(T, k).norm() > kEndpointTolerance)
      throw Error(s.origin + ": the reference trajectory must start and end at rest (the vehicle starts hovering)");
}

void check_envelope(const Scenario& s, const traj::PolynomialTrajectory& t) {
  const double max_tilt = kEnvelopeMargin * deg2rad(s.controller.max_tilt_deg);
  const double max_thrust = kEnvelopeMargin * s.vehicle.max_thrust();
  for (int i = 0; i < t.segments(); ++i) {
    const double T = t.durations()[static_cast<std::size_t>(i)];
    const int n = std::max(1, static_cast<int>(std::ceil(T / kLimitSampleStep)));
    for (int k = 0; k <= n; ++k) {
      // Thrust per unit mass: the acceleration, gravity and the drag at the reference's speed (an
      // upper bound: the largest linear coefficient, the quadratic one and the rotors' drag at
      // hover speed). Seventh campaign C4: 100 N s/m of drag at 0.8 m/s asked 80 N of a 42 N
      // vehicle, accepted and blamed on the flight.
      const Eigen::Vector3d v = t.evaluate_segment(i, T * k / n, 1);
      const double speed = v.norm();
      const double drag = (s.vehicle.linear_drag.maxCoeff() +
                           4.0 * s.vehicle.rotor_drag * s.vehicle.hover_rotor_speed() +
                           s.vehicle.quadratic_drag * speed) * speed;
      Eigen::Vector3d f = t.evaluate_segment(i, T * k / n, 2) + Eigen::Vector3d(0, 0, kGravity);
      if (speed > 0.0) f += (drag / s.vehicle.mass) * v / speed;
      const double tilt = std::atan2(f.head<2>().norm(), f.z());
      if (tilt > max_tilt || s.vehicle.mass * f.norm() > max_thrust)
        throw Error(s.origin + ": the reference trajectory needs " + short_number(tilt * 180.0 / kPi) +
                    " deg of tilt and " + short_number(s.vehicle.mass * f.norm()) + " N of thrust (acceleration, " +
                    "gravity and " + short_number(drag) + " N of drag at " + short_number(speed) + " m/s) in segment " +
                    std::to_string(i) + "; the vehicle allows " + short_number(max_tilt * 180.0 / kPi) + " deg and " +
                    short_number(max_thrust) + " N (" + short_number(kEnvelopeMargin) +
                    " of its limits): lower trajectory.v_max / a_max or the vehicle's drag");
    }
  }
}

}  // namespace

Json reference_fields(const Scenario& s) {
  const Json doc = scenario_document(s);
  char fingerprint[17];
  std::snprintf(fingerprint, sizeof fingerprint, "%016llx", static_cast<unsigned long long>(s.map->fingerprint()));
  Json fields{{"map", fingerprint}, {"vehicle.radius", s.vehicle.radius}};
  for (const char* key : {"start", "goal", "planning_margin_m", "waypoints", "trajectory", "planner"})
    if (doc.contains(key)) fields[key] = doc[key];
  // The seed draws the planner's samples; with waypoints or a file it only draws the flight's noise.
  if (doc.contains("planner")) fields["seed"] = doc["seed"];
  if (s.trajectory_file)
    fields["trajectory"]["file_sha256"] = sha256_hex(dump_json(traj::answer_to_json(*s.trajectory_file)));
  // The network is its bytes, not its path (eighteenth campaign F18: a copy of the weights at
  // another path was refused, weights overwritten after the build were flown): the shipped
  // network's hash when none is named.
  if (fields.contains("planner") && s.region == "sgan") {
    static const std::string builtin = heuristic::Sgan::builtin().sha256();
    fields["planner"].erase("weights");
    fields["planner"]["weights_sha256"] = s.weights.empty() ? builtin : sha256_hex(read_file_bytes(s.weights));
  }
  return fields;
}

ReferencePlan build_reference(const Scenario& s) {
  check_scenario(s);
  ReferencePlan r;
  r.built_from = reference_fields(s);
  // Plan and repair with the tracking margin added: a reference that grazes the inflated
  // map would be left by any tracking error (the flight checks the vehicle radius alone).
  const double radius = s.vehicle.radius + s.planning_margin;
  // The body at the ends stays inside the map: an end on a face (a start on the floor) put half
  // the vehicle outside, and the flight "collided" with no obstacle there (issue 20, eighth
  // campaign U2); it would now leave the map at once (REQ-FLIGHT-009).
  // Waypoints too (the recheck: a waypoint on a face flew out of the map). A hair of rounding
  // is forgiven: a goal at z = 4.7 in a 5 m map for a 0.3 m body is 0.3 m inside.
  constexpr double kFaceRounding = 1e-9;  // m
  std::vector<std::pair<Eigen::Vector3d, std::string>> ends{{s.start, "start"}, {s.goal, "goal"}};
  if (s.waypoints)
    for (Eigen::Index i = 0; i < s.waypoints->rows(); ++i)
      ends.emplace_back(s.waypoints->row(i).transpose(), "waypoints[" + std::to_string(i) + "]");
  for (const auto& [p, name] : ends) {
    const world::Box& b = s.map->bounds();
    const Eigen::Vector3d inside = (p - b.min).cwiseMin(b.max - p);
    Eigen::Index axis = 0;
    if (inside.minCoeff(&axis) < s.vehicle.radius - kFaceRounding) {
      const bool low = p[axis] - b.min[axis] <= b.max[axis] - p[axis];
      std::ostringstream os;
      os << s.origin << ": " << name << " " << format_point(p) << " is " << short_number(inside[axis])
         << " m from the map's " << (low ? "min" : "max") << " " << "xyz"[axis] << " = "
         << short_number(low ? b.min[axis] : b.max[axis]) << ", less than the vehicle radius "
         << short_number(s.vehicle.radius) << " m: the body would stick out of the map; move " << name
         << " inside";
      throw Error(os.str());
    }
  }
  if (s.trajectory_file) {
    r.trajectory = *s.trajectory_file;
    r.source = "file";
    const int m = r.trajectory.segments();
    r.path.resize(m + 1, 3);
    for (int i = 0; i < m; ++i) r.path.row(i) = r.trajectory.evaluate_segment(i, 0.0).transpose();
    r.path.row(m) = r.trajectory.evaluate(r.trajectory.total_duration()).transpose();
    require_flight_length(s, r.trajectory, true);
    const auto [v, a] = traj::exact_extremes(r.trajectory);
    if (exceeds_limits(v, a, s.limits)) {
      // Only the limit exceeded is named, with the field that sets it (eighteenth campaign F4:
      // a speed within v_max was said to exceed it beside an acceleration that did).
      const traj::Limits defaults = Scenario{}.limits;
      const auto over = [&](const char* what, double value, const char* field, double limit, double fallback,
                            const char* unit) {
        return std::string(what) + " " + short_number(value) + " " + unit + " exceeds trajectory." + field + " " +
               short_number(limit) + " " + unit + " (set trajectory." + field + " in the scenario to allow more; " +
               "without it the limit is " + short_number(fallback) + " " + unit + ")";
      };
      std::string why;
      if (over_limit(v, s.limits.v_max)) why = over("maximum speed", v, "v_max", s.limits.v_max, defaults.v_max, "m/s");
      if (over_limit(a, s.limits.a_max))
        why += (why.empty() ? "" : ", and its ") + over("maximum acceleration", a, "a_max", s.limits.a_max, defaults.a_max, "m/s^2");
      throw Error(s.origin + ": trajectory file: its " + why);
    }
    // Chords collision_sample_step apart (a step of 0 here once cast infinity to int and
    // checked two chords per segment; tenth campaign, found beside L10).
    const auto colliding =
        traj::colliding_segments(r.trajectory, *s.map, radius, traj::collision_sample_step(*s.map, radius));
    if (!colliding.empty())
      throw Error(s.origin + ": trajectory file: segment " + std::to_string(colliding.front()) +
                  " comes within the vehicle radius + planning margin (" + std::to_string(radius) +
                  " m) of an obstacle");
  } else {
    // The ends must keep the radius the plan keeps; named with the scenario's keys (issue 20,
    // fifth campaign: `planning_margin_m: 5` was reported as "within the robot radius 5.3").
    for (const auto& [p, name] : {std::pair<Eigen::Vector3d, const char*>{s.start, "start"}, {s.goal, "goal"}}) {
      const double c = s.map->clearance(p);
      if (c < radius) {
        std::ostringstream os;
        os << s.origin << ": " << name << " " << format_point(p) << " has clearance " << short_number(c)
           << " m, less than the vehicle radius " << short_number(s.vehicle.radius) << " m + planning_margin_m "
           << short_number(s.planning_margin) << " m the plan keeps; lower planning_margin_m or move the " << name;
        throw Error(os.str());
      }
    }
    Eigen::MatrixX3d path;
    if (s.waypoints) {
      r.source = "waypoints";
      path.resize(s.waypoints->rows() + 2, 3);
      path.row(0) = s.start.transpose();
      path.middleRows(1, s.waypoints->rows()) = *s.waypoints;
      path.row(path.rows() - 1) = s.goal.transpose();
      // Collision repair moves a trajectory off obstacles around a free polyline: each leg must
      // be one (issue 20, fifth campaign: a leg through an obstacle named no file or key).
      const Eigen::Index legs = path.rows() - 1;
      for (Eigen::Index i = 0; i < legs; ++i) {
        const Eigen::Vector3d a = path.row(i).transpose(), b = path.row(i + 1).transpose();
        if (!s.map->segment_free(a, b, radius)) {
          const auto end = [&](Eigen::Index k) {
            return k == 0 ? std::string("start") : k == legs ? std::string("goal") : "waypoints[" + std::to_string(k - 1) + "]";
          };
          std::ostringstream os;
          os << s.origin << ": waypoints: the straight leg from " << end(i) << " " << format_point(a) << " to " << end(i + 1)
             << " " << format_point(b) << " passes within the vehicle radius + planning margin (" << short_number(radius)
             << " m) of an obstacle; waypoints must be joined by collision-free straight legs";
          throw Error(os.str());
        }
      }
    } else {
      r.source = "planner";
      const auto problem = plan::PlanningProblem::make(*s.map, s.start, s.goal, radius);
      auto t0 = std::chrono::steady_clock::now();
      if (s.region == "astar") {
        const auto reference = plan::astar_reference(problem);
        r.region = plan::astar_dilated_region(problem, reference, plan::HeuristicRegion::default_dims(), 1);
      } else {
        const auto sgan = heuristic::Sgan::load_or_builtin(s.weights);
        r.region = heuristic::query_region(sgan, *s.map, s.start, s.goal, radius, s.seed).region;
      }
      r.stage_ms.emplace_back("region", elapsed_ms(t0));
      plan::PlannerOptions options;
      options.planner = plan::PlannerKind::kMiner;
      options.seed = s.seed;
      options.max_iterations = s.planner_iterations;
      options.record_tree = true;
      t0 = std::chrono::steady_clock::now();
      auto result = plan::plan(problem, options, &*r.region);
      r.stage_ms.emplace_back("plan", elapsed_ms(t0));
      if (!result.solved) throw NoSolution(s.origin + ": MINER RRT* found no path: " + result.reason);
      path.resize(static_cast<Eigen::Index>(result.path.size()), 3);
      for (std::size_t i = 0; i < result.path.size(); ++i) path.row(static_cast<Eigen::Index>(i)) = result.path[i].transpose();
      r.planner_iterations = result.iterations;
      r.tree_vertices = std::move(result.tree_vertices);
      r.tree_parents = std::move(result.tree_parents);
      r.planned_path = path;
    }
    const auto t_traj = std::chrono::steady_clock::now();
    traj::RepairOptions options;
    options.order = s.order;
    options.limits = s.limits;
    options.robot_radius = radius;
    if (s.allocation == "optimise") {
      traj::AllocationOptions a;
      a.rho = s.rho;
      options.optimise = a;
    }
    traj::RepairResult repaired;
    try {
      repaired = traj::repair_collisions(*s.map, path, options);
    } catch (const NoSolution&) {
      throw;
    } catch (const Error& e) {
      // Named through the scenario (sixteenth campaign F15: "this problem has 65" named no file
      // and no key); the planned or given route is free, so what fails here is the allocation.
      throw Error(s.origin + ": trajectory.allocation: \"" + s.allocation + "\": " + e.what());
    }
    r.allocation = repaired.allocation;
    r.trajectory = std::move(repaired.trajectory);
    r.path = std::move(repaired.waypoints);
    require_flight_length(s, r.trajectory);
    const auto [v, a] = traj::exact_extremes(r.trajectory);
    if (exceeds_limits(v, a, s.limits)) {
      // Stretching time by k divides v by k and a by k^2; the extra (1 + kLimitSlack) leaves
      // room for the peaks' rounding, so the check below and check_reference() pass.
      const double k = std::max({1.0, v / s.limits.v_max, std::sqrt(a / s.limits.a_max)});
      r.time_scale = k * (1.0 + kLimitSlack);
      traj::scale_time(r.trajectory, r.time_scale);
      require_flight_length(s, r.trajectory);
    }
    r.stage_ms.emplace_back("trajectory", elapsed_ms(t_traj));
  }
  check_reference_ends(s, r.trajectory);
  check_envelope(s, r.trajectory);
  const auto [v, a] = traj::exact_extremes(r.trajectory);
  r.max_speed = v;
  r.max_acceleration = a;
  return r;
}

void check_reference(const Scenario& s, const ReferencePlan& reference) {
  // A reference is flown only in the scenario it was built for (issue 20, ninth campaign P8:
  // from Python a reference of another scenario flew from another start, through walls, or
  // at 7x the scenario's v_max, and came back as an ordinary flight).
  const traj::PolynomialTrajectory& t = reference.trajectory;
  check_reference_ends(s, t);
  require_flight_length(s, t, reference.source == "file");
  const auto [v, a] = traj::exact_extremes(t);
  if (exceeds_limits(v, a, s.limits))
    throw Error(s.origin + ": the reference's maximum speed " + short_number(v) + " m/s and acceleration " +
                short_number(a) + " m/s^2 exceed the scenario's trajectory.v_max " + short_number(s.limits.v_max) +
                " m/s, a_max " + short_number(s.limits.a_max) + " m/s^2: build the reference from this scenario");
  check_envelope(s, t);
  const auto colliding =
      traj::colliding_segments(t, *s.map, s.vehicle.radius, traj::collision_sample_step(*s.map, s.vehicle.radius));
  if (!colliding.empty())
    throw Error(s.origin + ": the reference's segment " + std::to_string(colliding.front()) +
                " comes within the vehicle radius " + short_number(s.vehicle.radius) +
                " m of an obstacle of the scenario's map: build the reference from this scenario");
  // A disturbance window that opens after the flight ends would never act (ninth campaign C5).
  const double end = t.total_duration() + s.hover_after_s;
  if (s.command_dropout && s.command_dropout->first >= end)
    throw Error(s.origin + ": command_dropout_s: starts at " + short_number(s.command_dropout->first) +
                " s, after the flight ends at " + short_number(end) + " s (reference " +
                short_number(t.total_duration()) + " s + hover " + short_number(s.hover_after_s) +
                " s): it would never happen");
  for (std::size_t i = 0; i < s.wind.gusts.size(); ++i)
    if (s.wind.gusts[i].start_s >= end)
      throw Error(s.origin + ": wind.gusts[" + std::to_string(i) + "].start_s: " + short_number(s.wind.gusts[i].start_s) +
                  " s is after the flight ends at " + short_number(end) + " s: the gust would never blow");
  // ... and built from this scenario's fields, not only ending where it does and keeping its
  // limits (seventeenth campaign F18: a planned reference of seed 1 flew in the scenario of seed 2).
  if (!reference.built_from.is_null()) {
    const Json here = reference_fields(s);
    for (const auto& [key, value] : here.items()) {
      if (reference.built_from.contains(key) && reference.built_from[key] == value) continue;
      // Within a block (planner, trajectory) the member that differs is named.
      std::string field = key;
      Json there = reference.built_from.contains(key) ? reference.built_from[key] : Json(), mine = value;
      if (there.is_object() && mine.is_object()) {
        std::string differing;
        for (const auto& [sub, member] : mine.items())
          if (!there.contains(sub) || there[sub] != member) {
            differing = sub;
            break;
          }
        if (!differing.empty()) {
          field = key + "." + differing;
          const Json member = mine[differing];
          there = there.contains(differing) ? Json(there[differing]) : Json();
          mine = member;
        }
      }
      throw Error(s.origin + ": " + field + ": the reference was built from a scenario whose " + field +
                  " differs from this one's" +
                  (!there.is_null() && mine.is_primitive() ? " (" + there.dump() + " there, " + mine.dump() + " here)"
                                                           : std::string()) +
                  ": build the reference from this scenario");
    }
    for (const auto& [key, value] : reference.built_from.items())
      if (!here.contains(key))
        throw Error(s.origin + ": " + key + ": the reference was built from a scenario that sets " + key +
                    ", which this one does not: build the reference from this scenario");
  }
}

flight::FlightResult fly(const Scenario& scenario, const ReferencePlan& reference, const flight::FlyOptions& options) {
  check_scenario(scenario);
  check_reference(scenario, reference);
  flight::FlightSetup setup = scenario;
  apply_speed_limit(setup, scenario.limits);  // a struct built in C++ flies what its file would
  const std::shared_ptr<const world::Map> map = scenario.map;
  const double radius = scenario.vehicle.radius;
  setup.collides = [map, radius](const Eigen::Vector3d& p) { return !map->is_free(p, radius); };
  setup.world = Eigen::AlignedBox3d(map->bounds().min, map->bounds().max);
  flight::FlyOptions o = options;
  o.use_ground_truth = o.use_ground_truth || scenario.controller_reads_truth;
  return flight::fly(setup, reference, o);
}

}  // namespace miner::pipeline
