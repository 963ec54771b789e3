#include "miner/flight/n3.hpp"

#include <algorithm>
#include <cmath>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/flight/flatness.hpp"

namespace miner::flight::n3 {

namespace {
/// Slack on time comparisons: ticks are sums of 1/rate steps.
constexpr double kTimeEpsilon = 1e-9;
}  // namespace

const char* to_string(Status s) {
  switch (s) {
    case Status::kAccepted: return "accepted";
    case Status::kNoAuthority: return "no API control authority";
    case Status::kUnsupportedFlag: return "unsupported control flag";
    case Status::kNotFinite: return "non-finite set point";
  }
  return "?";
}

void validate(const Config& c) {
  auto fail = [](const std::string& what) { throw Error("n3: " + what); };
  // At most 10 kHz: the loop steps the simulation once per tick, so 4e9 Hz was 3e10 steps for
  // a few seconds of flight (issue 20, unbounded work); 10 kHz x the 1000 s flight cap is 1e7.
  constexpr double kMaxRateHz = 10000.0;
  if (!(c.rate_hz >= 400.0 && c.rate_hz <= kMaxRateHz))
    fail("rate_hz must be in [400, 10000] (the N3's inner loop), got " + exact_number(c.rate_hz));
  if (!(c.latency_s >= 0.0) || !std::isfinite(c.latency_s)) fail("latency_s must be finite and >= 0");
  if (!(c.timeout_s > 0.0) || !std::isfinite(c.timeout_s)) fail("timeout_s must be positive");
  if (!(c.max_tilt_deg > 0.0 && c.max_tilt_deg < 90.0)) fail("max_tilt_deg must be in (0, 90)");
  if (!(c.max_yaw_rate_deg > 0.0) || !std::isfinite(c.max_yaw_rate_deg)) fail("max_yaw_rate_deg must be positive");
  if (!(c.land_speed > 0.0) || !(c.max_horizontal_speed > 0.0) || !(c.max_vertical_speed > 0.0))
    fail("land_speed, max_horizontal_speed and max_vertical_speed must be positive");
  if (!(c.attitude_gain.minCoeff() > 0.0) || !(c.rate_gain.minCoeff() > 0.0) ||
      !(c.horizontal_velocity_gain > 0.0) || !(c.vertical_velocity_gain > 0.0) ||
      !(c.horizontal_velocity_integral_gain > 0.0) || !(c.vertical_velocity_integral_gain > 0.0) ||
      !(c.velocity_integral_limit > 0.0))
    fail("gains must be positive");
}

Config config_from_json(const JsonField& f) {
  f.only_keys({"rate_hz", "latency_s", "timeout_s", "failsafe", "max_tilt_deg", "max_yaw_rate_deg"});
  Config c;
  if (f.has("rate_hz")) c.rate_hz = f.at("rate_hz").number();
  if (f.has("latency_s")) c.latency_s = f.at("latency_s").number_in(0.0, 1.0, "s");
  // (0, 10]: a zero timeout is refused by the range itself (seventeenth campaign F21: "[0, 10]"
  // refused 0 with another message).
  if (f.has("timeout_s")) c.timeout_s = f.at("timeout_s").number_above(0.0, 10.0, "s");
  if (f.has("failsafe")) {
    const std::string s = f.at("failsafe").string();
    if (s == "hover") c.failsafe = Failsafe::kHover;
    else if (s == "land") c.failsafe = Failsafe::kLand;
    else f.at("failsafe").fail("expected \"hover\" or \"land\", got \"" + s + "\"");
  }
  if (f.has("max_tilt_deg")) c.max_tilt_deg = f.at("max_tilt_deg").number();
  if (f.has("max_yaw_rate_deg")) c.max_yaw_rate_deg = f.at("max_yaw_rate_deg").number_in(0.0, 3600.0, "deg/s");
  try {
    validate(c);
  } catch (const Error& e) {
    // The field path already says "n3" (fifth campaign: "n3: n3: rate_hz").
    const std::string what = e.what();
    f.fail(what.rfind("n3: ", 0) == 0 ? what.substr(4) : what);
  }
  return c;
}

Json to_json(const Config& c) {
  return Json{{"rate_hz", c.rate_hz},
              {"latency_s", c.latency_s},
              {"timeout_s", c.timeout_s},
              {"failsafe", c.failsafe == Failsafe::kHover ? "hover" : "land"},
              {"max_tilt_deg", c.max_tilt_deg},
              {"max_yaw_rate_deg", c.max_yaw_rate_deg}};
}

FlightController::FlightController(const VehicleParams& vehicle, const Config& config)
    : vehicle_(vehicle), config_(config), mixer_(vehicle) {
  validate(config);
  setpoint_.thrust = vehicle.weight();
}

void FlightController::obtain_control(double t) {
  authority_ = true;
  has_command_ = false;
  last_command_time_ = t;
  pending_.clear();
}

Status FlightController::submit(const Command& c, double t) {
  Status status = Status::kAccepted;
  const std::uint8_t horizontal = c.flag & kHorizontalMask;
  const std::uint8_t vertical = c.flag & kVerticalMask;
  if (horizontal == kHorizontalPosition || horizontal == kHorizontalAngularRate ||
      vertical == kVerticalPosition || vertical == kVerticalMask || (c.flag & kReservedMask)) {
    status = Status::kUnsupportedFlag;
  } else if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || !std::isfinite(c.yaw) ||
             !std::isfinite(t)) {
    status = Status::kNotFinite;
  } else if (!authority_) {
    status = Status::kNoAuthority;
  }
  if (status != Status::kAccepted) {
    ++rejected_;
    return status;
  }
  ++accepted_;
  pending_.push_back({t + config_.latency_s, c});
  return status;
}

