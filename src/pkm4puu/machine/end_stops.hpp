// SPDX-License-Identifier: BSD-2-Clause
// The sliders' compliant end stops, in one place: the force law, the
// contact mode that the integrators hold between located events, and the
// event indicators that locate its changes.
//
//   below rho_min by delta = rho_min - rho_i > 0:  F_stop,i = +max(0, k delta + d delta_dot)
//   above rho_max by delta = rho_i - rho_max > 0:  F_stop,i = -max(0, k delta + d delta_dot)
#pragma once

#include <cmath>

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// One joint against its end stops.
struct StopContact {
  double depth = 0;   // delta >= 0, m (0: within the travel)
  double rate = 0;    // delta_dot, m/s (0 when depth is 0)
  double force = 0;   // F_stop on rho, signed along +z, N
  int side = 0;       // -1: the lower stop (depth = rho_min - rho), +1: the upper, 0: none
};

inline StopContact stop_contact(const Params& p, double rho, double rhod) {
  StopContact c;
  if (rho < p.rho_min) {
    c.depth = p.rho_min - rho;
    c.rate = -rhod;
    c.force = std::fmax(0.0, p.stop_stiffness * c.depth + p.stop_damping * c.rate);
    c.side = -1;
  } else if (rho > p.rho_max) {
    c.depth = rho - p.rho_max;
    c.rate = rhod;
    c.force = -std::fmax(0.0, p.stop_stiffness * c.depth + p.stop_damping * c.rate);
    c.side = 1;
  }
  return c;
}

/// F_stop on rho (N, signed along +z).
inline double stop_force(const Params& p, double rho, double rhod) { return stop_contact(p, rho, rhod).force; }

/// The contact mode: which stops act, held fixed between located events by
/// the integrators (bit i: leg i's lower stop, bit 4 + i: its upper stop),
/// so that the state derivative is smooth between events (up to the
/// release kink) and the rounding of a located crossing cannot switch a
/// stop on or off again. kStopsFromState: each stop acts when its joint is
/// past it (the plain state function, for Model Exchange and the outputs).
constexpr unsigned kStopsFromState = ~0u;

/// The same as stop_contact with the stops held: a held stop acts with
/// the signed depth (slightly negative just before the located crossing),
/// a stop not held does not act.
inline StopContact stop_contact(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  if (stops == kStopsFromState) return stop_contact(p, rho, rhod);
  StopContact c;
  if (stops & (1u << leg)) {
    c.depth = p.rho_min - rho;
    c.rate = -rhod;
    c.force = std::fmax(0.0, p.stop_stiffness * c.depth + p.stop_damping * c.rate);
    c.side = -1;
  } else if (stops & (1u << (4 + leg))) {
    c.depth = rho - p.rho_max;
    c.rate = rhod;
    c.force = -std::fmax(0.0, p.stop_stiffness * c.depth + p.stop_damping * c.rate);
    c.side = 1;
  }
  return c;
}

/// The stops the joints are past at these actuator positions, as a contact
/// mode (bit i: rho_i < rho_min, bit 4 + i: rho_i > rho_max).
inline unsigned stops_passed(const Params& p, const Vec4& rho) {
  unsigned mask = 0;
  for (int i = 0; i < kLegs; ++i) {
    if (rho[i] < p.rho_min) mask |= 1u << i;
    if (rho[i] > p.rho_max) mask |= 1u << (kLegs + i);
  }
  return mask;
}

/// Energy stored in the stop's spring, 1/2 k delta^2 (J).
inline double stop_potential(const Params& p, double rho) {
  const double d = rho < p.rho_min ? p.rho_min - rho : (rho > p.rho_max ? rho - p.rho_max : 0.0);
  return 0.5 * p.stop_stiffness * d * d;
}

/// Number of end-stop event indicators: rho_i - rho_min (i = 0..3), then
/// rho_max - rho_i (i = 0..3). Each is positive within the travel; indicator
/// k falling through zero switches bit k of the contact mode on.
constexpr int kStopIndicators = 2 * kLegs;

/// The indicators from the actuator positions.
inline void stop_indicators(const Params& p, const Vec4& rho, double g[kStopIndicators]) {
  for (int i = 0; i < kLegs; ++i) {
    g[i] = rho[i] - p.rho_min;
    g[kLegs + i] = p.rho_max - rho[i];
  }
}

/// The indicators at a platform pose (any state: they depend on the pose only).
Status stop_indicators(const Model& m, const Pose& pose, double g[kStopIndicators]);

/// The contact mode after located crossings: dirs[k] < 0 where indicator k
/// fell through zero (its stop now acts), > 0 where it rose (released).
inline unsigned stops_after_crossings(unsigned stops, const int dirs[kStopIndicators]) {
  for (int k = 0; k < kStopIndicators; ++k) {
    if (dirs[k] < 0) stops |= 1u << k;
    if (dirs[k] > 0) stops &= ~(1u << k);
  }
  return stops;
}

/// The time scale of a contact (s): a tenth of the inverse of the fastest
/// rate a stop can excite, its spring and damper against the least mass
/// that can sit behind rho_i (the slider with its rotor; the rest of the
/// mechanism only adds mass). A fixed-step integrator that substeps by it
/// keeps RK4's error per step near (0.1)^5 / 120 ~ 1e-7 of the contact's
/// motion. +inf without stiffness and damping.
double stop_contact_step(const Model& m);

}  // namespace pkm
