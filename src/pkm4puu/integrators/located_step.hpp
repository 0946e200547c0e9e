// SPDX-License-Identifier: BSD-2-Clause
// One fixed grid step of any one-step method across the end stops'
// switches: split where the contact mode changes (located by bisection) and
// sub-stepped where the stiff terms need it (fixed_step_stability.hpp), every
// inner step counted against a work budget.
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

/// Inner steps (grid steps, sub-steps, bisection trials) allowed and taken
/// in one advance; `exhausted` tells a step refused for want of budget
/// (then `in_contact`: whether a stop was held).
struct WorkBudget {
  long limit = std::numeric_limits<long>::max();
  long used = 0;
  bool exhausted = false;
  bool in_contact = false;
};

/// The longest inner steps: out of contact (`free`) and while a stop is held.
/// After a switch of the contact mode (and where `layer` is set by the
/// caller, at the start of a run) a new fast transient starts: with
/// `layer_free` / `layer_contact` finite the steps start that short and grow
/// by kLayerGrowth per step (`layer`, the current one; +inf: none), so that
/// the transient is resolved while it lasts at a logarithmic cost.
struct InnerSteps {
  double free = std::numeric_limits<double>::infinity();
  double contact = std::numeric_limits<double>::infinity();
  double layer_free = std::numeric_limits<double>::infinity();
  double layer_contact = std::numeric_limits<double>::infinity();
  double layer = std::numeric_limits<double>::infinity();
  // With `contact_from_system`, `contact` is the system's own at each switch
  // into a contact mode (sys.contact_step(t, x, mode): ROS2's ringing from
  // the Jacobian's eigenvalues there), else fixed.
  bool contact_from_system = false;
};
/// The layer's growth per step: the time since the switch is then about six
/// steps (1 + 1/1.2 + 1/1.2^2 + ...), so that a mode of rate lambda has
/// decayed by exp(-6 h lambda) where the step is h; the cost is
/// log(h_grid lambda / 0.1) / log(1.2) steps per switch, about 100 at the
/// stiffest declared stops (docs/solvers.md).
constexpr double kLayerGrowth = 1.2;

/// The step from (t0, x) to t1 with `step(t, h, x)` (one step of the method,
/// x unchanged on failure). `sys` provides
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
Status located_fixed_step(System& sys, Stepper&& step_fn, double t0, double t1, InnerSteps& inner, Vec10& x,
                          unsigned& mode, Vec4& rho, bool& rho_valid, long& switches, double& t, WorkBudget& budget) {
  t = t0;
  int located = 0;
  Status s = Status::Ok;
  auto take = [&](double tt, double hh, Vec10& xx) {
    if (budget.used >= budget.limit) {
      budget.exhausted = true;
      budget.in_contact = mode != 0;
      return Status::SolverFailure;
    }
    ++budget.used;
    return step_fn(tt, hh, xx);
  };
  while (t < t1 && s == Status::Ok) {
    double step = t1 - t;
    bool to_end = true;
    const double limit = std::min(mode != 0 ? std::min(inner.free, inner.contact) : inner.free, inner.layer);
    if (step > limit) {
      step = limit;
      to_end = false;
    }
    sys.hold(mode & kContactModeBits);  // over the step and its re-steps
    Vec10 trial = x;
    s = take(t, step, trial);
    if (s != Status::Ok) break;
    Vec4 rho_trial;
    unsigned trial_mode = sys.mode(trial, rho_trial);
    bool rho_trial_valid = trial_mode != ~0u;
    if (trial_mode == ~0u) trial_mode = mode;  // off the workspace: the caller's guard reports it
    if (trial_mode != mode && located < kMaxSwitchesPerStep) {
      // The shortest step, re-stepped from t, after which the mode has changed.
      double lo = 0.0, hi = step;
      const double tol = switch_time_tolerance(t);
      while (hi - lo > tol && s == Status::Ok) {
        const double mid = 0.5 * (lo + hi);
        Vec10 xm = x;
        s = take(t, mid, xm);
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
    if (trial_mode != mode) {
      inner.layer = trial_mode != 0 ? inner.layer_contact : inner.layer_free;  // a new transient
      if (inner.contact_from_system && (trial_mode & kStopBits) != 0) {
        sys.hold(trial_mode & kContactModeBits);
        inner.contact = sys.contact_step(t + step, trial);
      }
    } else if (step >= inner.layer) {
      inner.layer *= kLayerGrowth;
    }
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
