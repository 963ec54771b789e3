#include "miner/flight/disturbances.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include <unsupported/Eigen/MatrixFunctions>

#include "miner/core/error.hpp"
#include "miner/core/units.hpp"

namespace miner::flight {

namespace {

/// Mean wind up to a strong gale and turbulence up to "severe" (MIL-F-8785C: sigma ~ 7 m/s at
/// low altitude); a quadrotor of the N3 class cannot fly in either, but the model stays defined.
constexpr double kMaxWindSpeed = 30.0;   // m/s
constexpr double kMaxTurbulence = 10.0;  // m/s
constexpr double kMaxScaleLength = 1000.0;  // m
/// Gusts a scenario may hold: each tick sums every gust (bounded work per tick; issue 20: 10^6
/// gusts ran for ever), and 1000 is one a second for a 1000 s flight.
constexpr std::size_t kMaxGusts = 1000;

}  // namespace

WindParams wind_params_from_json(const JsonField& f) {
  f.only_keys({"mean_m_s", "sigma_horizontal_m_s", "sigma_vertical_m_s", "length_horizontal_m", "length_vertical_m",
               "gusts"});
  WindParams w;
  w.enabled = true;
  if (f.has("mean_m_s")) {
    w.mean = f.at("mean_m_s").vec3();
    if (w.mean.norm() > kMaxWindSpeed) f.at("mean_m_s").fail("a mean wind above 30 m/s is beyond any multirotor");
  }
  w.sigma_horizontal = f.number_in_or("sigma_horizontal_m_s", 0.0, 0.0, kMaxTurbulence, "m/s");
  w.sigma_vertical = f.number_in_or("sigma_vertical_m_s", 0.0, 0.0, kMaxTurbulence, "m/s");
  w.length_horizontal = f.number_in_or("length_horizontal_m", w.length_horizontal, 0.0, kMaxScaleLength, "m");
  w.length_vertical = f.number_in_or("length_vertical_m", w.length_vertical, 0.0, kMaxScaleLength, "m");
  if (!(w.length_horizontal > 0.0)) f.at("length_horizontal_m").fail("must be positive");
  if (!(w.length_vertical > 0.0)) f.at("length_vertical_m").fail("must be positive");
  if (f.has("gusts")) {
    const JsonField g = f.at("gusts");
    if (g.array_size() > kMaxGusts)
      g.fail("holds " + std::to_string(g.array_size()) + " gusts; at most " + std::to_string(kMaxGusts));
    for (std::size_t i = 0; i < g.array_size(); ++i) {
      const JsonField e = g.at(i);
      e.only_keys({"start_s", "duration_s", "peak_m_s"});
      Gust gust;
      gust.start_s = e.at("start_s").number_in(0.0, 1000.0, "s");
      gust.duration_s = e.at("duration_s").number_in(0.0, 1000.0, "s");
      if (!(gust.duration_s > 0.0)) e.at("duration_s").fail("must be positive");
      gust.peak = e.at("peak_m_s").vec3();
      if (gust.peak.norm() > kMaxWindSpeed) e.at("peak_m_s").fail("a gust above 30 m/s is beyond any multirotor");
      w.gusts.push_back(gust);
    }
    // Gusts add up where they overlap: the 30 m/s bound holds for the wind they make together
    // with the mean (bounded by the sum of the speeds; a sweep over the gusts' start and end).
    std::vector<std::pair<double, double>> events;  // (time, +speed at a start / -speed after an end)
    for (const Gust& e : w.gusts) {
      events.emplace_back(e.start_s, e.peak.norm());
      events.emplace_back(e.start_s + e.duration_s, -e.peak.norm());
    }
    std::sort(events.begin(), events.end(), [](const auto& a, const auto& b) {
      return a.first < b.first || (a.first == b.first && a.second > b.second);  // closed intervals
    });
    double speed = w.mean.norm();
    for (const auto& [t, dv] : events) {
      speed += dv;
      if (speed > kMaxWindSpeed * (1.0 + 1e-12)) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "the gusts overlapping at t = %g s add up, with the mean wind, to up to %.4g m/s, above 30 m/s "
                      "(beyond any multirotor)",
                      t, speed);
        g.fail(text);
      }
    }
  }
  return w;
}

Json to_json(const WindParams& w) {
  Json gusts = Json::array();
  for (const auto& g : w.gusts)
    gusts.push_back({{"start_s", g.start_s}, {"duration_s", g.duration_s}, {"peak_m_s", vec3_json(g.peak)}});
  return Json{{"mean_m_s", vec3_json(w.mean)},
              {"sigma_horizontal_m_s", w.sigma_horizontal},
              {"sigma_vertical_m_s", w.sigma_vertical},
              {"length_horizontal_m", w.length_horizontal},
              {"length_vertical_m", w.length_vertical},
              {"gusts", gusts}};
}

