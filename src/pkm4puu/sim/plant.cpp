// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/plant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/parameters.hpp"

namespace pkm {

Plant::Plant(const Model& model) : model_(model) {}

Status Plant::set_solver(const SolverSettings& s, std::string* error) {
  const std::string why = validate(s);
  if (!why.empty()) {
    if (error) *error = why;
    return Status::InvalidArgument;
  }
  const std::string unstable = fixed_step_refusal(model_, s);
  if (!unstable.empty()) {
    if (error) *error = unstable;
    return Status::InvalidArgument;
  }
  settings_ = s;
  cvode_ready_ = false;  // re-created on the next CVODE advance
  return Status::Ok;
}

Status Plant::retune(const Params& p) {
  Model next;
  std::string why;
  if (make_model(p, next, &why) != Status::Ok) {
    error_ = why;
    return Status::InvalidParameter;
  }
  const Configuration now{model_.p}, then{p};
  for (const Parameter& row : kParameters) {
    if (row.target != ParameterTarget::Model || row.variability == ParameterVariability::Tunable) continue;
    if (row.get(now) != row.get(then)) {
      error_ = std::string("parameter ") + row.name + " is not tunable: a change of it needs a new run";
      return Status::InvalidArgument;
    }
  }
  if (initialized_) {
    settle_energy();  // ROS2's balance, at the energy it refers to
    double before = 0.0, after = 0.0;
    Status s = mechanical_energy(y_, before);
    if (s != Status::Ok) return s;
    const Model old = model_;
    model_ = next;
    s = mechanical_energy(y_, after);
    if (s != Status::Ok) {
      model_ = old;
      return s;
    }
    // The grasp's (or release's) work: the audit stays constant; ROS2's
    // energy balance starts again from here.
    set_energy_integrals({energy_.actuator_work + (after - before), energy_.dissipated});
    if (cvode_ready_) cvode_.reset(t_, packed());
  } else {
    model_ = next;
  }
  error_.clear();
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
  Vec4 rho, rhod;
  s = pkm::actuator_positions(model_, pose, rho);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) rhod[i] = qd[leg_offset(i)];
  s = prepare_cvode();
  if (s != Status::Ok) return s;
  y_ = y;
  rho_valid_ = false;
  stops_ = stops_after_event(model_.p, rho, rhod, 0u);
  t_ = t0;
  energy_ = EnergyIntegrals{};
  memory_ = SolverMemory{};
  for (int i = 0; i < kLegs; ++i) theta1_.ref[i] = q[leg_offset(i) + 1];
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

PlantSnapshot Plant::snapshot() const {
  PlantSnapshot s;
  s.t = t_;
  s.y = y_;
  s.theta1_ref = theta1_ref();
  s.energy = energy_;
  s.stops = stops_;
  s.memory = memory_;
  return s;
}

Status Plant::restore(const PlantSnapshot& snap, bool settled) {
  const unsigned stops = snap.stops;
  const unsigned legs_held = (stops | (stops >> kLegs)) & ((1u << kLegs) - 1u);
  if (stops != kStopsFromState &&
      ((stops & ~kContactModeBits) != 0u || (stops & (stops >> kLegs) & ((1u << kLegs) - 1u)) != 0u ||
       ((stops >> (2 * kLegs)) & ~legs_held) != 0u)) {
    char buf[140];
    std::snprintf(buf, sizeof buf,
                  "the contact mode %#x names no stop, both stops of one leg or the clamp of a stop not held", stops);
    error_ = buf;
    return Status::InvalidArgument;
  }
  if (!std::isfinite(snap.t) || !snap.y.allFinite() || !snap.theta1_ref.allFinite() ||
      !std::isfinite(snap.energy.actuator_work) || !std::isfinite(snap.energy.dissipated)) {
    error_ = "the time, state, theta1 references or energy integrals are not finite";
    return Status::NonFinite;
  }
  const std::string memory_fault = solver_memory_fault(snap.memory);
  if (!memory_fault.empty()) {
    error_ = "the integrators' memory is none a run can have: " + memory_fault;
    return Status::InvalidArgument;
  }
  Status s = guard(snap.y, snap.t);
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = expand_state(model_, snap.y, q, qd);
  if (s != Status::Ok) return s;
  // theta1 is continuous, never wrapped, but cannot wind: the references
  // are the pose's closed-form angles up to whole turns, within a few turns.
  for (int i = 0; i < kLegs; ++i) {
    const double th1 = q[leg_offset(i) + 1];
    const double ref = snap.theta1_ref[i];
    const bool near = std::fabs(unwrap_near(th1, ref) - ref) <= 1e-9;
    if (!(std::fabs(ref) <= kMaxTheta1) || !near) {
      char buf[240];
      std::snprintf(buf, sizeof buf,
                    "the theta1 reference %.17g rad of leg %d is not the pose's theta1 = %.17g rad modulo 2 pi "
                    "(within %g rad)",
                    ref, i + 1, th1, kMaxTheta1);
      error_ = buf;
      return Status::InvalidArgument;
    }
  }
  Vec4 rho, rhod;
  for (int i = 0; i < kLegs; ++i) {
    rho[i] = q[leg_offset(i)];
    rhod[i] = qd[leg_offset(i)];
  }
  const unsigned mode = stops != kStopsFromState ? stops : stops_after_event(model_.p, rho, rhod, 0u);
  if (settled && stops_after_event(model_.p, rho, rhod, mode) != mode) {
    error_ = describe_unsettled_mode(model_.p, rho, rhod, mode);
    return Status::InvalidArgument;
  }
  const Status prepared = prepare_cvode();
  if (prepared != Status::Ok) return prepared;
  t_ = snap.t;
  y_ = snap.y;
  rho_valid_ = false;
  stops_ = mode;
  energy_ = snap.energy;
  memory_ = snap.memory;
  theta1_.ref = snap.theta1_ref;
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, packed());
  initialized_ = true;
  return Status::Ok;
}

