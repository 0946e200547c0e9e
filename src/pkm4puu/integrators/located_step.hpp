// SPDX-License-Identifier: BSD-2-Clause
// One fixed grid step of any one-step method across the end stops'
// switches: split where the contact mode changes (located by bisection),
// sub-stepped where the stiff terms need it (fixed_step_stability.hpp) or
// where the method's error estimate asks (ROS2), every inner step counted
// against a work budget.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "pkm4puu/base/status.hpp"
#include "pkm4puu/base/types.hpp"
#include "pkm4puu/machine/end_stops.hpp"

namespace pkm {

/// The stop bits of a contact mode (end_stops.hpp): bits 0..7.
constexpr unsigned kStopBits = (1u << kStopIndicators) - 1u;

/// At most this many located switches per grid step (beyond, the step goes
/// on without locating: a chattering contact).
constexpr int kMaxSwitchesPerStep = 64;

/// The bisection's resolution in time near t (s).
inline double switch_time_tolerance(double t) {
  return 1e-12 + 8.0 * std::numeric_limits<double>::epsilon() * std::fabs(t);
}

/// Inner steps (grid steps, sub-steps, rejected steps, bisection trials)
/// allowed and taken in one advance; `exhausted` tells a step refused for
/// want of budget (then `in_contact`: whether a stop was held, and
/// `estimate`: the last error estimate, in units of its tolerance, of a
/// method that has one; 0 otherwise).
struct WorkBudget {
  long limit = std::numeric_limits<long>::max();
  long used = 0;
  long reserve = 0;  // kept for the grid steps after this one (one inner step each at least)
  bool exhausted = false;
  bool in_contact = false;
  double estimate = 0;
  double step = 0;  // the step (s) that estimate belongs to
};

/// The longest inner steps: out of contact (`free`) and while a stop is held
/// (RK4's stability bounds; +inf: none).
struct InnerSteps {
  double free = std::numeric_limits<double>::infinity();
  double contact = std::numeric_limits<double>::infinity();
};

/// The step-size control of a method with an error estimate: the step
/// function returns the estimate in units of its tolerance (accepted where
/// at most 1); a rejected step is retried shorter, an accepted one proposes
/// the next. The estimate of an embedded solution of order p is O(h^(p+1)).
/// `after_switch(mode)` is the first step to try after a switch into `mode`
/// (a new fast transient: ROS2 starts at h |lambda| = 0.1 on the stiffness
/// bound, fixed_step_stability.hpp) and at the start of the advance.
struct StepControl {
  bool on = false;  // off: the method has no estimate (RK4)
  double next = std::numeric_limits<double>::infinity();  // the next step to try (s)
  double first_free = std::numeric_limits<double>::infinity();     // after a switch out of contact
  double first_contact = std::numeric_limits<double>::infinity();  // after a switch into contact
};
/// The controller's factors: the usual safety 0.9 on the predicted step,
/// growth at most 5x and shrinking at least 0.1x per step (Hairer, Norsett
/// and Wanner, Solving ODEs I, II.4), and the exponent 1 / (p + 1) of the
/// one method with an estimate, ROS2 (its embedded solution of order p = 1).
constexpr double kStepSafety = 0.9, kStepGrowth = 5.0, kStepShrink = 0.1, kStepExponent = 0.5;

inline double step_factor(double estimate) {
  if (!(estimate > 0.0)) return kStepGrowth;  // also NaN: the caller rejects a NaN estimate first
  return std::clamp(kStepSafety * std::pow(estimate, -kStepExponent), kStepShrink, kStepGrowth);
}

/// The step from (t0, x) to t1 with `step(t, h, x, estimate)` (one step of
/// the method, x unchanged on failure; `estimate` its error estimate in
/// units of the tolerance, 0 without one). `sys` provides
///   void hold(unsigned stops)                           the stops held from now on,
///   unsigned mode(const Vec10& x, Vec4& rho)            the contact mode at x (end_stops.hpp's
///                                                       bits, the clamps' included; ~0u off the
///                                                       workspace) and the actuator positions.
/// `mode` and `rho` hold the contact mode and actuator positions at x on
/// entry and at the end on return (`rho_valid` false where unknown);
/// `switches` counts the located switches. `t` returns where the step got to
/// (t1 on success). On return the stops of the final mode are held (the
/// plant's contact mode from there on). Out of budget: SolverFailure with
/// budget.exhausted, x at t.
template <class System, class Stepper>
Status located_fixed_step(System& sys, Stepper&& step_fn, double t0, double t1, const InnerSteps& inner,
                          StepControl& control, Vec10& x, unsigned& mode, Vec4& rho, bool& rho_valid, long& switches,
                          double& t, WorkBudget& budget) {
  t = t0;
  int located = 0;
  Status s = Status::Ok;
  auto take = [&](double tt, double hh, Vec10& xx, double& estimate) {
    if (budget.used >= budget.limit - budget.reserve) {
      budget.exhausted = true;
      budget.in_contact = mode != 0;
      return Status::SolverFailure;
    }
    ++budget.used;
    estimate = 0.0;
    return step_fn(tt, hh, xx, estimate);
  };
  while (t < t1 && s == Status::Ok) {
    double step = t1 - t;
    bool to_end = true;
    const double limit = std::min(mode != 0 ? std::min(inner.free, inner.contact) : inner.free, control.next);
    if (step > limit) {
      step = limit;
      to_end = false;
    }
    sys.hold(mode & kContactModeBits);  // over the step and its re-steps
    Vec10 trial = x;
    double estimate = 0.0;
    s = take(t, step, trial, estimate);
    if (s != Status::Ok) break;
    if (control.on) {
      budget.estimate = estimate;
      budget.step = step;
      if (!(estimate <= 1.0)) {  // rejected (also NaN): again, shorter
        control.next = step * (std::isfinite(estimate) ? step_factor(estimate) : kStepShrink);
        continue;
      }
      // Accepted: the next step from this one's estimate; a step cut short
      // (by t1 or a bound) does not shrink a longer proposal that stands.
      const double proposed = step * step_factor(estimate);
      control.next = step < control.next ? std::max(proposed, control.next) : proposed;
    }
    Vec4 rho_trial;
    unsigned trial_mode = sys.mode(trial, rho_trial);
    bool rho_trial_valid = trial_mode != ~0u;
    if (trial_mode == ~0u) trial_mode = mode;  // off the workspace: the caller's guard reports it
    if (trial_mode != mode && located < kMaxSwitchesPerStep) {
      // The shortest step, re-stepped from t, after which the mode has
      // changed (shorter than the accepted step: its estimate is not asked).
      double lo = 0.0, hi = step;
      const double tol = switch_time_tolerance(t);
      while (hi - lo > tol && s == Status::Ok) {
        const double mid = 0.5 * (lo + hi);
        Vec10 xm = x;
        double ignored = 0.0;
        s = take(t, mid, xm, ignored);
        if (s != Status::Ok) break;
        Vec4 rho_m;
        const unsigned mm = sys.mode(xm, rho_m);
        if (mm == mode || mm == ~0u) {
          lo = mid;
        } else {
          hi = mid;
          trial = xm;
          trial_mode = mm;
          rho_trial = rho_m;
          rho_trial_valid = true;
        }
      }
      if (s != Status::Ok) break;
      if (hi < step) to_end = false;
      step = hi;
      ++located;
      ++switches;
    }
    if (trial_mode != mode && control.on)  // a new fast transient
      control.next = std::min(control.next, (trial_mode & kStopBits) != 0 ? control.first_contact : control.first_free);
    x = trial;
    mode = trial_mode;
    rho = rho_trial;
    rho_valid = rho_trial_valid;
    t = to_end ? t1 : t + step;
  }
  sys.hold(mode & kContactModeBits);
  return s;
}

}  // namespace pkm
