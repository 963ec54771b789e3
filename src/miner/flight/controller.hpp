#pragma once
/// \file
/// The companion computer's SE(3) cascade PID (REQ-FLIGHT-006; Lee et al. 2010, gains of
/// HKUST's n3ctrl), flying on the EKF estimate:
///
///   e_p = p_ref - p,  e_v = v_ref - v,  I <- I + e_p dt  (only while unsaturated, and
///   |K_i I| <= integral_limit per axis: anti-windup)
///   a_cmd = a_ref + K_p e_p + K_v e_v + K_i I + F_drag(v_ref) / m     (feed-forward from
///   the trajectory's flat outputs, plus the model's drag in still air at hover rotor speed,
///   aerodynamic_drag())
///   f = m (a_cmd + g e3), tilted at most max_tilt;  R_d = flatness(f, yaw_ref)
///   thrust = f . (R e3)  (projected on the current body z), sent as percent of max thrust
///
/// Speed limit (REQ-FLIGHT-016): written as a cascade, the position loop commands the
/// velocity v_c = v_ref + (K_p / K_v) e_p and a_cmd = a_ref + K_v (v_c - v) + ... (the same
/// law); when |v_c| exceeds max_speed, v_c is scaled onto it, so feedback never asks the
/// vehicle to fly faster than the scenario's limit allows (a_cmd += K_v (v_c' - v_c)).
///
/// Output: an N3 command with flag 0x22 (ANGLE | THRUST | yaw ANGLE | BODY): roll and
/// pitch of R_d (ZYX), thrust percent, yaw_ref; or, in yaw RATE mode (0x2A), the yaw rate
/// yaw_rate_ref + k_yaw wrap(yaw_ref - yaw) (REQ-FLIGHT-017) with R_d built on the present
/// yaw, which the N3 integrates from the rate.

#include <limits>
#include <utility>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/core/units.hpp"
#include "miner/flight/ekf.hpp"
#include "miner/flight/n3.hpp"
#include "miner/flight/vehicle.hpp"

namespace miner::flight {

struct ControllerParams {
  double rate_hz = 100.0;
  Eigen::Vector3d kp{2.3, 2.3, 2.5};      ///< 1/s^2
  Eigen::Vector3d kv{3.0, 3.0, 5.5};      ///< 1/s
  Eigen::Vector3d ki{0.1, 0.1, 0.1};      ///< 1/s^3
  double integral_limit = 1.0;            ///< m/s^2, the integral term's share of a_cmd
  double max_tilt_deg = kN3MaxTiltDeg;
  /// Fastest commanded velocity (m/s): the scenario's v_max with kSpeedLimitHeadroom.
  double max_speed = std::numeric_limits<double>::infinity();
  enum class YawMode { kAngle, kRate } yaw_mode = YawMode::kAngle;
  double yaw_gain = 2.0;  ///< 1/s, yaw RATE mode: yaw error -> rate
};
/// The share above the scenario's v_max the position loop may command to recover from an
/// error: 25 % (the reference itself peaks at v_max).
inline constexpr double kSpeedLimitHeadroom = 1.25;
ControllerParams controller_params_from_json(const JsonField& f);
Json to_json(const ControllerParams& c);

struct Reference {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  double yaw = 0.0;
  double yaw_rate = 0.0;  ///< rad/s, feed-forward in yaw RATE mode
};

struct ControlOutput {
  n3::Command command;
  Eigen::Vector3d a_cmd = Eigen::Vector3d::Zero();  ///< commanded acceleration (m/s^2)
  bool saturated = false;                           ///< tilt or thrust limited
  bool speed_limited = false;                       ///< v_c scaled onto max_speed
};

/// The reference's yaw (REQ-FLIGHT-017): fixed, or along the reference velocity's
/// horizontal direction (held below min_speed), approached at most at rate_limit:
///   psi_k = psi_{k-1} + clamp(wrap(psi_target - psi_{k-1}), -rate_limit dt, rate_limit dt),
/// with the feed-forward rate (psi_k - psi_{k-1}) / dt.
struct YawParams {
  enum class Mode { kFixed, kVelocity } mode = Mode::kFixed;
  double fixed = 0.0;                   ///< rad, Mode::kFixed
  double rate_limit = deg2rad(45.0);    ///< rad/s
  double min_speed = 0.1;               ///< m/s, below it the heading is held
};
/// The fastest yaw rate limit a file may give (deg/s): ten turns a second.
inline constexpr double kMaxYawRateLimitDeg = 3600.0;
YawParams yaw_params_from_json(const JsonField& f);
/// The section as yaw_params_from_json reads it: the mode's own keys only.
Json to_json(const YawParams& y);

class YawReference {
 public:
  YawReference(const YawParams& params, double initial_yaw) : params_(params), yaw_(initial_yaw) {}
  /// Advances by dt for reference velocity v_ref; returns (yaw, yaw rate).
  std::pair<double, double> step(const Eigen::Vector3d& v_ref, double dt);
  double yaw() const { return yaw_; }

 private:
  YawParams params_;
  double yaw_;
};

class Se3Controller {
 public:
  Se3Controller(const VehicleParams& vehicle, const ControllerParams& params);
  ControlOutput update(const Reference& ref, const NavState& estimate, double dt);
  const Eigen::Vector3d& integral() const { return integral_; }
  const ControllerParams& params() const { return params_; }

 private:
  VehicleParams vehicle_;
  ControllerParams params_;
  Eigen::Vector3d integral_ = Eigen::Vector3d::Zero();
};

}  // namespace miner::flight
