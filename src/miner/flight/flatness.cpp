#include "miner/flight/flatness.hpp"

#include <algorithm>
#include <cmath>

namespace miner::flight {

bool limit_tilt(Eigen::Vector3d& f, double max_tilt) {
  bool changed = false;
  const double floor_z = 1e-3;  // keep a positive vertical component: thrust points up
  if (f.z() < floor_z) {
    f.z() = floor_z;
    changed = true;
  }
  const double horizontal = std::hypot(f.x(), f.y());
  const double allowed = f.z() * std::tan(max_tilt);
  if (horizontal > allowed) {
    const double s = allowed / horizontal;
    f.x() *= s;
    f.y() *= s;
    changed = true;
  }
  return changed;
}

Eigen::Matrix3d attitude_from_thrust(const Eigen::Vector3d& f, double yaw) {
  const Eigen::Vector3d zb = f.normalized();
  const Eigen::Vector3d xc(std::cos(yaw), std::sin(yaw), 0.0);
  Eigen::Vector3d yb = zb.cross(xc);
  const double n = yb.norm();
  // z_b parallel to x_c needs a tilt of 90 deg, which limit_tilt never lets through.
  yb = n > 1e-9 ? Eigen::Vector3d(yb / n) : Eigen::Vector3d(-std::sin(yaw), std::cos(yaw), 0.0);
  Eigen::Matrix3d r;
  r.col(0) = yb.cross(zb);
  r.col(1) = yb;
  r.col(2) = zb;
  return r;
}

Euler euler_zyx(const Eigen::Matrix3d& r) {
  Euler e;
  e.pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  e.roll = std::atan2(r(2, 1), r(2, 2));
  e.yaw = std::atan2(r(1, 0), r(0, 0));
  return e;
}

Eigen::Matrix3d rotation_zyx(const Euler& e) {
  return (Eigen::AngleAxisd(e.yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(e.pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(e.roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

Eigen::Vector3d attitude_error(const Eigen::Matrix3d& rd, const Eigen::Matrix3d& r) {
  const Eigen::Matrix3d m = 0.5 * (rd.transpose() * r - r.transpose() * rd);
  return Eigen::Vector3d(m(2, 1), m(0, 2), m(1, 0));
}

}  // namespace miner::flight
