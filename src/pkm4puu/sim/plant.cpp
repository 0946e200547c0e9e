#include "pkm4puu/sim/plant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/integrators/located_cvode.hpp"
#include "pkm4puu/integrators/located_rk4.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"
#include "pkm4puu/machine/friction.hpp"
#include "pkm4puu/machine/passive_force.hpp"

namespace pkm {

/// What located_rk4_step integrates: the plant's derivative under the held
/// stops, and its contact mode.
struct PlantOde {
  Plant& plant;
  Status rates(double t, const Vec10& x, Vec10& xdot) { return plant.derivative(t, x, xdot); }
  void hold(unsigned stops) { plant.stops_ = stops; }
  unsigned mode(const Vec10& x, Vec4& rho) const { return plant.contact_mode(x, rho); }
};

Plant::Plant(const Model& model) : model_(model) {}

Status Plant::set_solver(const SolverSettings& s, std::string* error) {
  const std::string why = validate(s);
  if (!why.empty()) {
    if (error) *error = why;
    return Status::InvalidArgument;
  }
  settings_ = s;
  cvode_ready_ = false;  // re-created on the next CVODE advance
  return Status::Ok;
}

Status Plant::initialize(double t0, const Pose& pose, const Pose& velocity) {
  error_.clear();
  if (!std::isfinite(t0) || !pose.allFinite() || !velocity.allFinite()) {
    error_ = "the initial time, pose or velocity is not finite";
    return Status::NonFinite;
  }
  Vec8 y;
  y.head<4>() = pose;
  y.tail<4>() = velocity;
  Status s = guard(y, t0);  // reachable elbow-down, within the singularity limits
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = closed_form_position(model_, pose, q);
  if (s != Status::Ok) return s;
  s = solve_position(model_, pose, q);  // Eqs. 2-4 (a polish: the closed form is exact)
  if (s != Status::Ok) {
    error_ = "the position problem at the initial pose did not converge";
    return s;
  }
  s = solve_velocity(model_, q, velocity, qd);
  if (s != Status::Ok) return s;
  // The state derivative must exist there (with no inputs): a velocity so
  // large that the Coriolis terms overflow is refused here, not at the first step.
  Vec8 ydot;
  s = state_derivative(model_, settings_.formulation, y, Vec16::Zero(), ydot);
  if (s != Status::Ok || !ydot.allFinite()) {
    error_ = "the state derivative at the initial state is not finite (initial velocity too large?)";
    return Status::NonFinite;
  }
  s = prepare_cvode();
  if (s != Status::Ok) return s;
  y_ = y;
  rho_valid_ = false;
  t_ = t0;
  energy_ = EnergyIntegrals{};
  for (int i = 0; i < kLegs; ++i) theta1_.ref[i] = q[leg_offset(i) + 1];
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

Status Plant::prepare_cvode() {
  if (settings_.solver != Solver::Cvode || cvode_ready_) return Status::Ok;
  const Status s = cvode_.init(settings_.cvode_method, settings_.rtol, settings_.atol, &Plant::cvode_rhs, this,
                               kStopIndicators, &Plant::cvode_roots);
  if (s != Status::Ok) {
    error_ = "CVODE could not be set up: " + cvode_.last_error();
    return s == Status::InvalidArgument ? s : Status::SolverFailure;
  }
  cvode_ready_ = true;
  return Status::Ok;
}

Status Plant::restore(double t, const Vec8& y, const Vec4& theta1_ref) {
  if (!std::isfinite(t) || !y.allFinite() || !theta1_ref.allFinite()) {
    error_ = "the time, state or theta1 references are not finite";
    return Status::NonFinite;
  }
  Status s = guard(y, t);
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = expand_state(model_, y, q, qd);
  if (s != Status::Ok) return s;
  // theta1 is continuous, never wrapped, but cannot wind: the references
  // are the pose's closed-form angles up to whole turns, within a few turns.
  for (int i = 0; i < kLegs; ++i) {
    const double th1 = q[leg_offset(i) + 1];
    const bool near = std::fabs(unwrap_near(th1, theta1_ref[i]) - theta1_ref[i]) <= 1e-9;
    if (!(std::fabs(theta1_ref[i]) <= kMaxTheta1) || !near) {
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "the theta1 reference %.17g rad of leg %d is not the pose's theta1 = %.17g rad modulo 2 pi "
                    "(within %g rad)",
                    theta1_ref[i], i + 1, th1, kMaxTheta1);
      error_ = buf;
      return Status::InvalidArgument;
    }
  }
  const Status prepared = prepare_cvode();
  if (prepared != Status::Ok) return prepared;
  t_ = t;
  y_ = y;
  rho_valid_ = false;
  theta1_.ref = theta1_ref;
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

Status Plant::set_state(const Vec8& y) {
  if (!initialized_) return Status::NotInitialized;
  if (!y.allFinite()) return Status::NonFinite;
  GuardReport report;
  GuardLimits none;
  none.max_jacobian_condition = std::numeric_limits<double>::infinity();
  none.min_leg_measure = 0.0;
  const Status s = check_configuration(model_, y.head<4>(), none, &report);
  if (s != Status::Ok) {
    error_ = describe_configuration_failure(model_, y.head<4>(), none, report);
    return s;
  }
  y_ = y;
  rho_valid_ = false;
  theta1_stale_ = true;
  return Status::Ok;
}

Status Plant::derivative_now(const InputSignal& inputs, Vec10& xdot) const {
  if (!initialized_) return Status::NotInitialized;
  Vec10 x;
  x.head<8>() = y_;
  x[8] = energy_.actuator_work;
  x[9] = energy_.dissipated;
  return machine_rates(inputs, t_, x, kStopsFromState, xdot);
}

Status Plant::restore(double t, const Vec8& y, const Vec4& theta1_ref, const EnergyIntegrals& e) {
  if (!std::isfinite(e.actuator_work) || !std::isfinite(e.dissipated)) return Status::NonFinite;
  const EnergyIntegrals keep = energy_;
  energy_ = e;
  const Status s = restore(t, y, theta1_ref);
  if (s != Status::Ok) energy_ = keep;
  return s;
}

Vec10 Plant::packed() const {
  Vec10 x;
  x.head<8>() = y_;
  x[8] = energy_.actuator_work;
  x[9] = energy_.dissipated;
  return x;
}

void Plant::unpack(const Vec10& x) {
  y_ = x.head<8>();
  rho_valid_ = false;
  energy_.actuator_work = x[8];
  energy_.dissipated = x[9];
}

Status Plant::actuator_positions(Vec4& rho) const {
  if (!rho_valid_) {
    const Status s = pkm::actuator_positions(model_, y_.head<4>(), rho_);
    if (s != Status::Ok) return s;
    rho_valid_ = true;
  }
  rho = rho_;
  return Status::Ok;
}

unsigned Plant::contact_mode(const Vec10& x, Vec4& rho) const {
  if (pkm::actuator_positions(model_, x.head<4>(), rho) != Status::Ok) return ~0u;
  return contact_mode_at(x, rho);
}

unsigned Plant::contact_mode_at(const Vec10& x, const Vec4& rho) const {
  unsigned mode = stops_passed(model_.p, rho);
  if (mode == 0) return mode;
  Vec16 q, qd;  // the joint rates tell a released stop
  if (expand_state(model_, x.head<8>(), q, qd) != Status::Ok) return ~0u;
  for (int i = 0; i < kLegs; ++i) {
    const StopContact c = stop_contact(model_.p, rho[i], qd[leg_offset(i)]);
    if (c.depth > 0.0 && c.force == 0.0) mode |= 1u << (2 * kLegs + i);
  }
  return mode;
}

Status Plant::derivative(double t, const Vec10& x, Vec10& xdot) {
  ++rhs_count_;
  // A non-finite trial time or state is the integrator's (a step size
  // computed from absurd accelerations), not the inputs': the step fails,
  // the state is kept.
  if (!std::isfinite(t)) return Status::SolverFailure;
  bool inputs_fault = false;
  const Status s = machine_rates(inputs_, t, x, stops_, xdot, &inputs_fault);
  // With finite inputs a non-finite derivative is the trial state's.
  if (s == Status::NonFinite && !inputs_fault) return Status::SolverFailure;
  return s;
}

Status Plant::machine_rates(const InputSignal& inputs, double t, const Vec10& x, unsigned stops, Vec10& xdot,
                            bool* inputs_fault) const {
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t, F, we, tau);
  if (!F.allFinite() || !we.allFinite() || !tau.allFinite()) {
    if (inputs_fault) *inputs_fault = true;
    return Status::NonFinite;
  }
  const Vec4 Fa = F + model_.drive_ratio * tau;   // actuator force plus the screw's
  const Vec8 y = x.head<8>();
  Vec8 ydot;
  JointMotion jm;
  const Status s =
      state_derivative(model_, settings_.formulation, y, generalized_forces(Fa, we), ydot, nullptr, &jm, stops);
  if (s != Status::Ok) return s;
  xdot.head<8>() = ydot;
  energy_rates(model_.p, stops, Fa, we, y.tail<4>(), jm.rho, jm.rhod, xdot[8], xdot[9]);
  return Status::Ok;
}

int Plant::cvode_roots(double t, const Vec10& x, double* g, void* self) {
  (void)t;
  const auto* me = static_cast<const Plant*>(self);
  if (stop_indicators(me->model_, x.head<4>(), g) != Status::Ok)
    for (int k = 0; k < kStopIndicators; ++k) g[k] = 1.0;  // off the workspace: the rhs reports it
  return 0;
}

int Plant::cvode_rhs(double t, const Vec10& y, Vec10& ydot, void* self) {
  auto* me = static_cast<Plant*>(self);
  const Status s = me->derivative(t, y, ydot);
  me->rhs_status_ = s;
  // A trial state off the workspace (or not finite) may be CVODE's
  // overshoot: let it retry with a smaller step (recoverable); non-finite
  // inputs abort.
  if (s == Status::Ok) return 0;
  return (s == Status::Unreachable || s == Status::Singular || s == Status::SolverFailure) ? 1 : -1;
}

Status Plant::guard(const Vec8& y, double t) {
  // Called after every step: the message's time is formatted only on failure
  // (a %.17g costs about a tenth of an RK4 step).
  auto at = [t] {
    char buf[64];
    std::snprintf(buf, sizeof buf, "at t = %.17g s: ", t);
    return std::string(buf);
  };
  const double speed = std::max(y.segment<3>(4).cwiseAbs().maxCoeff(), kConditionLength * std::fabs(y[7]));
  if (!(speed <= kMaxSpeed)) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the platform moves at %.6g m/s (|dx|, |dy|, |dz| or 0.1 m |dphi|), beyond the physical bound "
                  "%g m/s",
                  speed, kMaxSpeed);
    error_ = at() + buf;
    return Status::SolverFailure;
  }
  GuardReport report;
  const Status s = check_configuration(model_, y.head<4>(), settings_.limits(), &report);
  if (s == Status::Ok) return s;
  error_ = at() + describe_configuration_failure(model_, y.head<4>(), settings_.limits(), report);
  return s;
}

