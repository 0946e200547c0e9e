// SPDX-License-Identifier: BSD-2-Clause
// The Plant's stepping: advance() with RK4, ROS2 or CVODE across the end
// stops' switches (integrators/located_*.hpp), each step checked by the
// guard, the fixed-step solvers within their work budget, and the energy
// audit checked where energy_tolerance asks.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pkm4puu/integrators/located_cvode.hpp"
#include "pkm4puu/integrators/located_rk4.hpp"
#include "pkm4puu/integrators/located_rosenbrock.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace pkm {

/// What the fixed-step solvers integrate: the plant's derivative under the
/// held stops, its Jacobian and ROS2's error measure (ROS2), and its contact
/// mode.
struct PlantOde {
  Plant& plant;
  // ROS2's speed scale (m/s): the largest speed at the advance's start and
  // its accepted steps (kRosenbrockTolerance, fixed_step_stability.hpp),
  // and the grid step (s) its floor is per.
  double speed = 0;
  double grid_step = 0;
  Status rates(double t, const Vec10& x, Vec10& xdot) { return plant.derivative(t, x, xdot); }
  /// The inputs at one instant.
  struct Inputs {
    Vec4 F, tau;
    Wrench we;
  };
  /// The pose and velocity rates ydot and their Jacobians A = dydot/dy and
  /// B = dydot/du (the leg-partitioned terms, the machine included; one
  /// evaluation gives all) at (t, x) under the held stops and the inputs at
  /// t, which `u` receives: the analytic Jacobian of ROS2 and of CVODE's
  /// BDF, counted as one evaluation. NonFinite: an input is not finite;
  /// SolverFailure: t or the state is not; Unreachable, Singular: a state
  /// off the workspace.
  static Status derivative_jacobians(Plant& plant, double t, const Vec10& x, Inputs& u, Vec8& ydot, Mat8& A,
                                     Mat8x12& B, JointJacobians* joints = nullptr) {
    ++plant.rhs_count_;
    if (!std::isfinite(t)) return Status::SolverFailure;
    read_inputs(plant.inputs_, t, u.F, u.we, u.tau);
    if (!u.F.allFinite() || !u.we.allFinite() || !u.tau.allFinite()) return Status::NonFinite;
    const Status s =
        state_derivative_jacobians(plant.model_, x.head<8>(), u.F, u.tau, u.we, plant.stops_, ydot, A, B, joints);
    return s == Status::NonFinite ? Status::SolverFailure : s;
  }
  /// The rates at (t, x) with derivative_jacobians' A and their time
  /// derivative through the inputs, B (u(t + h) - u(t)) / h (exact for the
  /// FMUs' linear inputs). The dissipation rate is left 0: ROS2's dissipated
  /// energy is the audit's balance (Plant::rosenbrock_dissipation).
  Status jacobian(double t, const Vec10& x, double h, Vec10& xdot, Mat8& A, Vec8& f_t) {
    Inputs u0, u1;
    Vec8 ydot;
    Mat8x12 B;
    JointJacobians joints;
    const Status s = derivative_jacobians(plant, t, x, u0, ydot, A, B, &joints);
    if (s != Status::Ok) return s;
    read_inputs(plant.inputs_, t + h, u1.F, u1.we, u1.tau);
    const Pose pd = x.segment<4>(4);
    xdot.head<8>() = ydot;
    xdot[8] = (u0.F + plant.model_.drive_ratio * u0.tau).dot(joints.J_rho * pd) + u0.we.dot(pd);  // as energy_rates
    xdot[9] = 0.0;
    Eigen::Matrix<double, kPlantInputs, 1> du;
    du << u1.F - u0.F, u1.we - u0.we, u1.tau - u0.tau;
    f_t = B * (du / h);
    return (xdot.allFinite() && A.allFinite() && f_t.allFinite()) ? Status::Ok : Status::SolverFailure;
  }
  /// |dx|, |dy|, |dz|, 0.1 m |dphi| at their largest (m/s).
  static double speed_of(const Vec10& x) {
    return std::max(x.segment<3>(4).cwiseAbs().maxCoeff(), kConditionLength * std::fabs(x[7]));
  }
  /// ROS2's error estimate of a step of h in units of its tolerance: each
  /// velocity's (dphi times 0.1 m) against kRosenbrockTolerance times the
  /// speed scale plus the floor (kRosenbrockSpeedFloor per grid step, at
  /// least kRosenbrockStepFloor); an accepted step's speed joins the scale.
  double error_norm(const Vec10& error, const Vec10& y0, const Vec10& y1, double h) {
    const double v = std::max(speed, std::max(speed_of(y0), speed_of(y1)));
    Vec10 e = error;
    e[7] *= kConditionLength;
    const double floor = std::max(kRosenbrockStepFloor, kRosenbrockSpeedFloor * std::min(1.0, h / grid_step));
    const double norm = e.segment<4>(4).cwiseAbs().maxCoeff() / (kRosenbrockTolerance * v + floor);
    if (norm <= 1.0) speed = v;
    return norm;
  }
  void hold(unsigned stops) { plant.stops_ = stops; }
  unsigned mode(const Vec10& x, Vec4& rho) const { return plant.contact_mode(x, rho); }
};

