// SPDX-License-Identifier: BSD-2-Clause
// The sliders' compliant end stops, in one place: the force law, the
// contact mode that the integrators hold between located events, and the
// event indicators that locate its changes.
//
//   below rho_min by delta = rho_min - rho_i > 0:  F_stop,i = +max(0, k delta + d delta_dot)
//   above rho_max by delta = rho_i - rho_max > 0:  F_stop,i = -max(0, k delta + d delta_dot)
//
// In a simulation both branches are relations held in the contact mode:
// whether a stop is in contact (delta crossing 0) and, while it is, whether
// its spring and damper push (k delta + d delta_dot > 0) or would pull, the
// force then clamped at 0. Each held branch is a smooth law defined on both
// sides of its switch: k delta + d delta_dot with the signed delta, or 0.
#pragma once

#include <cmath>
#include <string>

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// One joint against its end stops.
struct StopContact {
  double depth = 0;   // delta >= 0, m (0: within the travel)
  double rate = 0;    // delta_dot, m/s (0 when depth is 0)
  double force = 0;   // F_stop on rho, signed along +z, N
  int side = 0;       // -1: the lower stop (depth = rho_min - rho), +1: the upper, 0: none
};

/// The contact mode: which stops act, held fixed between located events by
/// the integrators (bit i: leg i's lower stop, bit 4 + i: its upper stop,
/// bit 8 + i: leg i's held stop clamped, its spring and damper pulling),
/// so that the state derivative is smooth between events (up to the
/// release kink) and the rounding of a located crossing cannot switch a
/// stop on or off again. The Plant holds one such mode for Co-Simulation
/// and Model Exchange alike, switched only at located events and in Event
/// Mode (stops_after_event). The release kink, where k delta + d delta_dot
/// changes sign inside a contact, is a relation too (bit 8 + i): the force
/// is continuous there but its slope jumps, which a variable-step error
/// test steps across with an error of its own (measured: CVODE at rtol
/// 1e-10 misplaces the next impact by 2e-9 s, at 1e-12 by 2e-10 s, not
/// converging with the tolerance); located, the right-hand side is smooth
/// between events. kStopsFromState: each stop acts when its joint is past
/// it (the plain state function, for the analyses outside a simulation:
/// inverse dynamics, Jacobians of a pose).
constexpr unsigned kStopsFromState = ~0u;
/// The bits a contact mode may hold.
constexpr unsigned kContactModeBits = 0xFFFu;
/// Bit 8 + leg: the leg's held stop is clamped.
constexpr unsigned clamp_bit(int leg) { return 1u << (8 + leg); }

/// The plain state function, defined below through the held law.
inline StopContact stop_contact(const Params& p, double rho, double rhod);

/// The same as stop_contact with the contact mode held: a held stop acts
/// with the signed depth (slightly negative just before the located
/// crossing) by k delta + d delta_dot, or not at all while clamped (then
/// with whatever sign that has near the located switch); a stop not held
/// does not act.
inline StopContact stop_contact(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  if (stops == kStopsFromState) return stop_contact(p, rho, rhod);
  StopContact c;
  if (stops & (1u << leg)) {
    c.depth = p.rho_min - rho;
    c.rate = -rhod;
    c.side = -1;
  } else if (stops & (1u << (4 + leg))) {
    c.depth = rho - p.rho_max;
    c.rate = rhod;
    c.side = 1;
  } else {
    return c;
  }
  if (!(stops & clamp_bit(leg))) c.force = -c.side * (p.stop_stiffness * c.depth + p.stop_damping * c.rate);
  return c;
}

/// The plain state function (each stop acts where its joint is past it, the
/// force clamped at 0 where it would pull): the held law above, with the
/// contact mode the state itself implies, so the law is written once.
inline StopContact stop_contact(const Params& p, double rho, double rhod) {
  const unsigned passed = rho < p.rho_min ? 1u : (rho > p.rho_max ? 1u << kLegs : 0u);  // as leg 0
  StopContact c = stop_contact(p, 0, passed, rho, rhod);
  if (c.side * c.force > 0.0) c.force = 0.0;  // k delta + d delta_dot < 0: clamped
  return c;
}

/// F_stop on rho (N, signed along +z).
inline double stop_force(const Params& p, double rho, double rhod) { return stop_contact(p, rho, rhod).force; }

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
/// With the clamps' (one per leg, bit 8 + i): the contact mode's indicators.
constexpr int kContactIndicators = kStopIndicators + kLegs;

/// The indicators from the actuator positions.
inline void stop_indicators(const Params& p, const Vec4& rho, double g[kStopIndicators]) {
  for (int i = 0; i < kLegs; ++i) {
    g[i] = rho[i] - p.rho_min;
    g[kLegs + i] = p.rho_max - rho[i];
  }
}


