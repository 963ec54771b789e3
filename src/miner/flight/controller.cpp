#include "miner/flight/controller.hpp"

#include <algorithm>
#include <cmath>

#include "miner/core/error.hpp"
#include "miner/flight/dynamics.hpp"
#include "miner/flight/flatness.hpp"

namespace miner::flight {

ControllerParams controller_params_from_json(const JsonField& f) {
  f.only_keys({"rate_hz", "kp", "kv", "ki", "integral_limit", "max_tilt_deg", "max_speed_m_s", "yaw_mode",
               "yaw_gain"});
  ControllerParams c;
  if (f.has("rate_hz")) c.rate_hz = f.at("rate_hz").number_in(1.0, 10000.0, "Hz");
  // Gains above kMaxGain (1/s^2, 1/s, 1/s^3) make the loop's own discretisation unstable at any
  // rate the N3 allows (issue 20: kp 1e300 flew and diverged).
  constexpr double kMaxGain = 1000.0;
  auto gains = [&](const char* key, Eigen::Vector3d& g, bool allow_zero) {
    if (!f.has(key)) return;
    const JsonField field = f.at(key);
    g = field.vec3();
    if (allow_zero ? g.minCoeff() < 0.0 : !(g.minCoeff() > 0.0))
      field.fail(allow_zero ? "gains must be >= 0" : "gains must be positive");
    if (g.maxCoeff() > kMaxGain) field.fail("gains must be at most 1000, got " + field.value().dump());
  };
  gains("kp", c.kp, false);
  gains("kv", c.kv, false);
  gains("ki", c.ki, true);
  if (f.has("integral_limit")) {
    c.integral_limit = f.at("integral_limit").number_in(0.0, 100.0, "m/s^2");
    if (!(c.integral_limit > 0.0)) f.at("integral_limit").fail("must be positive");
  }
  if (f.has("max_tilt_deg")) {
    c.max_tilt_deg = f.at("max_tilt_deg").positive_number();
    if (c.max_tilt_deg >= 90.0) f.at("max_tilt_deg").fail("must be below 90");
  }
  if (f.has("max_speed_m_s")) {
    c.max_speed = f.at("max_speed_m_s").number_in(0.0, 100.0, "m/s");
    if (!(c.max_speed > 0.0)) f.at("max_speed_m_s").fail("must be positive");
  }
  if (f.has("yaw_mode")) {
    const std::string m = f.at("yaw_mode").string();
    if (m == "angle") c.yaw_mode = ControllerParams::YawMode::kAngle;
    else if (m == "rate") c.yaw_mode = ControllerParams::YawMode::kRate;
    else f.at("yaw_mode").fail("must be \"angle\" or \"rate\", got \"" + m + "\"");
  }
  if (f.has("yaw_gain")) {
    c.yaw_gain = f.at("yaw_gain").number_in(0.0, kMaxGain, "1/s");
    if (!(c.yaw_gain > 0.0)) f.at("yaw_gain").fail("must be positive");
    // Read by the rate mode only (ninth campaign recheck of C5: flown without effect).
    if (c.yaw_mode != ControllerParams::YawMode::kRate)
      f.at("yaw_gain").fail("unused: yaw_mode is \"angle\" (the default); yaw_gain applies to \"rate\" only");
  }
  return c;
}

Json to_json(const ControllerParams& c) {
  Json doc{{"rate_hz", c.rate_hz}, {"kp", vec3_json(c.kp)}, {"kv", vec3_json(c.kv)},
           {"ki", vec3_json(c.ki)}, {"integral_limit", c.integral_limit},
           {"max_tilt_deg", c.max_tilt_deg}};
  if (std::isfinite(c.max_speed)) doc["max_speed_m_s"] = c.max_speed;
  if (c.yaw_mode == ControllerParams::YawMode::kRate) {
    doc["yaw_mode"] = "rate";
    doc["yaw_gain"] = c.yaw_gain;
  }
  return doc;
}

YawParams yaw_params_from_json(const JsonField& f) {
  f.only_keys({"mode", "fixed_deg", "rate_limit_deg_s", "min_speed_m_s"});
  YawParams y;
  if (f.has("mode")) {
    const std::string m = f.at("mode").string();
    if (m == "fixed") y.mode = YawParams::Mode::kFixed;
    else if (m == "velocity") y.mode = YawParams::Mode::kVelocity;
    else f.at("mode").fail("must be \"fixed\" or \"velocity\", got \"" + m + "\"");
  }
  if (f.has("fixed_deg")) y.fixed = deg2rad(f.at("fixed_deg").number_in(-180.0, 180.0, "deg"));
  if (f.has("rate_limit_deg_s")) {
    y.rate_limit = deg2rad(f.at("rate_limit_deg_s").number_in(0.0, kMaxYawRateLimitDeg, "deg/s"));
    if (!(y.rate_limit > 0.0)) f.at("rate_limit_deg_s").fail("must be positive");
  }
  if (f.has("min_speed_m_s")) y.min_speed = f.at("min_speed_m_s").number_in(0.0, 100.0, "m/s");
  // A key the chosen mode never reads is refused, not flown without effect (issue 20, ninth
  // campaign C5: fixed_deg 0 and 90 in velocity mode gave the same log bytes).
  if (y.mode == YawParams::Mode::kVelocity && f.has("fixed_deg"))
    f.at("fixed_deg").fail("unused: yaw.mode is \"velocity\" (the heading follows the velocity); drop it or use \"fixed\"");
  if (y.mode == YawParams::Mode::kFixed && f.has("min_speed_m_s"))
    f.at("min_speed_m_s").fail("unused: yaw.mode is \"fixed\" (min_speed_m_s applies to \"velocity\" only)");
  return y;
}

namespace {

/// An angle for a reader that takes degrees within [-limit, limit]: the struct's radians
/// converted back, a rounding past the limit (rad2deg(deg2rad(180)) is 180 + 3e-14) taken as
/// the limit.
double degrees_within(double radians, double limit) {
  const double d = rad2deg(radians);
  constexpr double kRounding = 1e-12;  // relative: far below any angle a scenario means
  if (std::abs(d) > limit && std::abs(d) <= limit * (1.0 + kRounding)) return std::copysign(limit, d);
  return d;
}

}  // namespace

Json to_json(const YawParams& y) {
  // Only the chosen mode's keys: yaw_params_from_json refuses the other mode's as unused.
  Json doc{{"mode", y.mode == YawParams::Mode::kFixed ? "fixed" : "velocity"},
           {"rate_limit_deg_s", degrees_within(y.rate_limit, kMaxYawRateLimitDeg)}};
  if (y.mode == YawParams::Mode::kFixed) doc["fixed_deg"] = degrees_within(y.fixed, 180.0);
  else doc["min_speed_m_s"] = y.min_speed;
  return doc;
}

std::pair<double, double> YawReference::step(const Eigen::Vector3d& v_ref, double dt) {
  double target = yaw_;
  if (params_.mode == YawParams::Mode::kFixed) target = params_.fixed;
  else if (v_ref.head<2>().norm() > params_.min_speed) target = std::atan2(v_ref.y(), v_ref.x());
  const double max_step = params_.rate_limit * dt;
  const double step = std::clamp(wrap_angle(target - yaw_), -max_step, max_step);
  yaw_ = wrap_angle(yaw_ + step);
  return {yaw_, dt > 0.0 ? step / dt : 0.0};
}

Se3Controller::Se3Controller(const VehicleParams& vehicle, const ControllerParams& params)
    : vehicle_(vehicle), params_(params) {}

ControlOutput Se3Controller::update(const Reference& ref, const NavState& x, double dt) {
  ControlOutput out;
  const Eigen::Matrix3d r = x.q.toRotationMatrix();
  const Eigen::Vector3d e_p = ref.p - x.p;
  const Eigen::Vector3d e_v = ref.v - x.v;
  // The model's drag at the reference velocity in still air, rotors at hover speed.
  const Eigen::Vector3d drag = aerodynamic_drag(vehicle_, r, ref.v, 4.0 * vehicle_.hover_rotor_speed()) / vehicle_.mass;
  const Eigen::Vector3d a_pd = ref.a + params_.kp.cwiseProduct(e_p) + params_.kv.cwiseProduct(e_v) + drag;
  out.a_cmd = a_pd + params_.ki.cwiseProduct(integral_);
  // The speed limit, on the cascade's velocity command (only when it binds: the unlimited
  // law keeps its bytes).
  if (std::isfinite(params_.max_speed)) {
    const Eigen::Vector3d v_c = ref.v + params_.kp.cwiseQuotient(params_.kv).cwiseProduct(e_p);
    const double speed = v_c.norm();
    if (speed > params_.max_speed) {
      out.a_cmd += params_.kv.cwiseProduct(v_c * (params_.max_speed / speed) - v_c);
      out.speed_limited = true;
    }
  }

  Eigen::Vector3d f = vehicle_.mass * (out.a_cmd + Eigen::Vector3d(0.0, 0.0, kGravity));
  out.saturated = limit_tilt(f, deg2rad(params_.max_tilt_deg));
  const bool rate_mode = params_.yaw_mode == ControllerParams::YawMode::kRate;
  const double yaw_now = rate_mode ? euler_zyx(r).yaw : ref.yaw;
  const Eigen::Matrix3d r_des = attitude_from_thrust(f, yaw_now);
  const double max_thrust = vehicle_.max_thrust();
  double thrust = f.dot(r.col(2));
  if (thrust > max_thrust || thrust < 0.0) out.saturated = true;
  thrust = std::clamp(thrust, 0.0, max_thrust);

  // Conditional integration with a clamp: the integrator neither winds up while the
  // vehicle cannot follow nor ever contributes more than integral_limit.
  if (!out.saturated) {
    integral_ += e_p * dt;
    for (int i = 0; i < 3; ++i) {
      if (params_.ki[i] > 0.0) {
        const double cap = params_.integral_limit / params_.ki[i];
        integral_[i] = std::clamp(integral_[i], -cap, cap);
      }
    }
  }

  const Euler e = euler_zyx(r_des);
  out.command.flag = n3::kHorizontalAngle | n3::kVerticalThrust | (rate_mode ? n3::kYawRate : n3::kYawAngle) |
                     n3::kFrameBody;
  out.command.x = e.roll;
  out.command.y = e.pitch;
  out.command.z = 100.0 * thrust / max_thrust;
  out.command.yaw = rate_mode ? ref.yaw_rate + params_.yaw_gain * wrap_angle(ref.yaw - yaw_now) : ref.yaw;
  return out;
}

}  // namespace miner::flight