Eigen::Vector4d FlightController::step(double t, const QuadState& s) {
  const double dt = stepped_ ? std::max(t - last_step_time_, 0.0) : 1.0 / config_.rate_hz;
  if (!stepped_) setpoint_.yaw = euler_zyx(s.q.toRotationMatrix()).yaw;
  stepped_ = true;
  last_step_time_ = t;
  while (!pending_.empty() && pending_.front().apply_time <= t + kTimeEpsilon) {
    if (authority_) {
      active_ = pending_.front().command;
      has_command_ = true;
      last_command_time_ = pending_.front().apply_time;
    }
    pending_.pop_front();
  }
  if (authority_ && t - last_command_time_ > config_.timeout_s + kTimeEpsilon) {
    authority_ = false;
    has_command_ = false;
    pending_.clear();
    ++timeouts_;
  }
  setpoint_.failsafe = !(authority_ && has_command_);
  if (setpoint_.failsafe) {
    fly_failsafe(s, dt);
  } else {
    fly_command(active_, s, dt);
  }
  return attitude_loop(s);
}

void FlightController::fly_failsafe(const QuadState& s, double dt) {
  Command brake;
  brake.flag = kHorizontalVelocity | kVerticalVelocity | kYawRate | kFrameGround;
  brake.z = config_.failsafe == Failsafe::kLand ? -config_.land_speed : 0.0;
  fly_command(brake, s, dt);
}

void FlightController::tilt_from_acceleration(const Eigen::Vector3d& a_horizontal, const QuadState&) {
  Eigen::Vector3d f(a_horizontal.x(), a_horizontal.y(), kGravity);
  limit_tilt(f, deg2rad(config_.max_tilt_deg));
  const Euler e = euler_zyx(attitude_from_thrust(f, setpoint_.yaw));
  setpoint_.roll = e.roll;
  setpoint_.pitch = e.pitch;
}

void FlightController::slew_yaw(double target, double dt) {
  const double max_step = deg2rad(config_.max_yaw_rate_deg) * dt;
  const double error = wrap_angle(target - setpoint_.yaw);
  setpoint_.yaw = wrap_angle(setpoint_.yaw + std::clamp(error, -max_step, max_step));
}

