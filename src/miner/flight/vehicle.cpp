#include "miner/flight/vehicle.hpp"

#include <cmath>
#include <cstdio>

#include <Eigen/LU>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/core/units.hpp"

namespace miner::flight {

namespace {
constexpr double kTiltLimitRad = deg2rad(kN3MaxTiltDeg);

[[noreturn]] void bad(const std::string& origin, const std::string& field, const std::string& why) {
  throw Error(origin + ": " + field + ": " + why);
}
}  // namespace

double min_thrust_to_weight() { return 1.0 / std::cos(kTiltLimitRad); }

double VehicleParams::max_thrust() const {
  return 4.0 * thrust_coefficient * rotor_speed_max * rotor_speed_max;
}

double VehicleParams::hover_rotor_speed() const {
  return std::sqrt(weight() / (4.0 * thrust_coefficient));
}

void validate(const VehicleParams& v, const std::string& origin) {
  // Each value positive and at most `hi`: bounds far above any multirotor (a 1 t, 20 m vehicle)
  // that still refuse the absurd (issue 20: values near 1e308 flew).
  auto positive = [&](double x, const char* field, double hi) {
    if (!std::isfinite(x) || !(x > 0.0) || x > hi) {
      // The value as written, every digit it needs (fifteenth campaign F13: 1000.001 was shown
      // as "got 1000", in range to the eye).
      char text[160];
      std::snprintf(text, sizeof text, "must be a finite number in (0, %g], got ", hi);
      bad(origin, field, text + (std::isfinite(x) ? Json(x).dump() : std::string(std::isnan(x) ? "nan" : (x > 0 ? "inf" : "-inf"))));
    }
  };
  // A struct's name, by the file's rule (the Python module and C++ callers set it directly).
  if (!is_plain_name(v.name)) bad(origin, "name", std::string(kPlainNameRule) + ", got " + quoted_excerpt(v.name));
  positive(v.mass, "mass_kg", 1000.0);
  for (int i = 0; i < 3; ++i) positive(v.inertia[i], "inertia_kg_m2", 1000.0);
  positive(v.arm_length, "arm_length_m", 10.0);
  positive(v.thrust_coefficient, "thrust_coefficient_N_per_rad_s2", 1.0);
  positive(v.torque_to_thrust_ratio, "torque_to_thrust_ratio_m", 1.0);
  positive(v.rotor_speed_max, "rotor_speed_max_rad_s", 1e5);
  for (const auto& [tau, field] : {std::pair{v.motor_time_constant_up, "motor_time_constant_up_s"},
                                   std::pair{v.motor_time_constant_down, "motor_time_constant_down_s"}})
    if (!std::isfinite(tau) || !(tau >= kMinPlantTimeConstant) || tau > kMaxMotorTimeConstant) {
      char text[240];
      std::snprintf(text, sizeof text,
                    "must be a finite number in [%g, %g] s (real motors respond in 10-100 ms; shorter ones are "
                    "too stiff for the integrator, slower ones lose the N3's attitude loop), got ",
                    kMinPlantTimeConstant, kMaxMotorTimeConstant);
      bad(origin, field, text + (std::isfinite(tau) ? Json(tau).dump() : std::string("a value that is not finite")));
    }
  positive(v.radius, "radius_m", kMaxRobotRadius);
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v.linear_drag[i]) || v.linear_drag[i] < 0.0 || v.linear_drag[i] > 100.0)
      bad(origin, "linear_drag_N_s_per_m", "must be finite and in [0, 100]");
    const double j = v.inertia[i], a = v.inertia[(i + 1) % 3], b = v.inertia[(i + 2) % 3];
    if (j > a + b)
      bad(origin, "inertia_kg_m2", "principal moments violate the triangle inequality (" +
                                       std::to_string(j) + " > " + std::to_string(a) + " + " +
                                       std::to_string(b) + "): no rigid body has them");
  }
  // At w_max on all four rotors, 0.01 N/(m/s)/(rad/s) is ~50 N per m/s: far above any multirotor.
  if (!std::isfinite(v.rotor_drag) || v.rotor_drag < 0.0 || v.rotor_drag > 0.01)
    bad(origin, "rotor_drag_N_s_per_m_rad", "must be finite and in [0, 0.01]");
  if (!std::isfinite(v.quadratic_drag) || v.quadratic_drag < 0.0 || v.quadratic_drag > 100.0)
    bad(origin, "quadratic_drag_N_s2_per_m2", "must be finite and in [0, 100]");
  // The rotors' own range first: the checks below derive torques and lags from it (issue 20,
  // eighth campaign U1: min > max was blamed on the inertia, with a negative torque).
  if (!std::isfinite(v.rotor_speed_min) || v.rotor_speed_min < 0.0 ||
      v.rotor_speed_min >= v.rotor_speed_max)
    bad(origin, "rotor_speed_min_rad_s", "must satisfy 0 <= min < rotor_speed_max_rad_s");
  if (v.thrust_to_weight() < min_thrust_to_weight())
    bad(origin, "rotor_speed_max_rad_s",
        "maximum thrust " + std::to_string(v.max_thrust()) + " N gives a thrust-to-weight ratio of " +
            std::to_string(v.thrust_to_weight()) + " < " + std::to_string(min_thrust_to_weight()) +
            " (weight " + std::to_string(v.weight()) +
            " N): the vehicle cannot hold altitude at the 35 deg tilt limit");
  if (4.0 * v.thrust_coefficient * v.rotor_speed_min * v.rotor_speed_min >= v.weight())
    bad(origin, "rotor_speed_min_rad_s", "idle thrust carries the whole weight: the vehicle cannot descend");
  // The collision sphere holds the rotors' axes at least: a 1 m arm inside a 0.3 m sphere flew
  // through obstacles its rotors would hit, counted "collisions 0" (issue 20, seventh campaign W5).
  if (v.radius < v.arm_length) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%g m is smaller than arm_length_m %g m: the collision sphere must hold the rotors (at least "
                  "the arm length; add the propeller radius)",
                  v.radius, v.arm_length);
    bad(origin, "radius_m", text);
  }
  // The rotors must turn the body to the tilt limit in time for the position loop: rest to
  // rest through kTiltLimitRad under the largest roll/pitch torque (two rotors at w_max, two
  // at w_min, lever arm_length / sqrt 2) takes 2 sqrt(theta J / tau_max). Seventh campaign C4:
  // an inertia of 100 kg m^2 was accepted and left the map by hundreds of metres.
  const double rotor_span = v.thrust_coefficient * (v.rotor_speed_max * v.rotor_speed_max -
                                                    v.rotor_speed_min * v.rotor_speed_min);
  const double torque_max = 2.0 * rotor_span * v.arm_length / std::sqrt(2.0);
  const double tilt_time = 2.0 * std::sqrt(kTiltLimitRad * std::max(v.inertia.x(), v.inertia.y()) / torque_max);
  if (!(tilt_time <= kMaxTiltTime)) {
    char text[260];
    std::snprintf(text, sizeof text,
                  "the rotors' largest roll/pitch torque %g N m turns this inertia to the %g deg tilt limit in %g s at "
                  "best, more than the %g s a position loop can wait: the vehicle cannot follow a trajectory",
                  torque_max, kN3MaxTiltDeg, tilt_time, kMaxTiltTime);
    bad(origin, "inertia_kg_m2", text);
  }
  // The rotors must hold the heading too: rest to rest through kTiltLimitRad about z under the
  // largest yaw torque (two rotors at w_max, two at w_min: 2 k_m (T_max - T_min) per pair) takes
  // 2 sqrt(theta J_z / tau_z) (fifteenth campaign F12: a torque ratio of 1e-12 was accepted and
  // the vehicle left the map).
  const double yaw_torque_max = 2.0 * v.torque_to_thrust_ratio * rotor_span;
  const double yaw_time = 2.0 * std::sqrt(kTiltLimitRad * v.inertia.z() / yaw_torque_max);
  if (!(yaw_time <= kMaxYawTime)) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "the rotors' largest yaw torque %g N m (torque_to_thrust_ratio_m %g) turns this vehicle's J_z %g "
                  "kg m^2 by %g deg in %g s at best, more than the %g s that holds its heading: raise the ratio "
                  "(propellers give 0.005-0.03 m)",
                  yaw_torque_max, v.torque_to_thrust_ratio, v.inertia.z(), kN3MaxTiltDeg, yaw_time, kMaxYawTime);
    bad(origin, "torque_to_thrust_ratio_m", text);
  }
  // The drag's lag, mass over the linear coefficients at full rotor speed, is a plant time
  // constant too: a 1 g vehicle with 100 N s/m of drag is as stiff as a 10 us motor.
  const double linear_coefficient = v.linear_drag.maxCoeff() + 4.0 * v.rotor_drag * v.rotor_speed_max;
  if (linear_coefficient > 0.0 && v.mass / linear_coefficient < kMinPlantTimeConstant) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "mass %g kg over the linear drag %g N s/m (at full rotor speed) is a lag of %g s, shorter than the "
                  "%g s the integrator takes: a vehicle this light cannot carry this much drag",
                  v.mass, linear_coefficient, v.mass / linear_coefficient, kMinPlantTimeConstant);
    bad(origin, "linear_drag_N_s_per_m", text);
  }
}

