// SPDX-License-Identifier: BSD-2-Clause
// Loop closures of the whole mechanism (Eq. 15) and their derivatives, plus
// the 4x4 actuator Jacobian. Full-size forms, as in the paper.
#pragma once

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

/// Leg i's configuration read from q.
LegConfig leg_config_from_q(const Vec16& q, int leg);
/// The platform's configuration read from q.
PlatformConfig platform_config_from_q(const Vec16& q);

/// C(q), Eq. 15: C_i = B_i + Rz(beta_i) p_Q - p - Rz(phi) r_Qi, i = 1..4.
Vec12 constraints(const Model& m, const Vec16& q);

/// C_q = dC/dq (12 x 16), analytic.
void constraint_jacobian(const Model& m, const Vec16& q, Mat12x16& Cq);

/// (C_q qd)_q qd, the velocity-dependent part of d^2C/dt^2 (so that
/// C_q qdd + gamma = 0 on the constraint manifold), analytic.
Vec12 constraint_gamma(const Model& m, const Vec16& q, const Vec16& qd);

/// dC_i/d(rho_i, theta1_i, theta2_i) = Rz(beta_i) J_i: leg i's 3x3 block.
Mat3 leg_block(const Model& m, int leg, const LegConfig& c);

/// Actuator Jacobian d(rho_1..4)/d(x, y, z, phi) at a configuration on the
/// manifold. Status::Singular if a leg block is singular.
Status actuator_jacobian(const Model& m, const Vec16& q, Mat4& J);

/// Condition number (2-norm) of the actuator Jacobian with its phi column
/// divided by 0.1 m (docs/model.md "The FMUs' names"). Returns +inf at
/// a singularity.
double actuator_jacobian_condition(const Mat4& J);

/// The same at a configuration q on the manifold (+inf at a singularity).
double actuator_jacobian_condition(const Model& m, const Vec16& q);

/// Characteristic length that makes the phi column commensurate, m.
constexpr double kConditionLength = 0.1;

}  // namespace pkm
