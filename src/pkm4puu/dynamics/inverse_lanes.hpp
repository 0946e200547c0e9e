// SPDX-License-Identifier: BSD-2-Clause
// Inverse dynamics in reduced, leg-partitioned form (docs/model.md,
// "Inverse dynamics"). With qd_i = A_i pd and qdd_i = A_i pdd + b_i
// (reduced_dynamics.hpp), projecting Eq. 1 on B = [A_1; ...; A_4; I4]
// removes lambda and leaves four equations for the four forces:
//   J_rho^T F = sum_i A_i^T tau_i + M_p pdd + V_p + G_p - we,
//   tau_i = M_i qdd_i + V_i + G_i - F_passive,i e_0,
// J_rho's row i being A_i's first row (d rho_i/dp). Each leg's position is
// its closed-form inverse kinematics (elbow-down): no iteration. Leg i's
// rows of Eq. 1 then give its multipliers, lambda_i = L_i^{-T} (F_i e_0 -
// tau_i) (Eq. 10 leg by leg), computed only when asked.
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// The four legs' terms of the reduced inverse dynamics (index = leg).
struct InverseLegs {
  double rho[kLegs], rhod[kLegs], rhodd[kLegs];
  double th1d[kLegs], th1dd[kLegs], th2d[kLegs], th2dd[kLegs];
  double qx[kLegs], qy[kLegs], A[kLegs];  // for the angles (leg_inverse_kinematics)
  double c2[kLegs], s2[kLegs];
  double linv[6][kLegs];  // L_i^{-1}'s first two columns by rows: l00 l01 l10 l11 l20 l21 (the third is e_0)
  double tau[3][kLegs];   // tau_i (header comment)
  double a03[kLegs];      // d rho_i/d phi (J_rho's row i: l00, l01, 1, a03)
};

/// The actuator forces F of the machine (rotor, payload, friction and, beyond
/// a stop, the stop's force, as actuator_forces) for the platform motion
/// (pose, pd, pdd) under the external wrench `we`. Status::Unreachable if a
/// leg is out of reach, ::Singular at a leg or parallel singularity.
Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseLegs& legs, Vec4& F);

/// Leg i's multipliers lambda_i = L_i^{-T} (F_i e_0 - tau_i) (Eq. 10).
void reduced_inverse_lambda(const InverseLegs& legs, const Vec4& F, Vec12& lambda);

/// theta1_i and theta2_i of leg i (leg_inverse_kinematics' angles).
void reduced_inverse_angles(const InverseLegs& legs, const Params& p, int leg, double& theta1, double& theta2);

}  // namespace pkm