VehicleParams vehicle_from_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  root.require_format(kVehicleFormat);
  root.only_keys({"format", "name", "mass_kg", "inertia_kg_m2", "arm_length_m", "thrust_coefficient_N_per_rad_s2",
                  "torque_to_thrust_ratio_m", "rotor_speed_min_rad_s", "rotor_speed_max_rad_s",
                  "motor_time_constant_up_s", "motor_time_constant_down_s", "linear_drag_N_s_per_m", "radius_m",
                  "rotor_drag_N_s_per_m_rad", "quadratic_drag_N_s2_per_m2"});
  VehicleParams v;
  if (root.has("name")) {
    v.name = root.at("name").string();
    // Copied into summaries and reports: the scenario name's rule (sixteenth campaign F24: an
    // empty name, a NUL, newlines or 100 kB were copied as they were).
    if (!is_plain_name(v.name)) root.at("name").fail(std::string(kPlainNameRule) + ", got " + quoted_excerpt(v.name));
  } else {
    // A file without a name is not the default vehicle: it is not reported under that vehicle's
    // name (seventeenth campaign F24: a 2 kg vehicle was "n3-class-1.5kg" in summary.json).
    v.name = kUnnamedVehicle;
  }
  v.mass = root.at("mass_kg").number();
  v.inertia = root.at("inertia_kg_m2").vec3();
  v.arm_length = root.at("arm_length_m").number();
  v.thrust_coefficient = root.at("thrust_coefficient_N_per_rad_s2").number();
  v.torque_to_thrust_ratio = root.at("torque_to_thrust_ratio_m").number();
  v.rotor_speed_min = root.at("rotor_speed_min_rad_s").number();
  v.rotor_speed_max = root.at("rotor_speed_max_rad_s").number();
  v.motor_time_constant_up = root.at("motor_time_constant_up_s").number();
  v.motor_time_constant_down = root.at("motor_time_constant_down_s").number();
  v.linear_drag = root.at("linear_drag_N_s_per_m").vec3();
  v.radius = root.at("radius_m").number();
  // The aerodynamic extras are optional: a vehicle file without them models linear drag only.
  if (root.has("rotor_drag_N_s_per_m_rad")) v.rotor_drag = root.at("rotor_drag_N_s_per_m_rad").number();
  if (root.has("quadratic_drag_N_s2_per_m2")) v.quadratic_drag = root.at("quadratic_drag_N_s2_per_m2").number();
  validate(v, origin);
  return v;
}