Status Plant::advance_rk4(double t_end) {
  const double span = t_end - t_;
  const double steps = rk4_steps_for(span, settings_.rk4_step);
  if (!(steps <= kMaxRk4StepsPerAdvance)) {  // also NaN
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "an interval of %.6g s needs %.3g RK4 steps of rk4_step = %.6g s, more than %.0e: "
                  "use shorter intervals or a larger rk4_step",
                  span, steps, settings_.rk4_step, kMaxRk4StepsPerAdvance);
    error_ = buf;
    return Status::InvalidArgument;
  }
  const long n = std::max(1L, static_cast<long>(steps));
  const double h = span / static_cast<double>(n);
  const double t0 = t_;
  const double h_contact = stop_contact_step(model_);
  PlantOde ode{*this};
  for (long k = 0; k < n; ++k) {
    const double tk = (k == 0) ? t0 : t0 + static_cast<double>(k) * h;
    const double t_next = (k + 1 == n) ? t_end : t0 + static_cast<double>(k + 1) * h;
    Vec10 x = packed();
    // rho at x: the previous grid step's end computed it (actuator_positions).
    Vec4 rho;
    unsigned mode = actuator_positions(rho) == Status::Ok ? contact_mode_at(x, rho) : ~0u;
    bool rho_valid = mode != ~0u;
    double t = tk;
    Status s = located_rk4_step(ode, tk, t_next, h_contact, x, mode, rho, rho_valid, contact_events_, t);
    if (s != Status::Ok) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "the RK4 step from t = %.17g s could not be evaluated: %s", t,
                    status_name(s));
      error_ = buf;
      return s;
    }
    s = guard(x.head<8>(), t_next);  // every step ends within the limits, or is undone
    if (s != Status::Ok) return s;
    unpack(x);
    t_ = t_next;
    if (rho_valid) {  // what actuator_positions would compute at the new state
      rho_ = rho;
      rho_valid_ = true;
    }
  }
  return Status::Ok;
}