Status Plant::prepare_cvode() {
  if (settings_.solver != Solver::Cvode || cvode_ready_) return Status::Ok;
  // The method, the tolerances and the smallest step for this machine
  // (fixed_step_stability.hpp), BDF with the analytic Jacobian.
  const Status s = cvode_.init(cvode_method_for(model_, settings_), settings_.rtol, cvode_atol(model_, settings_),
                               &Plant::cvode_rhs, this, kContactIndicators, &Plant::cvode_roots,
                               &Plant::cvode_jacobian, cvode_min_step(model_));
  if (s != Status::Ok) {
    error_ = "CVODE could not be set up: " + cvode_.last_error();
    return s == Status::InvalidArgument ? s : Status::SolverFailure;
  }
  cvode_ready_ = true;
  return Status::Ok;
}

unsigned Plant::contact_mode(const Vec10& x, Vec4& rho) const {
  if (pkm::actuator_positions(model_, x.head<4>(), rho) != Status::Ok) return ~0u;
  return contact_mode_at(x, rho);
}

unsigned Plant::contact_mode_at(const Vec10& x, const Vec4& rho) const {
  // The stops first (rho only): the joint rates matter only to a held stop's clamp.
  const Vec4 at_rest = Vec4::Zero();
  if ((stops_after_event(model_.p, rho, at_rest, stops_) & ((1u << kStopIndicators) - 1u)) == 0u) return 0u;
  Vec4 rho_x, rhod;
  if (joint_motion(x.head<8>(), rho_x, rhod) != Status::Ok) return ~0u;
  return stops_after_event(model_.p, rho, rhod, stops_);
}

int Plant::cvode_roots(double t, const Vec10& x, double* g, void* self) {
  (void)t;
  const auto* me = static_cast<const Plant*>(self);
  Vec4 rho, rhod = Vec4::Zero();
  // With no stop held the clamps' indicators do not depend on the rates:
  // the actuator positions alone (the legs' lanes, the same bits as
  // joint_motion's rho) save the legs' velocities at every root evaluation.
  const bool held = (me->stops_ & ((1u << kStopIndicators) - 1u)) != 0u;
  const Status s =
      held ? me->joint_motion(x.head<8>(), rho, rhod) : pkm::actuator_positions(me->model_, x.head<4>(), rho);
  if (s == Status::Ok) {
    pkm::contact_indicators(me->model_.p, rho, rhod, me->stops_, g);
  } else {
    for (int k = 0; k < kContactIndicators; ++k) g[k] = 1.0;  // off the workspace: the rhs reports it
  }
  return 0;
}

