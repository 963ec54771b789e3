#pragma once
/// \file
/// Sensor models (REQ-FLIGHT-004): the N3's IMU and an external pose source (visual-
/// inertial odometry or motion capture). Every random number comes from the caller's
/// seeded miner::Rng, so a flight is reproducible to the bit.
///
/// IMU (continuous-time model, discretised at the sample period dt):
///   accelerometer  a_m = R^T (p'' + g e3) + b_a + n_a,   n_a ~ N(0, sigma_a^2 / dt)
///   gyroscope      w_m = omega + b_g + n_g,              n_g ~ N(0, sigma_g^2 / dt)
///   biases         b_{k+1} = b_k + N(0, sigma_b^2 dt),   b_0 ~ N(0, sigma_b0^2)
/// with sigma_a, sigma_g the noise densities and sigma_b the bias random walks.
///
/// Pose: position p + n_p and attitude q (x) Exp(n_theta) at `rate_hz`, delivered
/// `delay_s` after the instant they describe; with probability `outlier_probability` a
/// measurement is an outlier whose position is off by `outlier_magnitude_m` in a random
/// direction (a VIO jump or a mocap marker swap).

#include <cstdint>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "miner/core/json_io.hpp"
#include "miner/core/rng.hpp"

namespace miner::flight {

struct ImuParams {
  double accel_noise_density = 0.01;    ///< m/s^2/sqrt(Hz)
  double gyro_noise_density = 0.001;    ///< rad/s/sqrt(Hz)
  double accel_bias_random_walk = 1e-4; ///< m/s^3/sqrt(Hz)
  double gyro_bias_random_walk = 1e-5;  ///< rad/s^2/sqrt(Hz)
  double accel_bias_initial = 0.05;     ///< m/s^2, std of the turn-on bias per axis
  double gyro_bias_initial = 0.005;     ///< rad/s, std of the turn-on bias per axis
};

struct ImuSample {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< specific force, body, m/s^2
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   ///< body rates, rad/s
};

class ImuModel {
 public:
  /// Draws the turn-on biases from `rng`.
  ImuModel(const ImuParams& params, double dt, Rng& rng);
  /// One sample for attitude q, body rates omega and linear acceleration p''; then
  /// advances the bias random walks.
  ImuSample sample(const Eigen::Quaterniond& q, const Eigen::Vector3d& omega,
                   const Eigen::Vector3d& acceleration);
  const Eigen::Vector3d& accel_bias() const { return b_a_; }
  const Eigen::Vector3d& gyro_bias() const { return b_g_; }
  const ImuParams& params() const { return params_; }
  double dt() const { return dt_; }

 private:
  ImuParams params_;
  double dt_;
  Rng* rng_;
  Eigen::Vector3d b_a_, b_g_;
};

/// The largest share of pose fixes that may be outliers: beyond half, the outliers are the
/// majority and no innovation gate can tell them from the truth.
inline constexpr double kMaxOutlierProbability = 0.5;

struct PoseParams {
  double rate_hz = 50.0;                ///< 30-100 Hz for VIO / motion capture
  double delay_s = 0.02;                ///< from the instant measured to delivery
  double position_sigma = 0.02;         ///< m
  double attitude_sigma = 0.01;         ///< rad
  double outlier_probability = 0.01;
  double outlier_magnitude = 1.0;       ///< m
  // A visual-inertial odometry front end's imperfections (REQ-FLIGHT-015); 0: absent.
  double drift_random_walk = 0.0;       ///< m/sqrt(s): the VIO frame's position drift per axis
  double yaw_drift_random_walk = 0.0;   ///< rad/sqrt(s): its yaw drift (about the start)
  double delay_jitter_s = 0.0;          ///< extra delay, uniform on [0, jitter]
  double dropout_rate_hz = 0.0;         ///< rate at which tracking is lost
  double dropout_mean_s = 0.0;          ///< mean length of a loss (exponential)
  bool vio() const {
    return drift_random_walk > 0.0 || yaw_drift_random_walk > 0.0 || delay_jitter_s > 0.0 || dropout_rate_hz > 0.0;
  }
};

struct PoseMeasurement {
  double stamp = 0.0;                   ///< the instant it describes (s)
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  bool outlier = false;                 ///< ground truth, for tests; the EKF never reads it
};

/// A pose measurement of the true (p, q) taken at `stamp`.
PoseMeasurement measure_pose(const PoseParams& params, double stamp, const Eigen::Vector3d& p,
                             const Eigen::Quaterniond& q, Rng& rng);

/// A pose stream as a VIO front end delivers it (REQ-FLIGHT-015). Its frame drifts: position
/// by a random walk b_p (b_p += N(0, s_d^2 Dt) per measurement period Dt) and yaw by a
/// random walk psi (s_psi), rotating the measured pose about the start, so
///   p_m = start + Rz(psi) (p - start) + b_p + n_p,   q_m = Rz(psi) q (x) Exp(n_theta).
/// Tracking is lost as a two-state Markov chain per period: lost with probability
/// 1 - exp(-rate Dt), regained with 1 - exp(-Dt / mean); nothing is delivered while lost.
/// Each delivered measurement arrives delay_s + U(0, delay_jitter_s) after its stamp.
/// Noise and outliers come from `noise_rng` exactly as measure_pose() draws them (every
/// period, lost or not); drift, losses and jitter from `vio_rng`, only when modelled.
class PoseSource {
 public:
  PoseSource(const PoseParams& params, double period, const Eigen::Vector3d& start, Rng& noise_rng, Rng& vio_rng);
  struct Delivery {
    PoseMeasurement measurement;
    double delay = 0.0;  ///< s after the stamp
  };
  /// The measurement of the true (p, q) at `stamp`, or nothing while tracking is lost.
  /// Called once per period, in order.
  std::optional<Delivery> measure(double stamp, const Eigen::Vector3d& p, const Eigen::Quaterniond& q);
  bool lost() const { return lost_; }
  const Eigen::Vector3d& drift() const { return drift_; }
  double yaw_drift() const { return yaw_drift_; }
  long losses() const { return losses_; }

 private:
  PoseParams params_;
  double period_;
  Eigen::Vector3d start_;
  Rng* noise_rng_;
  Rng* vio_rng_;
  Eigen::Vector3d drift_ = Eigen::Vector3d::Zero();
  double yaw_drift_ = 0.0;
  bool lost_ = false;
  long losses_ = 0;
};

/// Exp: rotation vector -> unit quaternion; Log: the inverse (angle in [0, pi]).
Eigen::Quaterniond quat_exp(const Eigen::Vector3d& theta);
Eigen::Vector3d quat_log(const Eigen::Quaterniond& q);

/// A vector of three independent N(0, sigma^2) draws.
Eigen::Vector3d normal3(Rng& rng, double sigma);

/// Reading and writing the "imu" and "pose" objects of a scenario (fields optional,
/// defaults above; noise parameters >= 0, rates and delay checked for consistency).
ImuParams imu_params_from_json(const JsonField& f);
PoseParams pose_params_from_json(const JsonField& f);
Json to_json(const ImuParams& p);
Json to_json(const PoseParams& p);

}  // namespace miner::flight