Status Plant::advance_cvode(double t_end, bool continuous) {
  if (!cvode_ready_) {  // set_solver after initialisation: created here
    const Status s = prepare_cvode();
    if (s != Status::Ok) return s;
    continuous = false;
  }
  if (!continuous || cvode_.needs_reset()) {
    const Status s = cvode_.reset(t_, packed());
    if (s != Status::Ok) return s;
  }
  Vec10 x = packed();
  rhs_status_ = Status::Ok;
  // The stops held between roots: those past at the start, then switched at each root.
  Vec4 rho;
  stops_ = (actuator_positions(rho) == Status::Ok ? contact_mode_at(x, rho) : ~0u) & 0xFFu;
  bool chattering = false;
  Status s = located_cvode_advance(cvode_, t_end, x, stops_, contact_events_, error_, chattering);
  if (s != Status::Ok) {
    cvode_.reset(t_, packed());
    return (rhs_status_ != Status::Ok && !chattering) ? rhs_status_ : s;
  }
  s = guard(x.head<8>(), t_end);  // the interval ends within the limits, or is undone
  if (s != Status::Ok) {
    cvode_.reset(t_, packed());
    return s;
  }
  unpack(x);
  t_ = t_end;
  return Status::Ok;
}

Status Plant::advance(double t_end, const InputSignal& inputs, bool continuous) {
  if (!initialized_) return Status::NotInitialized;
  if (!std::isfinite(t_end)) return Status::NonFinite;
  if (!(t_end > t_)) return t_end == t_ ? Status::Ok : Status::InvalidArgument;
  error_.clear();
  inputs_ = inputs;
  const double t_start = t_;
  const Status s = settings_.solver == Solver::Rk4 ? advance_rk4(t_end) : advance_cvode(t_end, continuous);
  inputs_ = InputSignal{};
  if (t_ != t_start) theta1_stale_ = true;
  return s;
}