int Plant::cvode_rhs(double t, const Vec10& y, Vec10& ydot, void* self) {
  auto* me = static_cast<Plant*>(self);
  if (me->cvode_capped()) return -1;
  const Status s = me->derivative(t, y, ydot);
  me->rhs_status_ = s;
  // A trial state off the workspace (or not finite) may be CVODE's
  // overshoot: let it retry with a smaller step (recoverable); non-finite
  // inputs abort.
  if (s == Status::Ok) return 0;
  return (s == Status::Unreachable || s == Status::Singular || s == Status::SolverFailure) ? 1 : -1;
}

int Plant::cvode_jacobian(double t, const Vec10& x, Mat10& J, void* self) {
  auto* me = static_cast<Plant*>(self);
  if (me->cvode_capped()) return -1;
  PlantOde::Inputs u;
  Vec8 ydot;
  Mat8 A;
  Mat8x12 B;
  if (PlantOde::derivative_jacobians(*me, t, x, u, ydot, A, B) != Status::Ok)
    return 1;  // a trial state off the workspace: CVODE retries with a smaller step
  // The energy integrals do not act back on the motion: their rows left 0,
  // the Newton iteration converges on them with the motion.
  J.setZero();
  J.topLeftCorner<8, 8>() = A;
  return 0;
}

bool Plant::cvode_capped() {
  if (rhs_count_ - cvode_call_start_ < static_cast<long>(kMaxCvodeEvaluationsPerCall)) return false;
  cvode_work_capped_ = true;
  return true;
}