void FlightController::fly_command(const Command& c, const QuadState& s, double dt) {
  const double max_tilt = deg2rad(config_.max_tilt_deg);
  // Yaw first: the body frame of horizontal velocities turns with it.
  if (c.flag & kYawRate) {
    const double rate_limit = deg2rad(config_.max_yaw_rate_deg);
    setpoint_.yaw = wrap_angle(setpoint_.yaw + std::clamp(c.yaw, -rate_limit, rate_limit) * dt);
  } else {
    slew_yaw(c.yaw, dt);
  }
  if ((c.flag & kHorizontalMask) == kHorizontalVelocity) {
    Eigen::Vector2d v_des(c.x, c.y);
    if (c.flag & kFrameBody) v_des = Eigen::Rotation2Dd(setpoint_.yaw) * v_des;
    if (v_des.norm() > config_.max_horizontal_speed) v_des *= config_.max_horizontal_speed / v_des.norm();
    const Eigen::Vector2d error = v_des - s.v.head<2>();
    const double cap = config_.velocity_integral_limit / config_.horizontal_velocity_integral_gain;
    for (int i = 0; i < 2; ++i) velocity_integral_[i] = std::clamp(velocity_integral_[i] + error[i] * dt, -cap, cap);
    const Eigen::Vector2d a = config_.horizontal_velocity_gain * error +
                              config_.horizontal_velocity_integral_gain * velocity_integral_.head<2>();
    tilt_from_acceleration(Eigen::Vector3d(a.x(), a.y(), 0.0), s);
  } else {
    // ANGLE: roll, pitch, each within the tilt limit, and the tilt of the pair too.
    velocity_integral_.head<2>().setZero();
    Euler e{std::clamp(c.x, -max_tilt, max_tilt), std::clamp(c.y, -max_tilt, max_tilt), setpoint_.yaw};
    const Eigen::Vector3d z = rotation_zyx(e).col(2);
    if (std::acos(std::clamp(z.z(), -1.0, 1.0)) > max_tilt + 1e-12) {
      Eigen::Vector3d f = z;
      limit_tilt(f, max_tilt);
      e = euler_zyx(attitude_from_thrust(f, setpoint_.yaw));
    }
    setpoint_.roll = e.roll;
    setpoint_.pitch = e.pitch;
  }
  const double max_thrust = vehicle_.max_thrust();
  if ((c.flag & kVerticalMask) == kVerticalThrust) {
    setpoint_.thrust = std::clamp(c.z, 0.0, 100.0) / 100.0 * max_thrust;
    velocity_integral_.z() = 0.0;
  } else {
    const double vz = std::clamp(c.z, -config_.max_vertical_speed, config_.max_vertical_speed);
    const double cap = config_.velocity_integral_limit / config_.vertical_velocity_integral_gain;
    velocity_integral_.z() = std::clamp(velocity_integral_.z() + (vz - s.v.z()) * dt, -cap, cap);
    const double az = config_.vertical_velocity_gain * (vz - s.v.z()) +
                      config_.vertical_velocity_integral_gain * velocity_integral_.z();
    const double tilt_cos = std::max(std::cos(setpoint_.roll) * std::cos(setpoint_.pitch), std::cos(max_tilt));
    setpoint_.thrust = std::clamp(vehicle_.mass * (kGravity + az) / tilt_cos, 0.0, max_thrust);
  }
}

Eigen::Vector4d FlightController::attitude_loop(const QuadState& s) const {
  const Eigen::Matrix3d r = s.q.toRotationMatrix();
  const Eigen::Matrix3d r_des = rotation_zyx({setpoint_.roll, setpoint_.pitch, setpoint_.yaw});
  const Eigen::Vector3d e_r = attitude_error(r_des, r);
  const Eigen::Vector3d omega_des = -config_.attitude_gain.cwiseProduct(e_r);
  const Eigen::Vector3d alpha = config_.rate_gain.cwiseProduct(omega_des - s.omega);
  const Eigen::Vector3d j_omega = vehicle_.inertia.cwiseProduct(s.omega);
  const Eigen::Vector3d torque = vehicle_.inertia.cwiseProduct(alpha) + s.omega.cross(j_omega);
  return mixer_.rotor_speeds(setpoint_.thrust, torque);
}

}  // namespace miner::flight::n3