const Vec4& Plant::theta1_ref() const {
  Vec16 q;
  if (theta1_stale_ && closed_form_position(model_, y_.head<4>(), q) == Status::Ok) follow_theta1(q);
  return theta1_.ref;
}

void Plant::follow_theta1(const Vec16& q) const {
  theta1_.follow(q);
  theta1_stale_ = false;
}

Status Plant::mechanism(const InputSignal& inputs, MechanismState& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  Vec8 ydot;
  const Status s = state_derivative(model_, settings_.formulation, y_, generalized_forces(model_, F, tau, we),
                                    ydot, &out);
  if (s != Status::Ok) return s;
  theta1_ref();  // brought up to date
  theta1_.unwrap(out.q);
  return Status::Ok;
}

Status Plant::coordinates(Vec16& q, Vec16& qd) const {
  if (!initialized_) return Status::NotInitialized;
  const Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  if (theta1_stale_) follow_theta1(q);  // the closed form theta1_ref() would evaluate again
  theta1_.unwrap(q);
  return Status::Ok;
}

Status Plant::machine_outputs(const InputSignal& inputs, MachineOutputs& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec16 q, qd;
  Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  const Params& p = model_.p;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    out.rho[i] = q[o];
    out.rhod[i] = qd[o];
    out.stop_force[i] = stop_force(p, q[o], qd[o]);
    out.friction_force[i] = friction_force(p, qd[o]);
  }
  s = holding_forces(model_, q, we, out.F_hold);
  if (s != Status::Ok) return s;
  out.kinetic_energy = kinetic_energy(model_, q, qd);
  out.potential_energy = potential_energy(model_, q);
  out.actuator_work = energy_.actuator_work;
  out.dissipated_energy = energy_.dissipated;
  energy_rates(p, kStopsFromState, F + model_.drive_ratio * tau, we, y_.tail<4>(), out.rho, out.rhod,
               out.actuator_power, out.dissipation_rate);
  stop_indicators(p, out.rho, out.stop_indicators);
  return Status::Ok;
}

double Plant::constraint_residual() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::quiet_NaN();
  return constraints(model_, q).norm();
}

double Plant::jacobian_condition() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::infinity();
  return actuator_jacobian_condition(model_, q);
}

}  // namespace pkm
