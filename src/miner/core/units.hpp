#pragma once
/// \file
/// One home for the constants and physical limits several capabilities share (issue 22:
/// pi and the tilt limit were defined several times). SI units throughout: m, s, rad, kg.

namespace miner {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double deg2rad(double degrees) { return degrees * kPi / 180.0; }
inline constexpr double rad2deg(double radians) { return radians * 180.0 / kPi; }
/// Standard gravity, m/s^2.
inline constexpr double kGravity = 9.81;
/// The largest robot (vehicle) radius a map query, a scan's swept body or a vehicle file may
/// give: a vehicle 20 m across (REQ-WORLD-002, REQ-FLIGHT-001).
inline constexpr double kMaxRobotRadius = 10.0;
/// The DJI N3's horizontal tilt limit in its ANGLE mode (deg), also the SE(3) controller's
/// default (../shared/anchors.md).
inline constexpr double kN3MaxTiltDeg = 35.0;

}  // namespace miner