double dryden_psd_horizontal(double sigma, double length, double airspeed, double omega) {
  const double x = length * omega / airspeed;
  return sigma * sigma * 2.0 * length / (kPi * airspeed) / (1.0 + x * x);
}

double dryden_psd_vertical(double sigma, double length, double airspeed, double omega) {
  const double x = length * omega / airspeed;
  return sigma * sigma * length / (kPi * airspeed) * (1.0 + 3.0 * x * x) / ((1.0 + x * x) * (1.0 + x * x));
}

WindModel::WindModel(const WindParams& params, double dt, Rng& rng) : params_(params), dt_(dt), rng_(&rng) {}

void WindModel::discretise(double airspeed) {
  airspeed_ = airspeed;
  // First order (x, y): the Ornstein-Uhlenbeck process with variance sigma^2, exactly.
  a_u_ = std::exp(-airspeed * dt_ / params_.length_horizontal);
  b_u_ = params_.sigma_horizontal * std::sqrt(std::max(0.0, 1.0 - a_u_ * a_u_));
  // Second order (z): x1' = x2, x2' = -x1 / T^2 - 2 x2 / T + n, y = sigma sqrt(T) / T^2 (x1 + sqrt(3) T x2),
  // i.e. H(s) = sigma sqrt(T) (1 + sqrt(3) T s) / (1 + T s)^2 with unit white noise n.
  const double t = params_.length_vertical / airspeed;
  Eigen::Matrix2d a;
  a << 0.0, 1.0, -1.0 / (t * t), -2.0 / t;
  // Van Loan: exp([[-A, B B^T], [0, A^T]] dt) = [[., Phi^-1 Q_d], [0, Phi^T]].
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.topLeftCorner<2, 2>() = -a;
  m(1, 3) = 1.0;  // B B^T with B = (0, 1)
  m.bottomRightCorner<2, 2>() = a.transpose();
  const Eigen::Matrix4d e = (m * dt_).exp();
  phi_w_ = e.bottomRightCorner<2, 2>().transpose();
  Eigen::Matrix2d q = phi_w_ * e.topRightCorner<2, 2>();
  q = 0.5 * (q + q.transpose());
  // 2x2 Cholesky; Q_d is positive definite for dt > 0 (the pair (A, B) is controllable).
  const double l11 = std::sqrt(std::max(q(0, 0), 0.0));
  const double l21 = l11 > 0.0 ? q(1, 0) / l11 : 0.0;
  const double l22 = std::sqrt(std::max(q(1, 1) - l21 * l21, 0.0));
  chol_w_ << l11, 0.0, l21, l22;
  c_w_ << params_.sigma_vertical * std::sqrt(t) / (t * t), params_.sigma_vertical * std::sqrt(t) * std::sqrt(3.0) / t;
}

Eigen::Vector3d WindModel::gust(double t) const {
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (const auto& e : params_.gusts)
    if (t >= e.start_s && t <= e.start_s + e.duration_s)
      g += e.peak * 0.5 * (1.0 - std::cos(2.0 * kPi * (t - e.start_s) / e.duration_s));
  return g;
}

Eigen::Vector3d WindModel::step(double t, const Eigen::Vector3d& v) {
  Eigen::Vector3d turbulence = Eigen::Vector3d::Zero();
  if (params_.sigma_horizontal > 0.0 || params_.sigma_vertical > 0.0) {
    const double airspeed = std::max((params_.mean - v).norm(), kMinTurbulenceAirspeed);
    // Recompute the discretisation when V moved by more than 1 %: the coefficients change
    // smoothly with V, and a hovering or cruising vehicle keeps them for many ticks.
    if (!(std::abs(airspeed - airspeed_) <= 0.01 * airspeed_)) discretise(airspeed);
    turbulence.x() = u_[0];
    turbulence.y() = u_[1];
    turbulence.z() = c_w_ * w_;
    for (double& u : u_) u = a_u_ * u + b_u_ * rng_->normal();
    const Eigen::Vector2d n(rng_->normal(), rng_->normal());
    w_ = phi_w_ * w_ + chol_w_ * n;
  }
  return params_.mean + turbulence + gust(t);
}

MismatchParams mismatch_params_from_json(const JsonField& f) {
  f.only_keys({"mass", "inertia", "thrust_coefficient", "drag", "motor_time_constant"});
  MismatchParams m;
  m.mass = f.number_in_or("mass", 1.0, kMinMismatch, kMaxMismatch, "x nominal");
  m.inertia = f.number_in_or("inertia", 1.0, kMinMismatch, kMaxMismatch, "x nominal");
  m.thrust_coefficient = f.number_in_or("thrust_coefficient", 1.0, kMinMismatch, kMaxMismatch, "x nominal");
  m.drag = f.number_in_or("drag", 1.0, kMinMismatch, kMaxMismatch, "x nominal");
  m.motor_time_constant = f.number_in_or("motor_time_constant", 1.0, kMinMismatch, kMaxMismatch, "x nominal");
  return m;
}

