// SPDX-License-Identifier: BSD-2-Clause
// The Plant's stepping: advance() with RK4 or CVODE across the end stops'
// switches (integrators/located_*.hpp), each step checked by the guard.
#include <algorithm>
#include <cstdio>

#include "pkm4puu/integrators/located_cvode.hpp"
#include "pkm4puu/integrators/located_rk4.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace pkm {

/// What located_rk4_step integrates: the plant's derivative under the held
/// stops, and its contact mode.
struct PlantOde {
  Plant& plant;
  Status rates(double t, const Vec10& x, Vec10& xdot) { return plant.derivative(t, x, xdot); }
  void hold(unsigned stops) { plant.stops_ = stops; }
  unsigned mode(const Vec10& x, Vec4& rho) const { return plant.contact_mode(x, rho); }
};

Status Plant::prepare_cvode() {
  if (settings_.solver != Solver::Cvode || cvode_ready_) return Status::Ok;
  const Status s = cvode_.init(settings_.cvode_method, settings_.rtol, settings_.atol, &Plant::cvode_rhs, this,
                               kContactIndicators, &Plant::cvode_roots);
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
  const Status s = me->derivative(t, y, ydot);
  me->rhs_status_ = s;
  // A trial state off the workspace (or not finite) may be CVODE's
  // overshoot: let it retry with a smaller step (recoverable); non-finite
  // inputs abort.
  if (s == Status::Ok) return 0;
  return (s == Status::Unreachable || s == Status::Singular || s == Status::SolverFailure) ? 1 : -1;
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
    const unsigned stops_start = stops_;  // kept with the state if the step is undone
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
      stops_ = stops_start;
      return s;
    }
    s = guard(x.head<8>(), t_next);  // every step ends within the limits, or is undone
    if (s != Status::Ok) {
      stops_ = stops_start;
      return s;
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
  // The stops held between roots: the contact mode, switched at each root.
  const unsigned stops_start = stops_;
  bool chattering = false;
  Status s = located_cvode_advance(cvode_, t_end, x, stops_, contact_events_, error_, chattering);
  if (s != Status::Ok) {
    stops_ = stops_start;
    cvode_.reset(t_, packed());
    return (rhs_status_ != Status::Ok && !chattering) ? rhs_status_ : s;
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

}  // namespace pkm
