#pragma once
/// \file
/// Quadrotor rigid-body dynamics integrated with SUNDIALS CVODE (REQ-FLIGHT-002).
///
/// State x = (p, v, q, omega, w) in R^17: position and velocity in the world (ENU, z up),
/// attitude quaternion q (body to world, w x y z), body rates omega and the four rotor
/// speeds w. With R = R(q), rotor thrusts f_i = k_f w_i^2 and (T, tau) = A f (Mixer):
///
///   p' = v
///   v' = -g e3 + (T / m) R e3 - F_drag(v - w) / m,   F_drag(v_a) = R D_w R^T v_a + c_q |v_a| v_a
///        D_w = D + k_r (sum_i w_i) diag(1, 1, 0)      (w the wind, aerodynamic_drag())
///   q' = 1/2 q (x) (0, omega)
///   omega' = J^{-1} (tau - omega x J omega)
///   w_i' = (u_i - w_i) / tau_m,   tau_m = tau_up if u_i > w_i else tau_down
///
/// The rotor speed commands u are held constant between control ticks (zero-order
/// hold): every advance() re-initialises CVODE at the tick and sets the stop time at the
/// next one, so no step integrates across an input change (../shared/anchors.md), and
/// renormalises q afterwards. The RHS uses q / |q| so a drifting norm never scales R.

#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "miner/flight/vehicle.hpp"

namespace miner::flight {

struct QuadState {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  Eigen::Vector4d rotor = Eigen::Vector4d::Zero();  ///< rad/s
};

/// Hovering at p: level, at rest, every rotor at the hover speed.
QuadState hover_state(const VehicleParams& vehicle, const Eigen::Vector3d& p, double yaw = 0.0);

/// Time derivative of the state, packed like pack() (17 entries).
using StateVector = Eigen::Matrix<double, 17, 1>;
StateVector pack(const QuadState& s);
QuadState unpack(const StateVector& x);

/// The aerodynamic drag force (world, N) at air-relative velocity v_air = v - wind with
/// rotor speeds summing to `rotor_speed_sum`: linear body drag, rotor drag in the rotor
/// plane and quadratic body drag (REQ-FLIGHT-012).
Eigen::Vector3d aerodynamic_drag(const VehicleParams& vehicle, const Eigen::Matrix3d& r,
                                 const Eigen::Vector3d& v_air, double rotor_speed_sum);

/// x' = f(x, u) above; `disturbance` is an extra world force (N), `wind` the air's
/// velocity (m/s, world).
StateVector derivative(const VehicleParams& vehicle, const Mixer& mixer, const StateVector& x,
                       const Eigen::Vector4d& rotor_command,
                       const Eigen::Vector3d& disturbance = Eigen::Vector3d::Zero(),
                       const Eigen::Vector3d& wind = Eigen::Vector3d::Zero());

/// Linear acceleration p'' of state s (the accelerometer's input), m/s^2.
Eigen::Vector3d acceleration(const VehicleParams& vehicle, const Mixer& mixer, const QuadState& s,
                             const Eigen::Vector3d& disturbance = Eigen::Vector3d::Zero(),
                             const Eigen::Vector3d& wind = Eigen::Vector3d::Zero());

struct IntegratorOptions {
  /// CVODE relative tolerance. Absolute tolerances are rtol times the scale of each
  /// component (1 m, 1 m/s, 1, 1 rad/s, w_max). Adams-Moulton + fixed point (non-stiff).
  double relative_tolerance = 1e-6;
  long max_steps_per_tick = 5000;
};

/// CVODE wrapper owning its SUNContext, vector and memory (not copyable).
class Integrator {
 public:
  Integrator(const VehicleParams& vehicle, IntegratorOptions options = {});
  ~Integrator();
  Integrator(const Integrator&) = delete;
  Integrator& operator=(const Integrator&) = delete;

  /// Integrates `state` from t0 to t1 > t0 with `rotor_command`, `disturbance` and `wind`
  /// held constant; throws miner::Error if CVODE fails (naming its flag) or the state stops
  /// being finite.
  void advance(QuadState& state, double t0, double t1, const Eigen::Vector4d& rotor_command,
               const Eigen::Vector3d& disturbance = Eigen::Vector3d::Zero(),
               const Eigen::Vector3d& wind = Eigen::Vector3d::Zero());

  /// Right-hand-side evaluations since construction (for benchmarks).
  long rhs_evaluations() const;
  const VehicleParams& vehicle() const;
  const Mixer& mixer() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace miner::flight
