#pragma once
/// \file
/// Differential flatness of the quadrotor (Mellinger & Kumar 2011; Lee et al. 2010):
/// a desired acceleration a and yaw psi fix the thrust direction and the attitude,
///
///   z_b = (a + g e3) / |a + g e3|,   x_c = (cos psi, sin psi, 0),
///   y_b = z_b x x_c / |z_b x x_c|,   x_b = y_b x z_b,   R_d = [x_b y_b z_b],
///
/// and the collective thrust m |a + g e3|. Shared by the N3's velocity modes and the
/// companion computer's SE(3) controller (REQ-FLIGHT-006). ZYX Euler angles (yaw, pitch,
/// roll): R = Rz(psi) Ry(theta) Rx(phi), the convention of the N3 angle commands.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "miner/core/units.hpp"

namespace miner::flight {

using miner::deg2rad;
using miner::kPi;

/// Scales the horizontal part of `thrust_vector` (world, z up) so its angle from the
/// vertical is at most max_tilt (rad); a non-positive z is lifted to keep the direction
/// upward. Returns true when it changed the vector.
bool limit_tilt(Eigen::Vector3d& thrust_vector, double max_tilt);

/// R_d above for thrust direction `thrust_vector` (any positive length) and yaw psi.
Eigen::Matrix3d attitude_from_thrust(const Eigen::Vector3d& thrust_vector, double yaw);

struct Euler {
  double roll = 0.0, pitch = 0.0, yaw = 0.0;  ///< rad
};
Euler euler_zyx(const Eigen::Matrix3d& r);
Eigen::Matrix3d rotation_zyx(const Euler& e);

/// Angle wrapped to (-pi, pi].
double wrap_angle(double a);

/// The vee of the skew part: e_R = 1/2 (R_d^T R - R^T R_d)^vee (Lee et al. 2010).
Eigen::Vector3d attitude_error(const Eigen::Matrix3d& r_desired, const Eigen::Matrix3d& r);

}  // namespace miner::flight
