// Inverse dynamics (Eqs. 10-11). With q, qd, qdd known from the servo
// kinematics, Eq. 1 has 16 rows and 16 unknowns: lambda (12) and the
// actuator forces F (4). The 12 rows of the unactuated coordinates
// (theta1_i, theta2_i, x, y, z, phi) carry no actuator force and give lambda
// (Eq. 10); the 4 rows of rho_i then give F (Eq. 11).
#pragma once

#include "servo_kinematics.hpp"

namespace pkm {

struct InverseDynamicsResult {
  Vec16 q, qd, qdd;
  Vec12 lambda;
  Vec4 F;
};

/// Eqs. 10-11 at a known motion (q, qd, qdd), external wrench `we`.
Status actuator_forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& qdd,
                       const Wrench& we, Vec4& F, Vec12& lambda);

/// The whole inverse problem for a platform motion: position (Newton from
/// the guess in out.q, or from the closed form when `warm_start` is false),
/// velocity, acceleration, then Eqs. 10-11.
Status inverse_dynamics(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                        const Wrench& we, InverseDynamicsResult& out, bool warm_start = false,
                        const NewtonOptions& opt = {});

}  // namespace pkm
