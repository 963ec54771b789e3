#include "miner/flight/dynamics.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "miner/core/error.hpp"

namespace miner::flight {

QuadState hover_state(const VehicleParams& vehicle, const Eigen::Vector3d& p, double yaw) {
  QuadState s;
  s.p = p;
  s.q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  s.rotor.setConstant(vehicle.hover_rotor_speed());
  return s;
}

StateVector pack(const QuadState& s) {
  StateVector x;
  x << s.p, s.v, s.q.w(), s.q.x(), s.q.y(), s.q.z(), s.omega, s.rotor;
  return x;
}

QuadState unpack(const StateVector& x) {
  QuadState s;
  s.p = x.segment<3>(0);
  s.v = x.segment<3>(3);
  s.q = Eigen::Quaterniond(x[6], x[7], x[8], x[9]);
  s.omega = x.segment<3>(10);
  s.rotor = x.segment<4>(13);
  return s;
}

Eigen::Vector3d aerodynamic_drag(const VehicleParams& vehicle, const Eigen::Matrix3d& r,
                                 const Eigen::Vector3d& v_air, double rotor_speed_sum) {
  // Each extra term only when modelled, so a vehicle without them keeps its bytes.
  Eigen::Vector3d d = vehicle.linear_drag;
  if (vehicle.rotor_drag != 0.0) d.head<2>().array() += vehicle.rotor_drag * rotor_speed_sum;
  Eigen::Vector3d drag = r * (d.asDiagonal() * (r.transpose() * v_air));
  if (vehicle.quadratic_drag != 0.0) drag += vehicle.quadratic_drag * v_air.norm() * v_air;
  return drag;
}

namespace {

/// Shared by derivative() and acceleration(): v' given the rotation, thrust, velocity, wind
/// and rotor speeds.
Eigen::Vector3d linear_acceleration(const VehicleParams& vehicle, const Eigen::Matrix3d& r,
                                    double thrust, const Eigen::Vector3d& v,
                                    const Eigen::Vector3d& disturbance, const Eigen::Vector3d& wind,
                                    const Eigen::Vector4d& rotor) {
  const Eigen::Vector3d drag = aerodynamic_drag(vehicle, r, v - wind, rotor.sum());
  return Eigen::Vector3d(0.0, 0.0, -kGravity) + (thrust * r.col(2) - drag + disturbance) / vehicle.mass;
}

Eigen::Vector4d rotor_thrusts(const VehicleParams& vehicle, const Eigen::Vector4d& w) {
  return vehicle.thrust_coefficient * w.array().square().matrix();
}

}  // namespace

StateVector derivative(const VehicleParams& vehicle, const Mixer& mixer, const StateVector& x,
                       const Eigen::Vector4d& rotor_command, const Eigen::Vector3d& disturbance,
                       const Eigen::Vector3d& wind) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(x[6], x[7], x[8], x[9]).normalized();
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const Eigen::Vector3d omega = x.segment<3>(10);
  const Eigen::Vector4d w = x.segment<4>(13);
  const Eigen::Vector4d wrench = mixer.wrench(rotor_thrusts(vehicle, w));

  StateVector dx;
  dx.segment<3>(0) = x.segment<3>(3);
  dx.segment<3>(3) = linear_acceleration(vehicle, r, wrench[0], x.segment<3>(3), disturbance, wind, w);
  // q' = 1/2 q (x) (0, omega), on the stored (unnormalised) q.
  const double qw = x[6], qx = x[7], qy = x[8], qz = x[9];
  dx[6] = 0.5 * (-qx * omega.x() - qy * omega.y() - qz * omega.z());
  dx[7] = 0.5 * (qw * omega.x() + qy * omega.z() - qz * omega.y());
  dx[8] = 0.5 * (qw * omega.y() + qz * omega.x() - qx * omega.z());
  dx[9] = 0.5 * (qw * omega.z() + qx * omega.y() - qy * omega.x());
  const Eigen::Vector3d j_omega = vehicle.inertia.cwiseProduct(omega);
  dx.segment<3>(10) = (wrench.tail<3>() - omega.cross(j_omega)).cwiseQuotient(vehicle.inertia);
  for (int i = 0; i < 4; ++i) {
    const double tau = rotor_command[i] > w[i] ? vehicle.motor_time_constant_up : vehicle.motor_time_constant_down;
    dx[13 + i] = (rotor_command[i] - w[i]) / tau;
  }
  return dx;
}

Eigen::Vector3d acceleration(const VehicleParams& vehicle, const Mixer& mixer, const QuadState& s,
                             const Eigen::Vector3d& disturbance, const Eigen::Vector3d& wind) {
  const Eigen::Matrix3d r = s.q.normalized().toRotationMatrix();
  const double thrust = mixer.wrench(rotor_thrusts(vehicle, s.rotor))[0];
  return linear_acceleration(vehicle, r, thrust, s.v, disturbance, wind, s.rotor);
}

namespace {
/// CVODE's name of a return flag: CVodeGetReturnFlagName returns a string the caller must free
/// (LeakSanitizer found it once a failure path was tested).
std::string flag_name(int flag) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string text = name != nullptr ? name : "unknown flag";
  std::free(name);
  return text;
}
}  // namespace

struct Integrator::Impl {
  VehicleParams vehicle;
  Mixer mixer;
  IntegratorOptions options;
  SUNContext context = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  void* cvode = nullptr;
  SUNNonlinearSolver nls = nullptr;
  bool initialised = false;
  long rhs_count = 0;
  Eigen::Vector4d command = Eigen::Vector4d::Zero();
  Eigen::Vector3d disturbance = Eigen::Vector3d::Zero();
  Eigen::Vector3d wind = Eigen::Vector3d::Zero();