VehicleParams load_vehicle(const std::string& path) { return vehicle_from_json(read_json_file(path), path); }

Json to_json(const VehicleParams& v) {
  Json doc{{"format", kVehicleFormat},
              {"name", v.name},
              {"mass_kg", v.mass},
              {"inertia_kg_m2", vec3_json(v.inertia)},
              {"arm_length_m", v.arm_length},
              {"thrust_coefficient_N_per_rad_s2", v.thrust_coefficient},
              {"torque_to_thrust_ratio_m", v.torque_to_thrust_ratio},
              {"rotor_speed_min_rad_s", v.rotor_speed_min},
              {"rotor_speed_max_rad_s", v.rotor_speed_max},
              {"motor_time_constant_up_s", v.motor_time_constant_up},
              {"motor_time_constant_down_s", v.motor_time_constant_down},
              {"linear_drag_N_s_per_m", vec3_json(v.linear_drag)},
              {"radius_m", v.radius}};
  if (v.rotor_drag != 0.0) doc["rotor_drag_N_s_per_m_rad"] = v.rotor_drag;
  if (v.quadratic_drag != 0.0) doc["quadratic_drag_N_s2_per_m2"] = v.quadratic_drag;
  return doc;
}

Mixer::Mixer(const VehicleParams& v)
    : k_f_(v.thrust_coefficient), w_min_(v.rotor_speed_min), w_max_(v.rotor_speed_max) {
  const double c = v.arm_length / std::sqrt(2.0);
  // Rotors at 45, 135, 225, 315 degrees: (x, y) = c (+,+), (-,+), (-,-), (+,-).
  const double xs[4] = {c, -c, -c, c};
  const double ys[4] = {c, c, -c, -c};
  const double spin[4] = {1.0, -1.0, 1.0, -1.0};
  for (int i = 0; i < 4; ++i) {
    a_(0, i) = 1.0;
    a_(1, i) = ys[i];
    a_(2, i) = -xs[i];
    a_(3, i) = spin[i] * v.torque_to_thrust_ratio;
  }
  a_inv_ = a_.inverse();
}

Eigen::Vector4d Mixer::rotor_speeds(double thrust, const Eigen::Vector3d& torque) const {
  Eigen::Vector4d wrench;
  wrench << thrust, torque;
  const Eigen::Vector4d f = a_inv_ * wrench;
  Eigen::Vector4d w;
  for (int i = 0; i < 4; ++i) {
    const double wi = std::sqrt(std::max(f[i], 0.0) / k_f_);
    w[i] = std::min(std::max(wi, w_min_), w_max_);
  }
  return w;
}

}  // namespace miner::flight
