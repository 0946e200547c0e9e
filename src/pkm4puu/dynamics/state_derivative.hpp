// SPDX-License-Identifier: BSD-2-Clause
// The integrators' state and its derivative.
//
// The integrated state is the platform's pose and velocity,
//   y = [x, y, z, phi, xd, yd, zd, phid],
// the independent coordinates of Eq. 13's leg partitioning. At every
// evaluation the 12 leg coordinates are recovered from y in closed form
// (elbow-down leg inverse kinematics) and the leg rates from
// qd_i = L_i^{-1} P_i pd. This is the projection of q onto C(q) = 0 and of
// qd onto C_q qd = 0 (along the leg coordinates) done at every stage rather
// than after every step: the redundant q never drifts, and ||C(q)|| stays
// at rounding level (~1e-17 m) over any run length.
#pragma once

#include "pkm4puu/dynamics/forward_dynamics.hpp"

namespace pkm {

struct MechanismState {
  Vec16 q = Vec16::Zero(), qd = Vec16::Zero(), qdd = Vec16::Zero();
  Vec12 lambda = Vec12::Zero();
};

/// q and qd from y (theta1 in atan2's range plus atan2(h', A); unwrap
/// outside if continuity matters).
Status expand_state(const Model& m, const Vec8& y, Vec16& q, Vec16& qd);

/// The actuated joints at a state.
struct JointMotion {
  Vec4 rho = Vec4::Zero(), rhod = Vec4::Zero();
};

/// dy/dt for the applied generalised forces f (actuators, drives, external
/// wrench: Eq. 1's right-hand side), with the chosen formulation; the
/// joints' passive forces (friction, end stops: machine.hpp) are added here
/// from the state. If `full` is given it receives q, qd, qdd, lambda; if
/// `joints` is given, rho and rhod.
/// `stops` (machine.hpp): which end stops act, or kStopsFromState.
Status state_derivative(const Model& m, Formulation form, const Vec8& y, const Vec16& f, Vec8& ydot,
                        MechanismState* full = nullptr, JointMotion* joints = nullptr,
                        unsigned stops = ~0u);

class ReducedDynamics;
/// The leg-partitioned reduced terms at y (reduced_dynamics.hpp), every leg
/// prepared and added with its share of f and its passive joint force; the
/// solve is left to the caller. `joints` as in state_derivative.
Status reduced_terms(const Model& m, const Vec8& y, const Vec16& f, unsigned stops, ReducedDynamics& rd,
                     JointMotion* joints = nullptr);

/// f plus the passive joint forces at (q, qd).
Vec16 with_passive_forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& f,
                          unsigned stops = ~0u);

}  // namespace pkm
