#include "miner/flight/controller.hpp"

#include <algorithm>
#include <cmath>

#include "miner/core/error.hpp"
#include "miner/flight/flatness.hpp"

namespace miner::flight {

ControllerParams controller_params_from_json(const JsonField& f) {
  f.only_keys({"rate_hz", "kp", "kv", "ki", "integral_limit", "max_tilt_deg"});
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
  return c;
}

Json to_json(const ControllerParams& c) {
  return Json{{"rate_hz", c.rate_hz}, {"kp", vec3_json(c.kp)}, {"kv", vec3_json(c.kv)},
              {"ki", vec3_json(c.ki)}, {"integral_limit", c.integral_limit},
              {"max_tilt_deg", c.max_tilt_deg}};
}

Se3Controller::Se3Controller(const VehicleParams& vehicle, const ControllerParams& params)
    : vehicle_(vehicle), params_(params) {}

ControlOutput Se3Controller::update(const Reference& ref, const NavState& x, double dt) {
  ControlOutput out;
  const Eigen::Matrix3d r = x.q.toRotationMatrix();
  const Eigen::Vector3d e_p = ref.p - x.p;
  const Eigen::Vector3d e_v = ref.v - x.v;
  const Eigen::Vector3d drag = r * (vehicle_.linear_drag.asDiagonal() * (r.transpose() * ref.v)) / vehicle_.mass;
  const Eigen::Vector3d a_pd = ref.a + params_.kp.cwiseProduct(e_p) + params_.kv.cwiseProduct(e_v) + drag;
  out.a_cmd = a_pd + params_.ki.cwiseProduct(integral_);

  Eigen::Vector3d f = vehicle_.mass * (out.a_cmd + Eigen::Vector3d(0.0, 0.0, kGravity));
  out.saturated = limit_tilt(f, deg2rad(params_.max_tilt_deg));
  const Eigen::Matrix3d r_des = attitude_from_thrust(f, ref.yaw);
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
  out.command.flag = n3::kHorizontalAngle | n3::kVerticalThrust | n3::kYawAngle | n3::kFrameBody;
  out.command.x = e.roll;
  out.command.y = e.pitch;
  out.command.z = 100.0 * thrust / max_thrust;
  out.command.yaw = ref.yaw;
  return out;
}

}  // namespace miner::flight