/// The switches' hysteresis (m): indicator k reads g_k + h while stop k is
/// not held and g_k - h while it is (stop_indicators with a contact mode),
/// so a stop switches on where its joint has passed it by h and off where
/// the joint is h short of it, and no indicator is exactly zero after an
/// event (FMI 2.0.4 §3.2.2, FMI 3.0.2 §3.1.1: z_j != 0 on leaving Event
/// Mode): after a switch the indicator is g_k -+ h with |g_k -+ h| >= 2h.
/// 1 pm, four orders above the rounding of rho (~1e-16 m at this machine's
/// scale) so that the state at a located switch cannot read as the other
/// side once switched, and far below anything the model resolves (a stop
/// switched 1 pm late changes its force by k h = 1e-7 N at 1e5 N/m).
constexpr double kStopHysteresis = 1e-12;
/// The clamps' hysteresis (N): their indicator is k delta + d delta_dot + h_F
/// while the held stop pushes, - h_F while clamped. 1e-9 N, five orders above
/// the rounding of k delta + d delta_dot at this machine's forces (~1e-14 N).
constexpr double kClampHysteresis = 1e-9;

/// The indicators under the contact mode `stops` (with the hysteresis):
/// g_k + h where stop k is not held, g_k - h where it is held (so negative
/// in contact, as g_k); a zero crossing switches that stop (falling: on,
/// rising: off).
/// kStopsFromState: the plain g_k, no hysteresis.
inline void stop_indicators(const Params& p, const Vec4& rho, unsigned stops, double z[kStopIndicators]) {
  stop_indicators(p, rho, z);
  if (stops == kStopsFromState) return;
  for (int k = 0; k < kStopIndicators; ++k) z[k] += (stops & (1u << k)) ? -kStopHysteresis : kStopHysteresis;
}

/// The same at a platform pose (any velocity: they depend on the pose only).
Status stop_indicators(const Model& m, const Pose& pose, unsigned stops, double z[kStopIndicators]);

/// The clamps' indicators under the contact mode `stops` (kLegs values):
/// for a leg with a held stop, k delta + d delta_dot + h_F while it pushes,
/// - h_F while clamped (negative while clamped); 1.0 for a leg with none
/// (no switch to locate).
inline void clamp_indicators(const Params& p, const Vec4& rho, const Vec4& rhod, unsigned stops, double z[kLegs]) {
  for (int i = 0; i < kLegs; ++i) {
    const StopContact c = stop_contact(p, i, stops & ~clamp_bit(i), rho[i], rhod[i]);
    z[i] = c.side == 0 ? 1.0 : -c.side * c.force + ((stops & clamp_bit(i)) ? -kClampHysteresis : kClampHysteresis);
  }
}

/// All the contact mode's indicators: stop_indicators, then clamp_indicators.
inline void contact_indicators(const Params& p, const Vec4& rho, const Vec4& rhod, unsigned stops,
                               double z[kContactIndicators]) {
  stop_indicators(p, rho, stops, z);
  clamp_indicators(p, rho, rhod, stops, z + kStopIndicators);
}

/// The contact mode after an event at actuator positions rho and rates rhod
/// (the one rule for Event Mode and initialisation, from stops = 0): a bit
/// not set whose indicator (with the hysteresis) is <= 0 is set, a set one
/// whose indicator is >= 0 is cleared; the stops first, then the clamps of
/// the stops held (a stop switched on starts unclamped; a released one
/// takes its clamp along). The result is consistent with the state: every
/// indicator under it is nonzero and needs no further switch.
inline unsigned stops_after_event(const Params& p, const Vec4& rho, const Vec4& rhod, unsigned stops) {
  double z[kStopIndicators];
  stop_indicators(p, rho, stops, z);
  for (int k = 0; k < kStopIndicators; ++k) {
    const bool held = stops & (1u << k);
    if (!held && z[k] <= 0.0) stops |= 1u << k;
    if (held && z[k] >= 0.0) stops &= ~((1u << k) | clamp_bit(k % kLegs));
  }
  double c[kLegs];
  clamp_indicators(p, rho, rhod, stops, c);
  for (int i = 0; i < kLegs; ++i) {
    const bool clamped = stops & clamp_bit(i);
    if (!(stops & ((1u << i) | (1u << (kLegs + i))))) continue;
    if (!clamped && c[i] <= 0.0) stops |= clamp_bit(i);
    if (clamped && c[i] >= 0.0) stops &= ~clamp_bit(i);
  }
  return stops & kContactModeBits;
}

/// Why the contact mode `stops` is not the one the event rule keeps at rho
/// and rhod (stops_after_event(p, rho, rhod, stops) != stops): the first
/// stop or clamp it gets wrong, with the distances and forces that say so
/// (a state no run reaches: a held stop with its slider clear of it pulls).
std::string describe_unsettled_mode(const Params& p, const Vec4& rho, const Vec4& rhod, unsigned stops);

/// The contact mode after located crossings: dirs[k] < 0 where indicator k
/// (contact_indicators) fell through zero (its bit set), > 0 where it rose
/// (cleared; a released stop takes its clamp along).
inline unsigned stops_after_crossings(unsigned stops, const int dirs[kContactIndicators]) {
  for (int k = 0; k < kContactIndicators; ++k) {
    if (dirs[k] < 0) stops |= 1u << k;
    if (dirs[k] > 0) stops &= ~(1u << k);
  }
  for (int i = 0; i < kLegs; ++i)
    if (!(stops & ((1u << i) | (1u << (kLegs + i))))) stops &= ~clamp_bit(i);
  return stops;
}

}  // namespace pkm