Json to_json(const MismatchParams& m) {
  return Json{{"mass", m.mass},
              {"inertia", m.inertia},
              {"thrust_coefficient", m.thrust_coefficient},
              {"drag", m.drag},
              {"motor_time_constant", m.motor_time_constant}};
}

VehicleParams plant_vehicle(const VehicleParams& nominal, const MismatchParams& m) {
  VehicleParams p = nominal;
  p.mass *= m.mass;
  p.inertia *= m.inertia;
  p.thrust_coefficient *= m.thrust_coefficient;
  p.linear_drag *= m.drag;
  p.rotor_drag *= m.drag;
  p.quadratic_drag *= m.drag;
  p.motor_time_constant_up *= m.motor_time_constant;
  p.motor_time_constant_down *= m.motor_time_constant;
  validate(p, "mismatch (the vehicle that flies)");
  return p;
}

BatteryParams battery_params_from_json(const JsonField& f) {
  f.only_keys({"full_voltage_v", "empty_voltage_v", "capacity_wh", "internal_resistance_ohm", "efficiency",
               "initial_charge"});
  BatteryParams b;
  b.enabled = true;
  b.full_voltage = f.number_in_or("full_voltage_v", b.full_voltage, 0.0, 1000.0, "V");
  b.empty_voltage = f.number_in_or("empty_voltage_v", b.empty_voltage, 0.0, 1000.0, "V");
  b.capacity_wh = f.number_in_or("capacity_wh", b.capacity_wh, 0.0, 1e5, "Wh");
  b.internal_resistance = f.number_in_or("internal_resistance_ohm", b.internal_resistance, 0.0, 10.0, "ohm");
  b.efficiency = f.number_in_or("efficiency", b.efficiency, 0.0, 1.0, "");
  b.initial_charge = f.number_in_or("initial_charge", b.initial_charge, 0.0, 1.0, "");
  if (!(b.empty_voltage > 0.0) || !(b.full_voltage > b.empty_voltage))
    f.fail("needs 0 < empty_voltage_v < full_voltage_v, got " + std::to_string(b.empty_voltage) + " and " +
           std::to_string(b.full_voltage));
  if (!(b.capacity_wh > 0.0)) f.at("capacity_wh").fail("must be positive");
  if (!(b.efficiency > 0.0)) f.at("efficiency").fail("must be positive");
  if (!(b.initial_charge > 0.0)) f.at("initial_charge").fail("must be positive (an empty battery does not take off)");
  return b;
}

Json to_json(const BatteryParams& b) {
  return Json{{"full_voltage_v", b.full_voltage},
              {"empty_voltage_v", b.empty_voltage},
              {"capacity_wh", b.capacity_wh},
              {"internal_resistance_ohm", b.internal_resistance},
              {"efficiency", b.efficiency},
              {"initial_charge", b.initial_charge}};
}

Battery::Battery(const BatteryParams& params)
    : params_(params), charge_(params.initial_charge), voltage_(terminal_voltage(params, params.initial_charge, 0.0)) {}

double Battery::power(const VehicleParams& plant, const BatteryParams& b, const Eigen::Vector4d& w) {
  const double k_m = plant.torque_to_thrust_ratio * plant.thrust_coefficient;  // N m / (rad/s)^2
  return k_m * w.array().cube().sum() / b.efficiency;
}

double Battery::terminal_voltage(const BatteryParams& b, double charge, double power) {
  const double v_oc = b.empty_voltage + (b.full_voltage - b.empty_voltage) * std::clamp(charge, 0.0, 1.0);
  const double disc = v_oc * v_oc - 4.0 * b.internal_resistance * power;
  // Beyond the maximum power point the pack cannot deliver P: it sits at V_oc / 2.
  return disc > 0.0 ? 0.5 * (v_oc + std::sqrt(disc)) : 0.5 * v_oc;
}

double Battery::step(const VehicleParams& plant, const Eigen::Vector4d& w, double dt) {
  if (depleted_) return voltage_;
  const double p = power(plant, params_, w);
  voltage_ = terminal_voltage(params_, charge_, p);
  const double stored_wh = charge_ * params_.capacity_wh;
  const double wh = std::min(p * dt / 3600.0, stored_wh);
  used_wh_ += wh;
  charge_ = std::max(0.0, (stored_wh - wh) / params_.capacity_wh);
  if (charge_ <= 0.0 && p > 0.0) {
    depleted_ = true;
    voltage_ = 0.0;
  }
  return voltage_;
}

}  // namespace miner::flight
