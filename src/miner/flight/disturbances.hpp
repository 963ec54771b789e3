#pragma once
/// \file
/// What makes a simulated flight look like a real one (issue 23): wind, the mismatch between
/// the vehicle the controller assumes and the one that flies, and the battery's voltage sag.
/// Every random draw comes from the flight's seeded streams; every model is off (and draws
/// nothing, so an ideal flight keeps its bytes) unless its scenario section is given.
///
/// Wind (REQ-FLIGHT-012), in the world frame, air velocity w = w_mean + w_turb + w_gust:
/// - w_turb: Dryden turbulence (MIL-F-8785C), one independent process per axis through the
///   frozen field at airspeed V = max(|w_mean - v|, kMinTurbulenceAirspeed):
///     Phi_u(omega) = sigma_u^2 (2 L_u / (pi V)) / (1 + (L_u omega / V)^2)          (x, y)
///     Phi_w(omega) = sigma_w^2 (L_w / (pi V)) (1 + 3 (L_w omega / V)^2) / (1 + (L_w omega / V)^2)^2   (z)
///   one-sided spectra in rad/s whose integrals are sigma^2. The horizontal axes use the
///   longitudinal form (a quadrotor has no preferred heading), the vertical the lateral one.
///   Each is the exact zero-order-hold discretisation of its shaping filter driven by unit
///   white noise: u_{k+1} = a u_k + sigma sqrt(1 - a^2) n, a = exp(-V dt / L) for the
///   first-order form; for the second-order form x' = A x + b n, H(s) = sigma sqrt(T)
///   (1 + sqrt(3) T s) / (1 + T s)^2, T = L / V, with Phi = exp(A dt) and Q_d by Van Loan.
/// - w_gust: "1 - cosine" gusts, w = peak (1 - cos(2 pi (t - t0) / d)) / 2 on [t0, t0 + d].
///
/// Aerodynamics (REQ-FLIGHT-012, dynamics.hpp): the vehicle feels the air-relative velocity
/// v_a = v - w through its linear drag, the rotor drag (blade flapping and induced drag,
/// proportional to the rotor speeds' sum, in the rotor plane) and a quadratic body drag.
///
/// Mismatch (REQ-FLIGHT-013): the plant flies with mass, inertia, thrust coefficient, every
/// drag coefficient and the motor time constants multiplied by the scenario's factors; the
/// SE(3) controller, the N3's mixer and the EKF keep the nominal vehicle.
///
/// Battery (REQ-FLIGHT-014): open-circuit voltage linear in the state of charge between
/// empty and full, terminal voltage V = V_oc - R I with I = P / V (the larger root of
/// V^2 - V_oc V + R P = 0; V_oc / 2 when P exceeds what the cell can deliver), electrical
/// power P = sum_i k_m w_i^3 / eta (each rotor's drag torque k_m w^2 times its speed). The
/// speed-controlled motors top out at w_max V / V_full: sag lowers the maximum thrust.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/core/rng.hpp"
#include "miner/flight/vehicle.hpp"

namespace miner::flight {

/// Below this airspeed the frozen-turbulence transform (L / V time constant) is taken at
/// 1 m/s: a hovering vehicle in still mean air still meets eddies at walking pace, and the
/// filter's time constant stays finite.
inline constexpr double kMinTurbulenceAirspeed = 1.0;  // m/s

struct Gust {
  double start_s = 0.0;
  double duration_s = 1.0;
  Eigen::Vector3d peak = Eigen::Vector3d::Zero();  ///< m/s, world
};

struct WindParams {
  bool enabled = false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  ///< m/s, world
  double sigma_horizontal = 0.0;                   ///< m/s, sigma_u = sigma_v
  double sigma_vertical = 0.0;                     ///< m/s, sigma_w
  /// Scale lengths (m). MIL-F-8785C at 1.5 m altitude: L_w = h = 1.5 m,
  /// L_u = h / (0.177 + 0.000823 h)^1.2 ~ 12 m (h in ft in the standard's formula).
  double length_horizontal = 12.0;
  double length_vertical = 1.5;
  std::vector<Gust> gusts;
};
WindParams wind_params_from_json(const JsonField& f);
Json to_json(const WindParams& w);

/// Dryden turbulence plus mean wind and gusts, stepped once per simulation tick.
class WindModel {
 public:
  WindModel(const WindParams& params, double dt, Rng& rng);
  /// The wind at time t for a vehicle flying at world velocity v; advances the turbulence
  /// one tick (call once per tick, in order).
  Eigen::Vector3d step(double t, const Eigen::Vector3d& v);
  /// Gust part alone at time t.
  Eigen::Vector3d gust(double t) const;
  const WindParams& params() const { return params_; }

