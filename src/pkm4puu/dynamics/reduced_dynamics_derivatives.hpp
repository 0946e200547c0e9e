// SPDX-License-Identifier: BSD-2-Clause
// Analytic derivatives of the reduced dynamics (reduced_dynamics.hpp), leg
// by leg from the Lagrangian terms, chained through the leg partitioning.
//
// The reduced equations as a residual in the platform coordinates p:
//   R(p, pd, pdd) = Mr pdd - h = sum_i A_i^T w_i + w_p = 0,
//   w_i = M_i qdd_i + V_i + G_i - f_i   (leg i's rows of Eq. 1 without C^T lambda)
//   w_p = M_p pdd + V_p + G_p - f_p     (the platform with its payload)
// with qd_i = A_i pd, qdd_i = A_i pdd + b_i. Forward dynamics solves R = 0
// for pdd, so dpdd/dx = -Mr^{-1} dR/dx (dR/dpdd = Mr); inverse dynamics
// solves it for the actuator forces F, on which R depends through
// f_i = (F_i + passive, 0, 0): dR/dF = -J_rho^T with J_rho = d rho/dp.
//
// Leg i's closure in the direction u of p (du q_i = A_i u), with the
// symmetric Gamma_i(u, v) = Rz(beta_i) H(A_i u, A_i v) + r_i u_phi v_phi
// (H, E, T: leg_kinematics_derivatives.hpp; r_i = Rz(phi) r_Qi; L_i^{-1} Rz(beta_i) = J_i^{-1}):
//   du (A_i v) = -L_i^{-1} Gamma_i(u, v)
//   d qd_i/dp  = Na A_i + n e_phi^T,   Na = -J_i^{-1} E(qd_i),  n = -phid L_i^{-1} r_i
//   d qdd_i/dpd = 2 d qd_i/dp
//   d qdd_i/dp = Qa A_i + qa e_phi^T,  Qa = -J_i^{-1} (E(qdd_i) + T(qd_i) + 2 E(qd_i) Na),
//                qa = 2 Na n - L_i^{-1} (pdd_phi r_i + phid^2 e_z x r_i)
//   d(A_i^T)/dp w_i = -A_i^T H_mu A_i - (w_i . L_i^{-1} r_i) e_phi e_phi^T,
//                H_mu = sum_c (J_i^{-T} w_i)_c d^2 p_Qc/dq^2  (w_i . L_i^{-1} r_i = -lambda_i . r_i)
// so that, with W_q, W_qd the partials of w_i (lagrangian_derivatives.hpp,
// minus the passive joint force's slopes, machine.hpp),
//   dR/dp  = sum_i A_i^T (W_q - H_mu + W_qd Na + M_i Qa) A_i + A_i^T (W_qd n + M_i qa) e_phi^T
//            - (w_i . L_i^{-1} r_i) e_phi e_phi^T + dw_p/dp
//   dR/dpd = sum_i A_i^T (W_qd + 2 M_i Na) A_i + 2 A_i^T M_i n e_phi^T + dw_p/dpd.
// The platform's (lagrangian.hpp, mwx' = -mwy, mwy' = mwx):
//   dw_p/dphi  = (-mwx phidd + mwy phid^2, -mwy phidd - mwx phid^2, 0, -mwx xdd - mwy ydd)
//   dw_p/dphid = (-2 mwx phid, -2 mwy phid, 0, 0)
#pragma once

#include "pkm4puu/dynamics/reduced_dynamics.hpp"

namespace pkm {

struct ResidualPartials {
  Mat4 dp = Mat4::Zero();    // dR/dp at fixed pd, pdd and applied forces
  Mat4 dpd = Mat4::Zero();   // dR/dpd
  Mat4 Mr = Mat4::Zero();    // dR/dpdd, the reduced mass matrix
  Mat4 J_rho = Mat4::Zero(); // d rho/dp (row i = A_i's rho row): dR/dF = -J_rho^T
  Mat4 drhod_dp = Mat4::Zero();  // d rhod/dp (row i = the rho row of d qd_i/dp); d rhod/dpd = J_rho
};

/// The partials at the reduced terms `rd` (reduced_terms, state_derivative.hpp:
/// every leg prepared and added with its applied and passive forces),
/// rates pd, accelerations pdd. `F_extra` is an actuator force not yet
/// in rd (inverse dynamics: the unknown F), zero otherwise. `stops` as in
/// state_derivative.
void residual_partials(const Model& m, const ReducedDynamics& rd, const Pose& pd, const Pose& pdd,
                       const Vec4& F_extra, unsigned stops, ResidualPartials& out);

/// Inputs of the plant's state derivative, in this order (u, 12 values):
/// F[1..4], Fe[1..3], Me_z, tau[1..4].
constexpr int kPlantInputs = 12;
using Mat8 = Eigen::Matrix<double, 8, 8>;
using Mat8x12 = Eigen::Matrix<double, 8, kPlantInputs>;

/// The state derivative ydot = (pd, pdd(p, pd, u)) of the leg-partitioned
/// formulation and its Jacobians A = dydot/dy (8x8) and B = dydot/du
/// (8x12): the machine included (rotor, friction, payload; the end stops
/// where smooth: `stops` as in state_derivative).
/// If `joints` is given it receives the slider rows: J_rho = d rho/dp and
/// drhod_dp = d rhod/dp (d rhod/dpd = J_rho).
struct JointJacobians {
  Mat4 J_rho, drhod_dp;
};
Status state_derivative_jacobians(const Model& m, const Vec8& y, const Vec4& F, const Vec4& tau, const Wrench& we,
                                  unsigned stops, Vec8& ydot, Mat8& A, Mat8x12& B, JointJacobians* joints = nullptr);

}  // namespace pkm
