// SPDX-License-Identifier: BSD-2-Clause
// Inverse dynamics (Eqs. 10-11). With q, qd, qdd known from the servo
// kinematics, Eq. 1 has 16 rows and 16 unknowns: lambda (12) and the
// actuator forces F (4). The 12 rows of the unactuated coordinates
// (theta1_i, theta2_i, x, y, z, phi) carry no actuator force and give lambda
// (Eq. 10); the 4 rows of rho_i then give F (Eq. 11): the general path
// (inverse_dynamics_general, actuator_forces). inverse_dynamics solves the
// same equations in reduced, leg-partitioned form (inverse_lanes.hpp).
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

/// The whole inverse problem for a platform motion in reduced,
/// leg-partitioned form (inverse_lanes.hpp): each leg's closed-form inverse
/// kinematics (elbow-down), its rates and accelerations, then the four
/// forces from the reduced system, lambda leg by leg. No iteration:
/// `warm_start` and `opt` are not used (kept for inverse_dynamics_general's
/// signature). Status::Unreachable off the workspace, ::Singular at a leg or
/// parallel singularity, ::NonFinite for a non-finite argument; on a
/// failure `out` holds no result (parts of it may have been written).
Status inverse_dynamics(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                        const Wrench& we, InverseDynamicsResult& out, bool warm_start = false,
                        const NewtonOptions& opt = {});

/// The reference path, Eqs. 2-11 taken literally: the position by Newton on
/// the servo constraints (from the guess in out.q, or from the closed form
/// when `warm_start` is false), velocity and acceleration from the 16x16
/// Phi_q, then Eqs. 10-11 with the full M and C_q.
Status inverse_dynamics_general(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                                const Wrench& we, InverseDynamicsResult& out, bool warm_start = false,
                                const NewtonOptions& opt = {});

/// Only the actuators' side of inverse_dynamics (no angles, no lambda):
/// what a feed-forward needs, at the least cost.
struct InverseActuators {
  Vec4 F = Vec4::Zero(), tau = Vec4::Zero();  // as InverseDynamicsResult
  Vec4 rho = Vec4::Zero(), rhod = Vec4::Zero();
  /// |cos theta2_i sin theta2_i| (leg_singularity_measure) and its minimum.
  Vec4 leg_measure = Vec4::Zero();
  double leg_measure_min = 0;
  /// The actuator Jacobian d rho/d(x, y, z, phi).
  Mat4 J_rho = Mat4::Zero();
  unsigned beyond_stops = 0;  // as InverseDynamicsResult
};
Status inverse_actuators(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                         const Wrench& we, InverseActuators& out);

}  // namespace pkm
