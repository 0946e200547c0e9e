#include "plant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "constraints.hpp"
#include "lagrangian.hpp"
#include "rk4.hpp"
#include "servo_kinematics.hpp"

namespace pkm {
namespace {

void eval_linear(void* user, double t, Vec4& F, Wrench& we) {
  const auto* in = static_cast<const LinearInputs*>(user);
  const double dt = t - in->t0;
  F = in->F0 + in->dF * dt;
  we = in->we0 + in->dwe * dt;
}

void read_inputs(const InputSignal& in, double t, Vec4& F, Wrench& we) {
  if (in.eval) {
    in.eval(in.user, t, F, we);
  } else {
    F.setZero();
    we.setZero();
  }
}

double unwrap_near(double angle, double ref) {
  constexpr double two_pi = 2.0 * kPi;
  return angle + two_pi * std::round((ref - angle) / two_pi);
}

}  // namespace

InputSignal LinearInputs::signal() { return {&eval_linear, this}; }

std::string validate(const SolverSettings& s) {
  char buf[160];
  if (s.solver != Solver::Cvode && s.solver != Solver::Rk4) return "solver must be 0 (CVODE) or 1 (RK4)";
  if (!(s.rk4_step > 0.0) || !std::isfinite(s.rk4_step)) {
    std::snprintf(buf, sizeof buf, "rk4_step = %.17g s must be positive and finite", s.rk4_step);
    return buf;
  }
  if (!(s.rtol > 0.0) || !(s.rtol < 1.0)) {
    std::snprintf(buf, sizeof buf, "rtol = %.17g must lie in (0, 1)", s.rtol);
    return buf;
  }
  if (!(s.atol > 0.0) || !std::isfinite(s.atol)) {
    std::snprintf(buf, sizeof buf, "atol = %.17g must be positive and finite", s.atol);
    return buf;
  }
  if (s.cvode_method != CvodeMethod::Adams && s.cvode_method != CvodeMethod::BDF)
    return "cvode_method must be 0 (Adams) or 1 (BDF)";
  if (s.formulation != Formulation::Augmented && s.formulation != Formulation::NullSpaceQR &&
      s.formulation != Formulation::LegPartitioned)
    return "formulation must be 0 (Eq. 12), 1 (Eq. 13, QR) or 2 (Eq. 13, leg-partitioned)";
  return validate(s.limits());
}

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
  y_ = y;
  t_ = t0;
  for (int i = 0; i < kLegs; ++i) theta1_ref_[i] = q[leg_offset(i) + 1];
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, y_);
  initialized_ = true;
  return Status::Ok;
}

Status Plant::restore(double t, const Vec8& y, const Vec4& theta1_ref) {
  if (!std::isfinite(t) || !y.allFinite() || !theta1_ref.allFinite()) return Status::NonFinite;
  Status s = guard(y, t);
  if (s != Status::Ok) return s;
  Vec16 q, qd;
  s = expand_state(model_, y, q, qd);
  if (s != Status::Ok) return s;
  t_ = t;
  y_ = y;
  theta1_ref_ = theta1_ref;
  theta1_stale_ = false;
  if (cvode_ready_) cvode_.reset(t_, y_);
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
  theta1_stale_ = true;
  return Status::Ok;
}

Status Plant::derivative_now(const InputSignal& inputs, Vec8& ydot) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 F;
  Wrench we;
  read_inputs(inputs, t_, F, we);
  return state_derivative(model_, settings_.formulation, y_, generalized_forces(F, we), ydot);
}

Status Plant::derivative(double t, const Vec8& y, Vec8& ydot) {
  Vec4 F;
  Wrench we;
  ++rhs_count_;
  // A non-finite trial time or state is the integrator's (a step size
  // computed from absurd accelerations), not the inputs': the step fails,
  // the state is kept.
  if (!std::isfinite(t)) return Status::SolverFailure;
  read_inputs(inputs_, t, F, we);
  if (!F.allFinite() || !we.allFinite()) return Status::NonFinite;  // the inputs' fault
  const Status s = state_derivative(model_, settings_.formulation, y, generalized_forces(F, we), ydot);
  return s == Status::NonFinite ? Status::SolverFailure : s;  // finite inputs: the trial state was not
}

int Plant::cvode_rhs(double t, const Vec8& y, Vec8& ydot, void* self) {
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
  GuardReport report;
  const Status s = check_configuration(model_, y.head<4>(), settings_.limits(), &report);
  if (s == Status::Ok) return s;
  char at[64];
  std::snprintf(at, sizeof at, "at t = %.17g s: ", t);
  error_ = at + describe_configuration_failure(model_, y.head<4>(), settings_.limits(), report);
  return s;
}

Status Plant::advance_rk4(double t_end) {
  const double span = t_end - t_;
  const double steps = std::ceil(span / settings_.rk4_step - 1e-9);
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
  auto f = [this](double t, const Vec8& y, Vec8& ydot) { return derivative(t, y, ydot); };
  const double t0 = t_;
  for (long k = 0; k < n; ++k) {
    const double tk = (k == 0) ? t0 : t0 + static_cast<double>(k) * h;
    const Vec8 before = y_;
    Status s = rk4_step(f, tk, h, y_);
    if (s != Status::Ok) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "the RK4 step from t = %.17g s could not be evaluated: %s", tk,
                    status_name(s));
      error_ = buf;
      return s;
    }
    const double t_next = (k + 1 == n) ? t_end : t0 + static_cast<double>(k + 1) * h;
    s = guard(y_, t_next);  // every step ends within the limits, or is undone
    if (s != Status::Ok) {
      y_ = before;
      return s;
    }
    t_ = t_next;
  }
  return Status::Ok;
}

Status Plant::advance_cvode(double t_end, bool continuous) {
  if (!cvode_ready_) {
    Status s = cvode_.init(settings_.cvode_method, settings_.rtol, settings_.atol, &Plant::cvode_rhs,
                           this);
    if (s != Status::Ok) {
      error_ = "CVODE could not be set up: " + cvode_.last_error();
      return s;
    }
    cvode_ready_ = true;
    continuous = false;
  }
  if (!continuous || cvode_.needs_reset()) {
    const Status s = cvode_.reset(t_, y_);
    if (s != Status::Ok) return s;
  }
  Vec8 y = y_;
  rhs_status_ = Status::Ok;
  Status s = cvode_.advance(t_end, y);
  if (s != Status::Ok) {
    error_ = cvode_.last_error();
    cvode_.reset(t_, y_);
    return rhs_status_ != Status::Ok ? rhs_status_ : s;
  }
  s = guard(y, t_end);  // the interval ends within the limits, or is undone
  if (s != Status::Ok) {
    cvode_.reset(t_, y_);
    return s;
  }
  y_ = y;
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
  if (theta1_stale_) update_theta1_ref();
  return theta1_ref_;
}

void Plant::update_theta1_ref() const {
  Vec16 q;
  if (closed_form_position(model_, y_.head<4>(), q) != Status::Ok) return;
  for (int i = 0; i < kLegs; ++i) theta1_ref_[i] = unwrap_near(q[leg_offset(i) + 1], theta1_ref_[i]);
  theta1_stale_ = false;
}

Status Plant::mechanism(const InputSignal& inputs, MechanismState& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 F;
  Wrench we;
  read_inputs(inputs, t_, F, we);
  Vec8 ydot;
  const Status s = state_derivative(model_, settings_.formulation, y_, generalized_forces(F, we), ydot, &out);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) {
    double& th1 = out.q[leg_offset(i) + 1];
    th1 = unwrap_near(th1, theta1_ref()[i]);
  }
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