  Impl(const VehicleParams& v, IntegratorOptions o) : vehicle(v), mixer(v), options(o) {}
  ~Impl() {
    if (cvode) CVodeFree(&cvode);
    if (nls) SUNNonlinSolFree(nls);
    if (y) N_VDestroy(y);
    if (abstol) N_VDestroy(abstol);
    if (context) SUNContext_Free(&context);
  }

  static int rhs(realtype /*t*/, N_Vector y_vec, N_Vector ydot, void* user) {
    auto* self = static_cast<Impl*>(user);
    ++self->rhs_count;
    const Eigen::Map<const StateVector> x(N_VGetArrayPointer(y_vec));
    Eigen::Map<StateVector> dx(N_VGetArrayPointer(ydot));
    dx = derivative(self->vehicle, self->mixer, x, self->command, self->disturbance, self->wind);
    return 0;
  }

  void check(int flag, const char* call) const {
    if (flag < 0) throw Error(std::string("CVODE: ") + call + " failed with flag " + std::to_string(flag) +
                              " (" + flag_name(flag) + ")");
  }
};

Integrator::Integrator(const VehicleParams& vehicle, IntegratorOptions options)
    : impl_(std::make_unique<Impl>(vehicle, options)) {
  validate(vehicle);
  if (!(options.relative_tolerance > 0.0) || !std::isfinite(options.relative_tolerance))
    throw Error("integrator: relative_tolerance must be positive and finite");
  auto& m = *impl_;
  if (SUNContext_Create(nullptr, &m.context) != 0) throw Error("CVODE: SUNContext_Create failed");
  m.y = N_VNew_Serial(17, m.context);
  m.abstol = N_VNew_Serial(17, m.context);
  Eigen::Map<StateVector> scale(N_VGetArrayPointer(m.abstol));
  scale.setOnes();
  scale.segment<4>(13).setConstant(vehicle.rotor_speed_max);
  scale *= options.relative_tolerance;
  N_VConst(0.0, m.y);
  m.cvode = CVodeCreate(CV_ADAMS, m.context);
  if (!m.cvode) throw Error("CVODE: CVodeCreate failed");
  m.check(CVodeInit(m.cvode, &Impl::rhs, 0.0, m.y), "CVodeInit");
  m.check(CVodeSVtolerances(m.cvode, options.relative_tolerance, m.abstol), "CVodeSVtolerances");
  m.check(CVodeSetUserData(m.cvode, &m), "CVodeSetUserData");
  m.check(CVodeSetMaxNumSteps(m.cvode, options.max_steps_per_tick), "CVodeSetMaxNumSteps");
  // CVODE's own report goes to stderr in its words ("[CVODE ERROR] CVode ... mxstep"); a failure
  // is thrown below with the time and the cause in this program's words instead.
  m.check(CVodeSetErrHandlerFn(m.cvode, [](int, const char*, const char*, char*, void*) {}, nullptr),
          "CVodeSetErrHandlerFn");
  m.nls = SUNNonlinSol_FixedPoint(m.y, 0, m.context);
  m.check(CVodeSetNonlinearSolver(m.cvode, m.nls), "CVodeSetNonlinearSolver");
}

Integrator::~Integrator() = default;

void Integrator::advance(QuadState& state, double t0, double t1, const Eigen::Vector4d& rotor_command,
                         const Eigen::Vector3d& disturbance, const Eigen::Vector3d& wind) {
  auto& m = *impl_;
  if (!(t1 > t0)) throw Error("integrator: advance needs t1 > t0");
  if (!rotor_command.allFinite() || !disturbance.allFinite() || !wind.allFinite())
    throw Error("integrator: rotor command, disturbance or wind is not finite");
  m.command = rotor_command;
  m.disturbance = disturbance;
  m.wind = wind;
  Eigen::Map<StateVector>(N_VGetArrayPointer(m.y)) = pack(state);
  // A new input starts a new smooth piece: re-initialise, and stop exactly at the tick.
  m.check(CVodeReInit(m.cvode, t0, m.y), "CVodeReInit");
  m.check(CVodeSetStopTime(m.cvode, t1), "CVodeSetStopTime");
  realtype t_reached = t0;
  const int flag = CVode(m.cvode, t1, m.y, &t_reached, CV_NORMAL);
  if (flag == CV_TOO_MUCH_WORK || flag == CV_CONV_FAILURE || flag == CV_ERR_FAILURE) {
    std::ostringstream os;
    os << "the vehicle's dynamics could not be integrated over the N3 tick [" << t0 << ", " << t1 << "] s (CVODE "
       << flag_name(flag) << " at t = " << t_reached << " s): the plant is too stiff or diverging; check "
       << "the vehicle's time constants (motor_time_constant_up_s/down_s >= " << kMinPlantTimeConstant
       << " s) and the scenario's disturbances";
    throw Error(os.str());
  }
  m.check(flag, "CVode");
  StateVector x = Eigen::Map<StateVector>(N_VGetArrayPointer(m.y));
  if (!x.allFinite()) throw Error("integrator: the state became non-finite at t = " + std::to_string(t1));
  state = unpack(x);
  state.q.normalize();
}

long Integrator::rhs_evaluations() const { return impl_->rhs_count; }
const VehicleParams& Integrator::vehicle() const { return impl_->vehicle; }
const Mixer& Integrator::mixer() const { return impl_->mixer; }

}  // namespace miner::flight