Status Plant::advance_fixed(double t_end) {
  const double span = t_end - t_;
  const double steps = rk4_steps_for(span, settings_.rk4_step);  // within the cap: advance_refusal
  const long n = std::max(1L, static_cast<long>(steps));
  const double h = span / static_cast<double>(n);
  const double t0 = t_;
  const bool rosenbrock = settings_.solver == Solver::Rosenbrock;
  const SubSteps sub = fixed_sub_steps(model_, settings_.solver);
  const InnerSteps inner{sub.free, sub.contact};
  PlantOde ode{*this};
  // ROS2's error control, within this advance: its first step is the grid
  // step (the estimate shortens it where the motion needs it), and after a
  // switch of the contact mode the stiffness bound's h |lambda| = 0.1.
  StepControl control;
  control.on = rosenbrock;
  control.first_free = sub.first_free;
  control.first_contact = sub.first_contact;
  ode.speed = PlantOde::speed_of(packed(false));
  ode.grid_step = h;
  // One budget for the whole advance: work_budget inner steps per grid
  // step, at most kMaxInnerStepsPerCall.
  WorkBudget budget;
  budget.limit = static_cast<long>(std::min(settings_.work_budget * static_cast<double>(n), kMaxInnerStepsPerCall));
  // ROS2's stage rates do not resolve the power dissipated in a transient it
  // steps over (a stiff stop's damper), so its dissipated energy is the
  // audit's balance: brought up to date when read (settle_energy), or at
  // every grid step where energy_tolerance checks it.
  const bool balance_each_step = rosenbrock && settings_.energy_tolerance > 0.0;
  double e_mech = 0.0;
  if (balance_each_step) {
    settle_energy();
    const Status s = mechanical_energy(y_, e_mech);
    if (s != Status::Ok) return s;
  } else if (rosenbrock && !memory_.balance_pending) {
    const Status s = mechanical_energy(y_, memory_.balance_mech);
    if (s != Status::Ok) return s;
    memory_.balance_work = energy_.actuator_work;
    memory_.balance_dissipated = energy_.dissipated;
  }
  for (long k = 0; k < n; ++k) {
    const double tk = (k == 0) ? t0 : t0 + static_cast<double>(k) * h;
    const double t_next = (k + 1 == n) ? t_end : t0 + static_cast<double>(k + 1) * h;
    const unsigned stops_start = stops_;  // kept with the state if the step is undone
    // Stop as soon as the budget cannot suffice: every grid step after this
    // one takes one inner step at least.
    budget.reserve = n - k - 1;
    Vec10 x = packed(!rosenbrock);
    // rho at x: the previous grid step's end computed it (actuator_positions).
    Vec4 rho;
    unsigned mode = actuator_positions(rho) == Status::Ok ? contact_mode_at(x, rho) : ~0u;
    bool rho_valid = mode != ~0u;
    double t = tk;
    Status s =
        rosenbrock ? located_rosenbrock_step(ode, tk, t_next, inner, control, x, mode, rho, rho_valid, contact_events_,
                                             t, budget, kRosenbrockFilterFraction * h)
                   : located_rk4_step(ode, tk, t_next, inner, x, mode, rho, rho_valid, contact_events_, t, budget);
    if (s != Status::Ok) {
      if (budget.exhausted) {
        error_ = work_budget_message(model_, settings_, t, budget, n);
      } else {
        char buf[160];
        std::snprintf(buf, sizeof buf, "the %s step from t = %.17g s could not be evaluated: %s",
                      rosenbrock ? "Rosenbrock" : "RK4", t, status_name(s));
        error_ = buf;
      }
      stops_ = stops_start;
      return s;
    }
    s = guard(x.head<8>(), t_next);  // every step ends within the limits, or is undone
    if (s == Status::Ok && balance_each_step) s = rosenbrock_dissipation(x, e_mech, tk, t_next);
    if (s != Status::Ok) {
      stops_ = stops_start;
      return s;
    }
    if (rosenbrock && !balance_each_step) {
      x[9] = energy_.dissipated;  // the balance's reference, not this step's
      memory_.balance_pending = 1;
    }
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
  cvode_call_start_ = rhs_count_;
  cvode_work_capped_ = false;
  // The stops held between roots: the contact mode, switched at each root.
  const unsigned stops_start = stops_;
  bool chattering = false;
  Status s = located_cvode_advance(cvode_, t_end, x, stops_, contact_events_, error_, chattering);
  if (s != Status::Ok) {
    if (cvode_work_capped_) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "CVODE evaluated the state derivative %.0f times in this call from t = %.17g s to %.17g s, the "
                    "most one call may take, before reaching its end: shorter communication steps, looser rtol or "
                    "atol, cvode_method = 1 (BDF) or solver = 2 (Rosenbrock)",
                    kMaxCvodeEvaluationsPerCall, t_, t_end);
      error_ = buf;
    }
    stops_ = stops_start;
    cvode_.reset(t_, packed());
    return (rhs_status_ != Status::Ok && !chattering && !cvode_work_capped_) ? rhs_status_ : s;
  }
  s = guard(x.head<8>(), t_end);  // the interval ends within the limits, or is undone
  if (s != Status::Ok) {
    stops_ = stops_start;
    cvode_.reset(t_, packed());
    return s;
  }
  unpack(x);
  t_ = t_end;
  return Status::Ok;
}

std::string Plant::advance_refusal(double span, const char* what) const {
  char buf[320] = "";
  const double steps = fixed_step(settings_.solver) ? rk4_steps_for(span, settings_.rk4_step) : 0.0;
  if (settings_.solver == Solver::Cvode && span < kMinCvodeSpan)
    std::snprintf(buf, sizeof buf, "%s of %.17g s is shorter than CVODE can start with (%.6g s, sqrt(DBL_MIN))", what,
                  span, kMinCvodeSpan);
  else if (!(steps <= kMaxInnerStepsPerCall))  // also NaN
    std::snprintf(buf, sizeof buf,
                  "%s of %.6g s needs %.3g fixed steps of rk4_step = %.6g s, more than the %.0f inner steps one call "
                  "may take: use a shorter one or a larger rk4_step",
                  what, span, steps, settings_.rk4_step, kMaxInnerStepsPerCall);
  return buf;
}

