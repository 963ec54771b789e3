#pragma once
/// \file
/// An emulated DJI N3 flight controller, the interface a companion computer talks to
/// (REQ-FLIGHT-003), modelled on the Onboard SDK's flight control command:
///
/// one flag byte = horizontal | vertical | yaw | frame | stable, with
///   horizontal  ANGLE 0x00 (roll x, pitch y, rad, |.| <= 35 deg)  VELOCITY 0x40 (m/s)
///   vertical    VELOCITY 0x00 (m/s)  THRUST 0x20 (z in percent of max thrust, 0-100)
///   yaw         ANGLE 0x00 (rad)  RATE 0x08 (rad/s, |.| <= 150 deg/s)
///   frame       GROUND 0x00  BODY 0x02 (horizontal velocities in the yaw-rotated frame)
///   stable      0x01 (accepted, no effect here)
/// POSITION (0x80 / 0x10) and ANGULAR_RATE (0xC0) are refused as unsupported.
///
/// Commands reach the controller `latency_s` after submission; API control is dropped
/// when none has arrived for `timeout_s` (0.1 s, as the N3 does), and the failsafe
/// (brake and hover, or land) flies until obtain_control() is called again. The
/// internal loop runs at `rate_hz` (>= 400 Hz): attitude P -> body-rate P -> torque,
/// thrust -> motor mixing -> rotor speed commands. Like a real flight controller it
/// flies on its own attitude and velocity estimate, modelled here as the true state (its
/// fused IMU/GPS/barometer estimate is not the subject of this emulation); the
/// companion computer never sees it and flies on the EKF.

#include <cstdint>
#include <deque>
#include <string>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/flight/dynamics.hpp"
#include "miner/flight/vehicle.hpp"

namespace miner::flight::n3 {

inline constexpr std::uint8_t kHorizontalAngle = 0x00;
inline constexpr std::uint8_t kHorizontalVelocity = 0x40;
inline constexpr std::uint8_t kHorizontalPosition = 0x80;
inline constexpr std::uint8_t kHorizontalAngularRate = 0xC0;
inline constexpr std::uint8_t kHorizontalMask = 0xC0;
inline constexpr std::uint8_t kVerticalVelocity = 0x00;
inline constexpr std::uint8_t kVerticalPosition = 0x10;
inline constexpr std::uint8_t kVerticalThrust = 0x20;
inline constexpr std::uint8_t kVerticalMask = 0x30;
inline constexpr std::uint8_t kYawAngle = 0x00;
inline constexpr std::uint8_t kYawRate = 0x08;
inline constexpr std::uint8_t kFrameGround = 0x00;
inline constexpr std::uint8_t kFrameBody = 0x02;
inline constexpr std::uint8_t kStable = 0x01;
inline constexpr std::uint8_t kReservedMask = 0x04;

struct Command {
  std::uint8_t flag = kHorizontalAngle | kVerticalThrust | kYawAngle | kFrameBody;  ///< 0x22
  double x = 0.0, y = 0.0, z = 0.0, yaw = 0.0;
};

enum class Failsafe { kHover, kLand };

struct Config {
  double rate_hz = 400.0;            ///< internal loop and IMU rate (>= 400)
  double latency_s = 0.02;           ///< command transport to the controller
  double timeout_s = 0.1;            ///< command-stream timeout
  Failsafe failsafe = Failsafe::kHover;
  double land_speed = 0.5;           ///< m/s, failsafe kLand descent
  double max_tilt_deg = kN3MaxTiltDeg;
  double max_yaw_rate_deg = 150.0;
  double max_horizontal_speed = 10.0;  ///< m/s, VELOCITY mode
  double max_vertical_speed = 4.0;     ///< m/s, VELOCITY mode
  Eigen::Vector3d attitude_gain{6.0, 6.0, 3.0};  ///< 1/s, attitude error -> body rate
  Eigen::Vector3d rate_gain{30.0, 30.0, 15.0};   ///< 1/s, rate error -> angular acceleration
  double horizontal_velocity_gain = 2.0;          ///< 1/s, VELOCITY mode (P)
  double vertical_velocity_gain = 2.0;            ///< 1/s, VELOCITY mode (P)
  double horizontal_velocity_integral_gain = 1.0; ///< 1/s^2, VELOCITY mode (I): drag
  double vertical_velocity_integral_gain = 1.0;   ///< 1/s^2, VELOCITY mode (I)
  double velocity_integral_limit = 2.0;           ///< m/s^2, the I term's share
};

/// Reads the scenario's "n3" object (all fields optional) and checks it.
Config config_from_json(const JsonField& f);
Json to_json(const Config& c);
void validate(const Config& c);

enum class Status { kAccepted, kNoAuthority, kUnsupportedFlag, kNotFinite };
const char* to_string(Status s);

/// The set points the internal loop is flying (for logs and tests).
struct Setpoint {
  double roll = 0.0, pitch = 0.0, yaw = 0.0;  ///< rad
  double thrust = 0.0;                        ///< N
  bool failsafe = false;
};

class FlightController {
 public:
  FlightController(const VehicleParams& vehicle, const Config& config);

  /// Grants API control (the SDK's obtain-control call); the timeout clock starts now.
  void obtain_control(double t);
  bool has_authority() const { return authority_; }
  bool in_failsafe() const { return !authority_; }

  /// Queues a command sent at time t; it takes effect at t + latency_s.
  Status submit(const Command& command, double t);

  /// One internal-loop tick at time t on the controller's state estimate `state`:
  /// applies due commands, checks the timeout, returns the rotor speed commands.
  Eigen::Vector4d step(double t, const QuadState& state);

  const Setpoint& setpoint() const { return setpoint_; }
  const Config& config() const { return config_; }
  long accepted() const { return accepted_; }
  long rejected() const { return rejected_; }
  /// Number of times API control was dropped by the timeout.
  int timeouts() const { return timeouts_; }

 private:
  struct Pending {
    double apply_time;
    Command command;
  };
  void fly_failsafe(const QuadState& s, double dt);
  void fly_command(const Command& c, const QuadState& s, double dt);
  Eigen::Vector4d attitude_loop(const QuadState& s) const;
  void slew_yaw(double target, double dt);
  void tilt_from_acceleration(const Eigen::Vector3d& a_horizontal, const QuadState& s);

  VehicleParams vehicle_;
  Config config_;
  Mixer mixer_;
  bool authority_ = false;
  bool has_command_ = false;
  double last_command_time_ = 0.0;
  double last_step_time_ = 0.0;
  bool stepped_ = false;
  Command active_;
  Eigen::Vector3d velocity_integral_ = Eigen::Vector3d::Zero();  ///< world x, y, z (m)
  std::deque<Pending> pending_;
  Setpoint setpoint_;
  long accepted_ = 0, rejected_ = 0;
  int timeouts_ = 0;
};

}  // namespace miner::flight::n3
