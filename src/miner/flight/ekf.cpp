#include "miner/flight/ekf.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "miner/core/error.hpp"
#include "miner/core/statistics.hpp"
#include "miner/flight/vehicle.hpp"

namespace miner::flight {

namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return m;
}

/// The nonzero blocks of E = F - I for one IMU step.
struct Transition {
  double dt;
  Eigen::Matrix3d a;  ///< E_v,theta
  Eigen::Matrix3d b;  ///< E_v,ba
  Eigen::Matrix3d c;  ///< E_theta,theta

  /// E X, by block rows (rows of b_a and b_g are zero).
  Matrix15 times(const Matrix15& x) const {
    Matrix15 y;
    y.middleRows<3>(0) = dt * x.middleRows<3>(3);
    y.middleRows<3>(3) = a * x.middleRows<3>(6) + b * x.middleRows<3>(9);
    y.middleRows<3>(6) = c * x.middleRows<3>(6) - dt * x.middleRows<3>(12);
    y.bottomRows<6>().setZero();
    return y;
  }
};

}  // namespace

Matrix15 initial_covariance(const EkfParams& params) {
  Vector15 sigma;
  sigma << Eigen::Vector3d::Constant(params.initial_position_sigma),
      Eigen::Vector3d::Constant(params.initial_velocity_sigma),
      Eigen::Vector3d::Constant(params.initial_attitude_sigma),
      Eigen::Vector3d::Constant(params.imu.accel_bias_initial),
      Eigen::Vector3d::Constant(params.imu.gyro_bias_initial);
  return sigma.array().square().matrix().asDiagonal();
}

Vector15 state_error(const NavState& estimate, const NavState& truth) {
  Vector15 e;
  e << truth.p - estimate.p, truth.v - estimate.v, quat_log(estimate.q.conjugate() * truth.q),
      truth.b_a - estimate.b_a, truth.b_g - estimate.b_g;
  return e;
}

void strapdown(NavState& x, const ImuSample& s, double dt) {
  const Eigen::Vector3d a = x.q * (s.accel - x.b_a) - Eigen::Vector3d(0.0, 0.0, kGravity);
  x.p += x.v * dt + 0.5 * a * dt * dt;
  x.v += a * dt;
  x.q = (x.q * quat_exp((s.gyro - x.b_g) * dt)).normalized();
}

Ekf::Ekf(const EkfParams& params, double imu_dt, int delay_ticks, const NavState& initial,
         const Matrix15& p0)
    : params_(params), dt_(imu_dt), delay_ticks_(delay_ticks), x_(initial), p_(p0) {
  if (!(imu_dt > 0.0) || delay_ticks < 0) throw Error("ekf: needs imu_dt > 0 and delay_ticks >= 0");
  if (!(params.gate_probability > 0.0 && params.gate_probability < 1.0))
    throw Error("ekf: gate_probability must be in (0, 1)");
  gate_ = chi_square_quantile(params.gate_probability, 6.0);
}

void Ekf::predict(const ImuSample& s) {
  const Eigen::Matrix3d r = x_.q.toRotationMatrix();
  const Eigen::Vector3d a_body = s.accel - x_.b_a;
  const Eigen::Vector3d w_body = s.gyro - x_.b_g;
  Transition e;
  e.dt = dt_;
  e.a = -r * skew(a_body) * dt_;
  e.b = -r * dt_;
  e.c = quat_exp(w_body * dt_).toRotationMatrix().transpose() - Eigen::Matrix3d::Identity();
  const Matrix15 ep = e.times(p_);
  const Matrix15 ep_t = ep.transpose();
  p_ += ep + ep_t + e.times(ep_t);
  const auto& n = params_.imu;
  p_.diagonal().segment<3>(3).array() += n.accel_noise_density * n.accel_noise_density * dt_;
  p_.diagonal().segment<3>(6).array() += n.gyro_noise_density * n.gyro_noise_density * dt_;
  p_.diagonal().segment<3>(9).array() += n.accel_bias_random_walk * n.accel_bias_random_walk * dt_;
  p_.diagonal().segment<3>(12).array() += n.gyro_bias_random_walk * n.gyro_bias_random_walk * dt_;
  p_ = 0.5 * (p_ + p_.transpose()).eval();
  strapdown(x_, s, dt_);
  ++horizon_tick_;
}

