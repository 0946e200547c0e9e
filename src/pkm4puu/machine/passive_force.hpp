// SPDX-License-Identifier: BSD-2-Clause
// The passive force on each actuated coordinate rho_i: friction plus end
// stop, its slopes and the power it dissipates. On rho_i (positive along +z)
// act F_i + (2 pi / p) tau_i (actuator force and motor torque through a
// lossless screw), F_fric,i (friction.hpp) and F_stop,i (end_stops.hpp); the
// rotor's reflected mass J (2 pi / p)^2 sits on rho_i's diagonal of M
// (lagrangian.hpp), as does the payload on the platform's.
//
// Energy: the stop's spring stores 1/2 k delta^2 (stop_potential); the rest
// of the stop force dissipates, at the rate (|F_stop| - k delta) delta_dot,
// which is d delta_dot^2 while the stop pushes and -k delta delta_dot >= 0
// while it is released (k delta + d delta_dot < 0 means delta_dot < 0).
#pragma once

#include <cmath>

#include "pkm4puu/machine/end_stops.hpp"
#include "pkm4puu/machine/friction.hpp"
#include "pkm4puu/base/types.hpp"

namespace pkm {

/// Friction plus end stop on rho (N): the joint's passive force.
inline double passive_joint_force(const Params& p, double rho, double rhod) {
  return friction_force(p, rhod) + stop_force(p, rho, rhod);
}
inline double passive_joint_force(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  return friction_force(p, rhod) + stop_contact(p, leg, stops, rho, rhod).force;
}

/// d/d(rho, rhod) of passive_joint_force (the friction's tanh is smooth;
/// a stop contributes (-k, -d) while it pushes and nothing otherwise: its
/// kinks at contact and release take the side the force is evaluated on).
struct PassiveSlopes { double drho = 0, drhod = 0; };
inline PassiveSlopes passive_joint_force_slopes(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  PassiveSlopes s;
  s.drhod = friction_slope(p, rhod);
  if (stop_contact(p, leg, stops, rho, rhod).force != 0.0) {
    s.drho = -p.stop_stiffness;
    s.drhod -= p.stop_damping;
  }
  return s;
}

/// Power dissipated in joint i (W, >= 0): friction plus the stop's damping
/// (header comment).
inline double dissipated_power(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  const StopContact c = stop_contact(p, leg, stops, rho, rhod);
  return -friction_force(p, rhod) * rhod + (-c.side * c.force - p.stop_stiffness * c.depth) * c.rate;
}

/// d/d(rho, rhod) of dissipated_power. With s = side (d depth/drho =
/// d rate/drhod = s): friction -(F_fric' rhod + F_fric); a pushing stop
/// (d rate^2) 2 d rate s on rhod; a released one (-k depth rate) -k s rate
/// on rho and -k depth s on rhod.
inline PassiveSlopes dissipated_power_slopes(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  PassiveSlopes s;
  s.drhod = -(friction_slope(p, rhod) * rhod + friction_force(p, rhod));
  const StopContact c = stop_contact(p, leg, stops, rho, rhod);
  if (c.force != 0.0) {
    s.drhod += 2.0 * p.stop_damping * c.rate * c.side;
  } else if (c.side != 0) {
    s.drho -= p.stop_stiffness * c.side * c.rate;
    s.drhod -= p.stop_stiffness * c.depth * c.side;
  }
  return s;
}

/// The energy audit's integrands: the power of the actuator forces plus the
/// screws' (Fa) and of the external wrench, and the power dissipated by
/// friction and the end stops `stops`.
inline void energy_rates(const Params& p, unsigned stops, const Vec4& Fa, const Wrench& we, const Pose& pose_rate,
                         const Vec4& rho, const Vec4& rhod, double& power, double& dissipation) {
  power = Fa.dot(rhod) + we.dot(pose_rate);
  dissipation = 0.0;
  for (int i = 0; i < kLegs; ++i) dissipation += dissipated_power(p, i, stops, rho[i], rhod[i]);
}

}  // namespace pkm
