#pragma once
/// \file
/// The companion computer's SE(3) cascade PID (REQ-FLIGHT-006; Lee et al. 2010, gains of
/// HKUST's n3ctrl), flying on the EKF estimate:
///
///   e_p = p_ref - p,  e_v = v_ref - v,  I <- I + e_p dt  (only while unsaturated, and
///   |K_i I| <= integral_limit per axis: anti-windup)
///   a_cmd = a_ref + K_p e_p + K_v e_v + K_i I + R D R^T v_ref / m     (feed-forward from
///   the trajectory's flat outputs, plus its drag)
///   f = m (a_cmd + g e3), tilted at most max_tilt;  R_d = flatness(f, yaw_ref)
///   thrust = f . (R e3)  (projected on the current body z), sent as percent of max thrust
///
/// Output: an N3 command with flag 0x22 (ANGLE | THRUST | yaw ANGLE | BODY): roll and
/// pitch of R_d (ZYX), thrust percent, yaw_ref.

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
};
ControllerParams controller_params_from_json(const JsonField& f);
Json to_json(const ControllerParams& c);

struct Reference {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  double yaw = 0.0;
};

struct ControlOutput {
  n3::Command command;
  Eigen::Vector3d a_cmd = Eigen::Vector3d::Zero();  ///< commanded acceleration (m/s^2)
  bool saturated = false;                           ///< tilt or thrust limited
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
