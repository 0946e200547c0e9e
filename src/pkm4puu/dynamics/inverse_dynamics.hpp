// SPDX-License-Identifier: BSD-2-Clause
// Inverse dynamics (Eqs. 10-11). With q, qd, qdd known from the servo
// kinematics, Eq. 1 has 16 rows and 16 unknowns: lambda (12) and the
// actuator forces F (4). The 12 rows of the unactuated coordinates
// (theta1_i, theta2_i, x, y, z, phi) carry no actuator force and give lambda
// (Eq. 10); the 4 rows of rho_i then give F (Eq. 11).
#pragma once

#include "pkm4puu/kinematics/servo_kinematics.hpp"

namespace pkm {

//
// The machine (machine.hpp) is included: the rotor's reflected mass and the
// payload through M, V and G, and the joints' passive forces (friction and,
// beyond a stop, the stop's force) are subtracted, so that F is what the
// actuators must add for the plant to follow the motion. A motion whose
// rho lies beyond an end stop is still solved; `beyond_stops` reports it.
struct InverseDynamicsResult {
  Vec16 q, qd, qdd;
  Vec12 lambda;
  Vec4 F;
  /// The equivalent motor torques, F_i p / (2 pi) (N*m).
  Vec4 tau = Vec4::Zero();
  /// Bit i set (i = 0..3): rho_i < rho_min; bit 4 + i: rho_i > rho_max.
  unsigned beyond_stops = 0;
};


/// Eqs. 10-11 at a known motion (q, qd, qdd), external wrench `we`: the
/// actuator forces on top of the joints' passive forces (header comment).
Status actuator_forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& qdd,
                       const Wrench& we, Vec4& F, Vec12& lambda);

/// The actuator forces that hold the configuration q at rest under gravity,
/// the payload and the wrench `we` (no friction at rest; the end stops'
/// springs are not counted on: gravity compensation for a controller).
Status holding_forces(const Model& m, const Vec16& q, const Wrench& we, Vec4& F);

/// The whole inverse problem for a platform motion: position (Newton from
/// the guess in out.q, or from the closed form when `warm_start` is false),
/// velocity, acceleration, then Eqs. 10-11.
Status inverse_dynamics(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                        const Wrench& we, InverseDynamicsResult& out, bool warm_start = false,
                        const NewtonOptions& opt = {});

}  // namespace pkm