 private:
  void discretise(double airspeed);
  WindParams params_;
  double dt_;
  Rng* rng_;
  double u_[2] = {0.0, 0.0};           ///< horizontal first-order states (x, y)
  Eigen::Vector2d w_ = Eigen::Vector2d::Zero();  ///< vertical second-order state
  double airspeed_ = -1.0;             ///< V the coefficients below were computed for
  double a_u_ = 0.0, b_u_ = 0.0;       ///< u_{k+1} = a u_k + b n
  Eigen::Matrix2d phi_w_ = Eigen::Matrix2d::Zero(), chol_w_ = Eigen::Matrix2d::Zero();
  Eigen::RowVector2d c_w_ = Eigen::RowVector2d::Zero();
};

/// One-sided Dryden spectra (rad/s) of the horizontal (first-order) and vertical
/// (second-order) forms, for the tests and docs.
double dryden_psd_horizontal(double sigma, double length, double airspeed, double omega);
double dryden_psd_vertical(double sigma, double length, double airspeed, double omega);

struct MismatchParams {
  double mass = 1.0, inertia = 1.0, thrust_coefficient = 1.0, drag = 1.0, motor_time_constant = 1.0;
  bool any() const {
    return mass != 1.0 || inertia != 1.0 || thrust_coefficient != 1.0 || drag != 1.0 || motor_time_constant != 1.0;
  }
};
/// Factors in [kMinMismatch, kMaxMismatch]: half to twice the nominal value.
inline constexpr double kMinMismatch = 0.5, kMaxMismatch = 2.0;
MismatchParams mismatch_params_from_json(const JsonField& f);
Json to_json(const MismatchParams& m);
/// The vehicle that flies: `nominal` with the factors applied; throws naming the factor
/// when the result is not a physical, flyable vehicle (validate()).
VehicleParams plant_vehicle(const VehicleParams& nominal, const MismatchParams& m);

struct BatteryParams {
  bool enabled = false;
  double full_voltage = 16.8;      ///< V, 4S LiPo charged
  double empty_voltage = 13.2;     ///< V, 4S at 3.3 V per cell
  double capacity_wh = 60.0;       ///< Wh
  double internal_resistance = 0.04;  ///< ohm, pack
  double efficiency = 0.75;        ///< motor + ESC, mechanical / electrical power
  double initial_charge = 1.0;     ///< state of charge at take-off, (0, 1]
};
BatteryParams battery_params_from_json(const JsonField& f);
Json to_json(const BatteryParams& b);

class Battery {
 public:
  explicit Battery(const BatteryParams& params);
  /// Draws the electrical power of rotor speeds w for dt seconds; returns the terminal
  /// voltage during the interval. It never gives more than it stores: once the charge is spent
  /// the pack is depleted (voltage 0; issue 20, eighth campaign W3: 0.5 Wh gave 2.67 Wh).
  double step(const VehicleParams& plant, const Eigen::Vector4d& w, double dt);
  /// Electrical power (W) of rotor speeds w.
  static double power(const VehicleParams& plant, const BatteryParams& b, const Eigen::Vector4d& w);
  /// Terminal voltage at state of charge `charge` delivering `power` W.
  static double terminal_voltage(const BatteryParams& b, double charge, double power);
  double voltage() const { return voltage_; }
  double charge() const { return charge_; }
  double energy_used_wh() const { return used_wh_; }
  /// The pack is empty: its stored energy is spent, the ESCs' low-voltage cutoff holds the
  /// voltage (and the rotors) at 0 from then on.
  bool depleted() const { return depleted_; }
  /// Highest rotor speed the motors reach at the present voltage (rad/s).
  double rotor_speed_limit(const VehicleParams& plant) const {
    return plant.rotor_speed_max * voltage_ / params_.full_voltage;
  }

 private:
  BatteryParams params_;
  double charge_, voltage_, used_wh_ = 0.0;
  bool depleted_ = false;
};

}  // namespace miner::flight