Status Plant::set_state(const Vec8& y) {
  if (!initialized_) return Status::NotInitialized;
  if (!y.allFinite()) return Status::NonFinite;
  settle_energy();
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
  return machine_rates(inputs, t_, x, stops_, xdot);
}

Status Plant::update_stops(unsigned& switched) {
  switched = 0;
  if (!initialized_) return Status::NotInitialized;
  Vec4 rho, rhod;
  const Status s = joint_motion(y_, rho, rhod);
  if (s != Status::Ok) return s;
  const unsigned now = stops_after_event(model_.p, rho, rhod, stops_);
  switched = now ^ stops_;
  stops_ = now;
  return Status::Ok;
}

Status Plant::joint_motion(const Vec8& y, Vec4& rho, Vec4& rhod) const {
  Vec16 q, qd;
  const Status s = expand_state(model_, y, q, qd);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) {
    rho[i] = q[leg_offset(i)];
    rhod[i] = qd[leg_offset(i)];
  }
  return Status::Ok;
}

Status Plant::contact_indicators(double z[kContactIndicators]) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 rho, rhod;
  const Status s = joint_motion(y_, rho, rhod);
  if (s == Status::Ok) pkm::contact_indicators(model_.p, rho, rhod, stops_, z);
  return s;
}

void Plant::settle_energy() const {
  SolverMemory& m = memory_;
  if (!m.balance_pending) return;
  double e = 0.0;
  if (mechanical_energy(y_, e) != Status::Ok) return;  // y_ is always assembled: not reached
  energy_.dissipated = m.balance_dissipated + (energy_.actuator_work - m.balance_work) - (e - m.balance_mech);
  m.balance_pending = 0;
}

Vec10 Plant::packed(bool settle) const {
  if (settle) settle_energy();
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

const Vec4& Plant::theta1_ref() const {
  Vec16 q;
  if (theta1_stale_ && closed_form_position(model_, y_.head<4>(), q) == Status::Ok) follow_theta1(q);
  return theta1_.ref;
}

void Plant::follow_theta1(const Vec16& q) const {
  theta1_.follow(q);
  theta1_stale_ = false;
}

}  // namespace pkm
