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
// (H: leg_kinematics_derivatives.hpp, r_i = Rz(phi) r_Qi):
//   du (A_i v)  = -L_i^{-1} Gamma_i(u, v)
//   du qd_i     = N_i u,   N_i = -L_i^{-1} [Rz E(qd_i) A_i + r_i phid e_phi^T]
//   dpd qdd_i   = 2 N_i
//   du qdd_i    = Q_i u,   Q_i = -L_i^{-1} [Rz (E(qdd_i) + T(qd_i)) A_i + 2 Rz E(qd_i) N_i
//                                        + (pdd_phi r_i + phid^2 e_z x r_i) e_phi^T]
//   du (A_i^T) w_i = S_i u, S_i = -A_i^T H_mu A_i - (mu_i . r_i) e_phi e_phi^T,
//                           mu_i = L_i^{-T} w_i (= -lambda_i), H_mu = sum_c (Rz^T mu_i)_c d^2 p_Qc/dq^2
// so that
//   dR/dp  = sum_i S_i + A_i^T (W_q A_i + W_qd N_i + M_i Q_i) + dw_p/dp
//   dR/dpd = sum_i A_i^T (W_qd A_i + 2 M_i N_i) + dw_p/dpd
// with W_q, W_qd the partials of w_i (lagrangian_derivatives.hpp, minus
// the passive joint forces' slopes, machine.hpp). The platform's
// (lagrangian.hpp, mwx' = -mwy, mwy' = mwx):
//   dw_p/dphi  = (-mwx phidd + mwy phid^2, -mwy phidd - mwx phid^2, 0, -mwx xdd - mwy ydd)
//   dw_p/dphid = (-2 mwx phid, -2 mwy phid, 0, 0)
#pragma once

#include "reduced_dynamics.hpp"

namespace pkm {

struct ResidualPartials {
  Mat4 dp = Mat4::Zero();    // dR/dp at fixed pd, pdd and applied forces
  Mat4 dpd = Mat4::Zero();   // dR/dpd
  Mat4 Mr = Mat4::Zero();    // dR/dpdd, the reduced mass matrix
  Mat4 J_rho = Mat4::Zero(); // d rho/dp (row i = A_i's rho row): dR/dF = -J_rho^T
};

/// The partials at the reduced terms `rd` (reduced_terms, minimal_state.hpp:
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
Status state_derivative_jacobians(const Model& m, const Vec8& y, const Vec4& F, const Vec4& tau, const Wrench& we,
                                  unsigned stops, Vec8& ydot, Mat8& A, Mat8x12& B);

}  // namespace pkm
