#include "miner/flight/sensors.hpp"

#include <cmath>

#include "miner/core/error.hpp"
#include "miner/flight/vehicle.hpp"

namespace miner::flight {

Eigen::Vector3d normal3(Rng& rng, double sigma) {
  const double x = rng.normal(), y = rng.normal(), z = rng.normal();
  return sigma * Eigen::Vector3d(x, y, z);
}

Eigen::Quaterniond quat_exp(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  if (angle < 1e-12) return Eigen::Quaterniond(1.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle));
}

Eigen::Vector3d quat_log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // the short way round
  const double s = q.vec().norm();
  if (s < 1e-12) return 2.0 * q.vec();
  return 2.0 * std::atan2(s, q.w()) * q.vec() / s;
}

ImuModel::ImuModel(const ImuParams& params, double dt, Rng& rng) : params_(params), dt_(dt), rng_(&rng) {
  b_a_ = normal3(rng, params.accel_bias_initial);
  b_g_ = normal3(rng, params.gyro_bias_initial);
}

ImuSample ImuModel::sample(const Eigen::Quaterniond& q, const Eigen::Vector3d& omega,
                           const Eigen::Vector3d& acceleration) {
  ImuSample s;
  const Eigen::Vector3d specific_force = q.conjugate() * (acceleration + Eigen::Vector3d(0.0, 0.0, kGravity));
  s.accel = specific_force + b_a_ + normal3(*rng_, params_.accel_noise_density / std::sqrt(dt_));
  s.gyro = omega + b_g_ + normal3(*rng_, params_.gyro_noise_density / std::sqrt(dt_));
  b_a_ += normal3(*rng_, params_.accel_bias_random_walk * std::sqrt(dt_));
  b_g_ += normal3(*rng_, params_.gyro_bias_random_walk * std::sqrt(dt_));
  return s;
}

PoseMeasurement measure_pose(const PoseParams& params, double stamp, const Eigen::Vector3d& p,
                             const Eigen::Quaterniond& q, Rng& rng) {
  PoseMeasurement m;
  m.stamp = stamp;
  m.p = p + normal3(rng, params.position_sigma);
  m.q = (q * quat_exp(normal3(rng, params.attitude_sigma))).normalized();
  if (rng.uniform01() < params.outlier_probability) {
    m.outlier = true;
    Eigen::Vector3d dir = normal3(rng, 1.0);
    dir /= std::max(dir.norm(), 1e-12);
    m.p += params.outlier_magnitude * dir;
  }
  return m;
}

PoseSource::PoseSource(const PoseParams& params, double period, const Eigen::Vector3d& start, Rng& noise_rng,
                       Rng& vio_rng)
    : params_(params), period_(period), start_(start), noise_rng_(&noise_rng), vio_rng_(&vio_rng) {}