void Ekf::push_imu(std::int64_t tick, const ImuSample& sample) {
  if (latest_tick_ >= 0 && tick != latest_tick_ + 1)
    throw Error("ekf: IMU tick " + std::to_string(tick) + " after " + std::to_string(latest_tick_) +
                " (samples must come one tick at a time)");
  if (latest_tick_ < 0) horizon_tick_ = tick;  // the initial state describes the first tick
  latest_tick_ = tick;
  imu_buffer_.emplace_back(tick, sample);
  fuse_due();
  // The buffer's front is always the horizon's tick; step the horizon up to latest - delay.
  while (!imu_buffer_.empty() && horizon_tick_ < latest_tick_ - delay_ticks_) {
    predict(imu_buffer_.front().second);
    imu_buffer_.pop_front();
    fuse_due();
  }
}

FuseResult Ekf::push_pose(const PoseMeasurement& m) {
  const auto stamp_tick = static_cast<std::int64_t>(std::llround(m.stamp / dt_));
  last_ = FuseResult{};
  if (stamp_tick < horizon_tick_) {
    ++stale_;
    last_.stale = true;
    return last_;
  }
  auto it = pose_buffer_.begin();
  while (it != pose_buffer_.end() && it->first <= stamp_tick) ++it;
  pose_buffer_.insert(it, {stamp_tick, m});
  fuse_due();
  return last_;
}

void Ekf::fuse_due() {
  while (!pose_buffer_.empty() && pose_buffer_.front().first <= horizon_tick_) {
    if (pose_buffer_.front().first < horizon_tick_) {
      ++stale_;
      last_ = FuseResult{};
      last_.stale = true;
    } else {
      last_ = fuse(pose_buffer_.front().second);
    }
    pose_buffer_.pop_front();
  }
}

FuseResult Ekf::fuse(const PoseMeasurement& m) {
  FuseResult out;
  Eigen::Matrix<double, 6, 1> r;
  r << m.p - x_.p, quat_log(x_.q.conjugate() * m.q);
  // H selects rows/columns 0-2 (position) and 6-8 (attitude).
  const int idx[6] = {0, 1, 2, 6, 7, 8};
  Eigen::Matrix<double, 6, 6> s;
  Eigen::Matrix<double, 15, 6> pht;
  for (int j = 0; j < 6; ++j) {
    pht.col(j) = p_.col(idx[j]);
    for (int i = 0; i < 6; ++i) s(i, j) = p_(idx[i], idx[j]);
  }
  const double sp = params_.pose.position_sigma, sa = params_.pose.attitude_sigma;
  Eigen::Matrix<double, 6, 1> rdiag;
  rdiag << Eigen::Vector3d::Constant(sp * sp), Eigen::Vector3d::Constant(sa * sa);
  s.diagonal() += rdiag;
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(s);
  if (llt.info() != Eigen::Success) throw Error("ekf: innovation covariance is not positive definite");
  out.nis = r.dot(llt.solve(r));
  if (!(out.nis <= gate_)) {
    ++rejected_;
    return out;
  }
  const Eigen::Matrix<double, 15, 6> k = llt.solve(pht.transpose()).transpose();
  const Vector15 dx = k * r;
  // Joseph form: (I - KH) P (I - KH)^T + K R K^T.
  Matrix15 ikh = Matrix15::Identity();
  for (int j = 0; j < 6; ++j) ikh.col(idx[j]) -= k.col(j);
  p_ = ikh * p_ * ikh.transpose() + k * rdiag.asDiagonal() * k.transpose();
  x_.p += dx.segment<3>(0);
  x_.v += dx.segment<3>(3);
  x_.q = (x_.q * quat_exp(dx.segment<3>(6))).normalized();
  x_.b_a += dx.segment<3>(9);
  x_.b_g += dx.segment<3>(12);
  // Reset: the attitude error is re-expressed about the corrected attitude.
  Matrix15 g = Matrix15::Identity();
  g.block<3, 3>(6, 6) -= skew(0.5 * dx.segment<3>(6));
  p_ = g * p_ * g.transpose();
  p_ = 0.5 * (p_ + p_.transpose()).eval();
  ++fused_;
  nis_.push_back(out.nis);
  out.accepted = true;
  return out;
}

NavState Ekf::current() const {
  NavState x = x_;
  for (const auto& [tick, sample] : imu_buffer_) {
    if (tick >= latest_tick_) break;  // the latest sample predicts the next tick
    strapdown(x, sample, dt_);
  }
  return x;
}

}  // namespace miner::flight
