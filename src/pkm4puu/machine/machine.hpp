// The machine around the mechanism (MODEL_SPEC "The machine around the
// mechanism: drives, friction, end stops, payload"): the forces that act on
// each actuated coordinate rho_i besides the actuator force F_i, their
// power, and the end stops' event indicators. Per joint, allocation free;
// the platform's payload enters the mass matrix (lagrangian.hpp) instead.
//
// On rho_i (positive along +z) act
//   F_i + (2 pi / p) tau_i                      actuator force and motor torque on a lossless screw
//   F_fric,i = -b rhod_i - F_c tanh(rhod_i / v_s)  regularised joint friction
//   F_stop,i                                    compliant end stop:
//     below rho_min by delta = rho_min - rho_i > 0:  +max(0, k delta + d delta_dot)
//     above rho_max by delta = rho_i - rho_max > 0:  -max(0, k delta + d delta_dot)
// and the rotor's reflected mass J (2 pi / p)^2 sits on rho_i's diagonal of M.
//
// Energy: the stop's spring stores 1/2 k delta^2 (potential_energy); the rest
// of the stop force dissipates, at the rate (|F_stop| - k delta) delta_dot,
// which is d delta_dot^2 while the stop pushes and -k delta delta_dot >= 0
// while it is released (k delta + d delta_dot < 0 means delta_dot < 0).
#pragma once

#include <cmath>

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// Regularised joint friction on rho (N, opposes rhod).
inline double friction_force(const Params& p, double rhod) {
  double F = -p.friction_viscous * rhod;
  if (p.friction_coulomb != 0.0) F -= p.friction_coulomb * std::tanh(rhod / p.friction_velocity);
  return F;
}

/// dF_fric/drhod.
inline double friction_slope(const Params& p, double rhod) {
  double s = -p.friction_viscous;
  if (p.friction_coulomb != 0.0) {
    const double th = std::tanh(rhod / p.friction_velocity);
    s -= p.friction_coulomb / p.friction_velocity * (1.0 - th * th);
  }
  return s;
}

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

/// Which stops act, held fixed between located events by the integrators
/// (bit i: leg i's lower stop, bit 4 + i: its upper stop), so that the
/// state derivative is smooth between events (up to the release kink) and
/// the rounding of a located crossing cannot switch a stop on or off again.
/// kStopsFromState: each stop acts when its joint is past it (the plain
/// state function, for Model Exchange and the outputs).
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

/// Energy stored in the stop's spring, 1/2 k delta^2 (J).
inline double stop_potential(const Params& p, double rho) {
  const double d = rho < p.rho_min ? p.rho_min - rho : (rho > p.rho_max ? rho - p.rho_max : 0.0);
  return 0.5 * p.stop_stiffness * d * d;
}

/// Power dissipated in joint i (W, >= 0): friction plus the stop's damping
/// (header comment).
inline double dissipated_power(const Params& p, int leg, unsigned stops, double rho, double rhod) {
  const StopContact c = stop_contact(p, leg, stops, rho, rhod);
  return -friction_force(p, rhod) * rhod + (std::fabs(c.force) - p.stop_stiffness * c.depth) * c.rate;
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

/// Number of end-stop event indicators: rho_i - rho_min (i = 0..3), then
/// rho_max - rho_i (i = 0..3). Each is positive within the travel.
constexpr int kStopIndicators = 2 * kLegs;

/// The indicators from the actuator positions.
inline void stop_indicators(const Params& p, const Vec4& rho, double g[kStopIndicators]) {
  for (int i = 0; i < kLegs; ++i) {
    g[i] = rho[i] - p.rho_min;
    g[kLegs + i] = p.rho_max - rho[i];
  }
}

/// The actuator positions rho_1..4 at a platform pose (closed-form leg
/// inverse kinematics; the four legs as lanes, bit for bit leg_inverse_kinematics
/// leg by leg: ReducedDynamics::leg_positions). Status::Unreachable outside
/// the workspace (rho untouched), NonFinite for a non-finite pose.
Status actuator_positions(const Model& m, const Pose& pose, Vec4& rho);

/// The indicators at a platform pose (any state: they depend on the pose only).
Status stop_indicators(const Model& m, const Pose& pose, double g[kStopIndicators]);

}  // namespace pkm