Status Plant::advance(double t_end, const InputSignal& inputs, bool continuous) {
  if (!initialized_) return Status::NotInitialized;
  if (!std::isfinite(t_end)) return Status::NonFinite;
  if (!(t_end > t_)) return t_end == t_ ? Status::Ok : Status::InvalidArgument;
  error_ = advance_refusal(t_end - t_, "an interval");
  if (!error_.empty()) return Status::InvalidArgument;
  inputs_ = inputs;
  const double t_start = t_;
  const Vec8 y_start = y_;
  const EnergyIntegrals e_start = energy_;
  const unsigned stops_start = stops_;
  const SolverMemory memory_start = memory_;
  double audit_start = 0.0;
  const bool audit = settings_.energy_tolerance > 0.0;
  if (audit) {
    const Status a = energy_audit(audit_start);
    if (a != Status::Ok) {
      inputs_ = InputSignal{};
      return a;
    }
  }
  Status s = fixed_step(settings_.solver) ? advance_fixed(t_end) : advance_cvode(t_end, continuous);
  if (s == Status::Ok && audit) {
    double audit_end = 0.0;
    s = energy_audit(audit_end);
    const double residual = audit_end - audit_start;
    if (s == Status::Ok && !(std::fabs(residual) <= settings_.energy_tolerance)) {
      char buf[480];
      std::snprintf(buf, sizeof buf,
                    "the energy audit from t = %.17g s to %.17g s is off by %.6g J (kinetic + potential - "
                    "actuator_work + dissipated_energy went from %.9g J to %.9g J), more than energy_tolerance = "
                    "%g J: the step is undone; a smaller rk4_step, solver = 2 (Rosenbrock) or solver = 0 (CVODE)",
                    t_start, t_end, residual, audit_start, audit_end, settings_.energy_tolerance);
      error_ = buf;
      s = Status::SolverFailure;
    }
    if (s != Status::Ok) {  // back to the call's start
      y_ = y_start;
      energy_ = e_start;
      stops_ = stops_start;
      t_ = t_start;
      rho_valid_ = false;
      memory_ = memory_start;
      if (cvode_ready_) cvode_.reset(t_, packed());
    }
  }
  inputs_ = InputSignal{};
  if (t_ != t_start) theta1_stale_ = true;
  return s;
}

Status Plant::mechanical_energy(const Vec8& y, double& e) const {
  Vec16 q, qd;
  const Status s = expand_state(model_, y, q, qd);
  if (s == Status::Ok) e = kinetic_energy(model_, q, qd) + potential_energy(model_, q);
  return s;
}

Status Plant::rosenbrock_dissipation(Vec10& x, double& e_mech, double t0, double t1) {
  double e1 = 0.0;
  const Status s = mechanical_energy(x.head<8>(), e1);
  if (s != Status::Ok) return s;
  // dissipated = work - change of kinetic + potential (the audit's balance).
  const double dissipated = (x[8] - energy_.actuator_work) - (e1 - e_mech);
  if (settings_.energy_tolerance > 0.0 && dissipated < -settings_.energy_tolerance) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "the Rosenbrock step from t = %.17g s to %.17g s gains %.6g J that the inputs did not supply "
                  "(kinetic + potential %.9g J -> %.9g J, actuator work %.6g J), more than energy_tolerance = %g J: "
                  "a smaller rk4_step or solver = 0 (CVODE)",
                  t0, t1, -dissipated, e_mech, e1, x[8] - energy_.actuator_work, settings_.energy_tolerance);
    error_ = buf;
    return Status::SolverFailure;
  }
  x[9] = energy_.dissipated + dissipated;
  e_mech = e1;
  return Status::Ok;
}

Status Plant::energy_audit(double& value) const {
  MachineOutputs mo;
  const Status s = machine_outputs(inputs_, mo);
  value = mo.kinetic_energy + mo.potential_energy - mo.actuator_work + mo.dissipated_energy;
  return s;
}

}  // namespace pkm
