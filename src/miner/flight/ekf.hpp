#pragma once
/// \file
/// A 15-state error-state EKF (REQ-FLIGHT-005; Sola 2017, "Quaternion kinematics for the
/// error-state Kalman filter", local attitude error) driven by the N3's IMU and corrected
/// by delayed pose measurements.
///
/// Nominal state x = (p, v, q, b_a, b_g); error state dx = (dp, dv, dtheta, db_a, db_g)
/// with q_true = q (x) Exp(dtheta). Per IMU sample (a_m, w_m) over dt:
///   a = R (a_m - b_a) - g e3,  p += v dt + a dt^2 / 2,  v += a dt,  q = q (x) Exp((w_m - b_g) dt)
///   F = I + E,  E_pv = I dt,  E_vtheta = -R [a_m - b_a]x dt,  E_vba = -R dt,
///   E_thetatheta = Exp((w_m - b_g) dt)^T - I,  E_thetabg = -I dt
///   P <- F P F^T + Q,  Q = diag(0, s_a^2 dt I, s_g^2 dt I, s_ba^2 dt I, s_bg^2 dt I)
/// (E is sparse, so F P F^T = P + EP + (EP)^T + E(EP)^T costs O(15^2), not O(15^3)).
/// Pose update: r = (p_m - p, Log(q^-1 q_m)), H = [I 0 0 0 0; 0 0 I 0 0],
/// S = H P H^T + R, NIS = r^T S^-1 r; a measurement with NIS above the chi2(6) quantile
/// `gate_probability` is rejected as an outlier; otherwise K = P H^T S^-1, Joseph-form
/// covariance update, injection and the attitude reset G = I - [dtheta / 2]x.
///
/// Delay: the filter runs on a fusion horizon `delay_ticks` IMU samples behind the present
/// (PX4 EKF2's scheme): IMU samples wait in a buffer until they reach the horizon, a pose
/// stamped t_m is fused when the horizon reaches t_m (exactly, all times are IMU ticks),
/// and current() predicts from the horizon to the present through the buffered samples.

#include <cstdint>
#include <deque>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "miner/flight/sensors.hpp"

namespace miner::flight {

using Matrix15 = Eigen::Matrix<double, 15, 15>;
using Vector15 = Eigen::Matrix<double, 15, 1>;

struct NavState {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d b_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_g = Eigen::Vector3d::Zero();
};

struct EkfParams {
  ImuParams imu;    ///< process noise: the IMU's noise densities and bias random walks
  PoseParams pose;  ///< measurement noise (sigmas) and delay
  double gate_probability = 0.999;
  double initial_position_sigma = 0.05;  ///< m
  double initial_velocity_sigma = 0.05;  ///< m/s
  double initial_attitude_sigma = 0.02;  ///< rad
};

/// diag(P0) from the initial sigmas and the IMU's turn-on bias sigmas.
Matrix15 initial_covariance(const EkfParams& params);

/// The error of `estimate` relative to `truth` in the filter's error coordinates:
/// (p - p_t, v - v_t, Log(q^-1 q_t) ... ) signs chosen so truth = estimate (+) error.
Vector15 state_error(const NavState& estimate, const NavState& truth);

/// One strapdown step of the nominal state (no covariance).
void strapdown(NavState& x, const ImuSample& s, double dt);

struct FuseResult {
  bool accepted = false;
  bool stale = false;   ///< stamped before the horizon: too late to fuse
  double nis = 0.0;
};

class Ekf {
 public:
  Ekf(const EkfParams& params, double imu_dt, int delay_ticks, const NavState& initial,
      const Matrix15& initial_covariance);

  /// The IMU sample taken at tick k (time k * dt); ticks must come in order, one each.
  /// The initial state describes the first tick pushed.
  void push_imu(std::int64_t tick, const ImuSample& sample);
  /// A pose measurement; fused when the horizon reaches its stamp (possibly right now).
  /// Returns the outcome of the fusions this call performed (the last one).
  FuseResult push_pose(const PoseMeasurement& m);

  /// The estimate at the latest pushed tick (horizon + buffered IMU).
  NavState current() const;
  /// The filter state and covariance at the horizon, and its time (s).
  const NavState& horizon_state() const { return x_; }
  const Matrix15& covariance() const { return p_; }
  double horizon_time() const { return static_cast<double>(horizon_tick_) * dt_; }
  std::int64_t horizon_tick() const { return horizon_tick_; }

  long fused() const { return fused_; }
  long rejected() const { return rejected_; }
  long stale() const { return stale_; }
  double gate() const { return gate_; }
  /// NIS of every accepted measurement, in order (for consistency tests).
  const std::vector<double>& nis_history() const { return nis_; }

 private:
  void predict(const ImuSample& s);
  FuseResult fuse(const PoseMeasurement& m);
  void fuse_due();

  EkfParams params_;
  double dt_;
  int delay_ticks_;
  double gate_;
  NavState x_;
  Matrix15 p_;
  std::int64_t horizon_tick_ = 0;
  std::int64_t latest_tick_ = -1;
  std::deque<std::pair<std::int64_t, ImuSample>> imu_buffer_;
  std::deque<std::pair<std::int64_t, PoseMeasurement>> pose_buffer_;
  FuseResult last_;
  long fused_ = 0, rejected_ = 0, stale_ = 0;
  std::vector<double> nis_;
};

}  // namespace miner::flight