std::optional<PoseSource::Delivery> PoseSource::measure(double stamp, const Eigen::Vector3d& p,
                                                        const Eigen::Quaterniond& q) {
  Delivery d;
  d.delay = params_.delay_s;
  if (!params_.vio()) {
    d.measurement = measure_pose(params_, stamp, p, q, *noise_rng_);
    return d;
  }
  if (params_.drift_random_walk > 0.0) drift_ += normal3(*vio_rng_, params_.drift_random_walk * std::sqrt(period_));
  if (params_.yaw_drift_random_walk > 0.0) yaw_drift_ += params_.yaw_drift_random_walk * std::sqrt(period_) * vio_rng_->normal();
  if (params_.dropout_rate_hz > 0.0) {
    const double u = vio_rng_->uniform01();
    if (!lost_ && u < -std::expm1(-params_.dropout_rate_hz * period_)) {
      lost_ = true;
      ++losses_;
    } else if (lost_ && (params_.dropout_mean_s <= 0.0 || u < -std::expm1(-period_ / params_.dropout_mean_s))) {
      lost_ = false;
    }
  }
  const Eigen::Quaterniond frame(Eigen::AngleAxisd(yaw_drift_, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d p_vio = start_ + frame * (p - start_) + drift_;
  d.measurement = measure_pose(params_, stamp, p_vio, frame * q, *noise_rng_);
  if (params_.delay_jitter_s > 0.0) d.delay += params_.delay_jitter_s * vio_rng_->uniform01();
  if (lost_) return std::nullopt;
  return d;
}

// Every value has a range [0, hi] (issue 20: an accelerometer noise of 1e300 and a pose delay of
// 1e6 s were accepted and flown).

ImuParams imu_params_from_json(const JsonField& f) {
  f.only_keys({"accel_noise_density", "gyro_noise_density", "accel_bias_random_walk", "gyro_bias_random_walk",
               "accel_bias_initial", "gyro_bias_initial"});
  ImuParams p;
  p.accel_noise_density = f.number_in_or("accel_noise_density", p.accel_noise_density, 0.0, 1.0, "m/s^2/sqrt(Hz)");
  p.gyro_noise_density = f.number_in_or("gyro_noise_density", p.gyro_noise_density, 0.0, 1.0, "rad/s/sqrt(Hz)");
  p.accel_bias_random_walk = f.number_in_or("accel_bias_random_walk", p.accel_bias_random_walk, 0.0, 1.0, "m/s^3/sqrt(Hz)");
  p.gyro_bias_random_walk = f.number_in_or("gyro_bias_random_walk", p.gyro_bias_random_walk, 0.0, 1.0, "rad/s^2/sqrt(Hz)");
  p.accel_bias_initial = f.number_in_or("accel_bias_initial", p.accel_bias_initial, 0.0, 10.0, "m/s^2");
  p.gyro_bias_initial = f.number_in_or("gyro_bias_initial", p.gyro_bias_initial, 0.0, 1.0, "rad/s");
  return p;
}

PoseParams pose_params_from_json(const JsonField& f) {
  f.only_keys({"rate_hz", "delay_s", "position_sigma", "attitude_sigma", "outlier_probability", "outlier_magnitude",
               "drift_random_walk", "yaw_drift_random_walk", "delay_jitter_s", "dropout_rate_hz", "dropout_mean_s"});
  PoseParams p;
  if (f.has("rate_hz")) {
    p.rate_hz = f.at("rate_hz").number_in(0.0, 10000.0, "Hz");
    if (!(p.rate_hz > 0.0)) f.at("rate_hz").fail("must be positive");
  }
  p.delay_s = f.number_in_or("delay_s", p.delay_s, 0.0, 1.0, "s");
  // (0, hi]: the EKF divides by them, so the range itself refuses 0 (seventeenth campaign F21).
  if (f.has("position_sigma")) p.position_sigma = f.at("position_sigma").number_above(0.0, 10.0, "m");
  if (f.has("attitude_sigma")) p.attitude_sigma = f.at("attitude_sigma").number_above(0.0, 1.0, "rad");
  // Outliers are a minority, or no gate can tell them from the truth: at 1.0 every fix was an
  // outlier and the flight left the map, blamed on the flight (issue 20, seventh campaign C4).
  p.outlier_probability = f.number_in_or("outlier_probability", p.outlier_probability, 0.0, kMaxOutlierProbability, "");
  p.outlier_magnitude = f.number_in_or("outlier_magnitude", p.outlier_magnitude, 0.0, 100.0, "m");
  p.drift_random_walk = f.number_in_or("drift_random_walk", 0.0, 0.0, 10.0, "m/sqrt(s)");
  p.yaw_drift_random_walk = f.number_in_or("yaw_drift_random_walk", 0.0, 0.0, 1.0, "rad/sqrt(s)");
  p.delay_jitter_s = f.number_in_or("delay_jitter_s", 0.0, 0.0, 1.0, "s");
  p.dropout_rate_hz = f.number_in_or("dropout_rate_hz", 0.0, 0.0, 100.0, "Hz");
  p.dropout_mean_s = f.number_in_or("dropout_mean_s", 0.0, 0.0, 100.0, "s");
  if (p.dropout_rate_hz > 0.0 && !(p.dropout_mean_s > 0.0))
    f.at("dropout_rate_hz").fail("needs a positive dropout_mean_s (how long a loss lasts)");
  if (f.has("dropout_mean_s") && !(p.dropout_rate_hz > 0.0))
    f.at("dropout_mean_s").fail("unused: no tracking loss starts without a positive dropout_rate_hz");
  if (p.delay_s + p.delay_jitter_s > 1.0) f.at("delay_jitter_s").fail("delay_s + delay_jitter_s must be at most 1 s");
  if (!(p.position_sigma > 0.0) || !(p.attitude_sigma > 0.0))
    f.fail("position_sigma and attitude_sigma must be positive (the EKF divides by them)");
  return p;
}

Json to_json(const ImuParams& p) {
  return Json{{"accel_noise_density", p.accel_noise_density},
              {"gyro_noise_density", p.gyro_noise_density},
              {"accel_bias_random_walk", p.accel_bias_random_walk},
              {"gyro_bias_random_walk", p.gyro_bias_random_walk},
              {"accel_bias_initial", p.accel_bias_initial},
              {"gyro_bias_initial", p.gyro_bias_initial}};
}

Json to_json(const PoseParams& p) {
  Json doc{{"rate_hz", p.rate_hz},
              {"delay_s", p.delay_s},
              {"position_sigma", p.position_sigma},
              {"attitude_sigma", p.attitude_sigma},
              {"outlier_probability", p.outlier_probability},
              {"outlier_magnitude", p.outlier_magnitude}};
  if (p.vio()) {
    doc["drift_random_walk"] = p.drift_random_walk;
    doc["yaw_drift_random_walk"] = p.yaw_drift_random_walk;
    doc["delay_jitter_s"] = p.delay_jitter_s;
    doc["dropout_rate_hz"] = p.dropout_rate_hz;
    // pose_params_from_json refuses a loss's length without losses as unused: left out when
    // it is the default 0 (a stray non-zero length is written, and refused by the reader).
    if (p.dropout_rate_hz > 0.0 || p.dropout_mean_s != 0.0) doc["dropout_mean_s"] = p.dropout_mean_s;
  }
  return doc;
}

}  // namespace miner::flight
