// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"

#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/lagrangian_derivatives.hpp"
#include "pkm4puu/dynamics/leg_lanes_derivatives.hpp"
#include "pkm4puu/kinematics/leg_kinematics_derivatives.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"

namespace pkm {
namespace {

/// out += A^T X A + (A^T x) e_phi^T for A = L^{-1} P, P = [I3, c]:
/// with Y = L^{-T} X L^{-1} and y = L^{-T} x, P^T Y P = [Y, Y c; c^T Y, c^T Y c]
/// and P^T y = (y, c . y).
void add_projected(const Mat3& Linv, const Vec3& c, const Mat3& X, const Vec3& x, Mat4& out) {
  const Mat3 Y = Linv.transpose() * X * Linv;
  const Vec3 y = Linv.transpose() * x;
  const Vec3 Yc = Y * c;
  out.topLeftCorner<3, 3>() += Y;
  out.col(3).head<3>() += Yc + y;
  out.row(3).head<3>() += c.transpose() * Y;
  out(3, 3) += c.dot(Yc) + c.dot(y);
}

}  // namespace

void residual_partials(const Model& m, const ReducedDynamics& rd, const Pose& pd, const Pose& pdd,
                       const Vec4& F_extra, unsigned stops, ResidualPartials& out) {
  const Params& p = m.p;
  out.dp.setZero();
  out.dpd.setZero();
  const double phid = pd[3];
  for (int i = 0; i < kLegs; ++i) {
    const ReducedDynamics::Leg& L = rd.leg(i);
    const Vec3 qd = L.A * pd;
    const Vec3 Apdd = L.A * pdd;
    const Vec3 qdd = Apdd + L.b;
    Vec3 w = L.M * Apdd - L.r;  // M qdd + V + G - f (the r of add_leg)
    w[0] -= F_extra[i];
    const Vec3& r = L.attach;
    const Vec3 c(-r.y(), r.x(), 0.0);  // e_z x r: P_i's phi column
    const Vec3 Linv_r = L.Linv * r;
    const LegPointCurvature k = leg_point_curvature(p, L.c);
    const Mat3 Eqd = leg_point_hessian_times(k, qd);
    // d qd_i/dp = Na A + n e_phi^T, d qdd_i/dp = Qa A + qa e_phi^T (header comment).
    // (E and T have a zero rho column, and so have Na and Qa.)
    Mat3 Na;
    Na.col(0).setZero();
    Na.rightCols<2>().noalias() = -(L.Jinv * Eqd.rightCols<2>());
    const Vec3 n = -phid * Linv_r;
    Mat3 Y = leg_point_hessian_times(k, qdd) + leg_point_third_times(k, qd);
    Y.rightCols<2>().noalias() += 2.0 * (Eqd.rightCols<2>() * Na.bottomRightCorner<2, 2>());
    Mat3 Qa;
    Qa.col(0).setZero();
    Qa.rightCols<2>().noalias() = -(L.Jinv * Y.rightCols<2>());
    const Vec3 qa = 2.0 * (Na * n) - L.Linv * (pdd[3] * r + phid * phid * c);
    // The leg's own terms, its joint's passive force and d(A_i^T)/dp w_i.
    LegTermsPartials W = leg_terms_partials(p, L.c, qd, qdd);
    const PassiveSlopes ps = passive_joint_force_slopes(p, i, stops, L.c.rho, qd[0]);
    W.dqd(0, 0) -= ps.drhod;
    const Vec3 mu_leg = L.Jinv.transpose() * w;  // Rz^T L^{-T} w
    Mat3 K = W.dqd * Na + L.M * Qa;
    K.col(2) += W.dtheta2;
    K(0, 0) -= ps.drho;
    K(1, 1) -= mu_leg.dot(k.p11);
    K(1, 2) -= mu_leg.dot(k.p12);
    K(2, 1) -= mu_leg.dot(k.p12);
    K(2, 2) -= mu_leg.dot(k.p22);
    add_projected(L.Linv, c, K, W.dqd * n + L.M * qa, out.dp);
    out.dp(3, 3) -= w.dot(Linv_r);
    add_projected(L.Linv, c, W.dqd + 2.0 * (L.M * Na), 2.0 * (L.M * n), out.dpd);
    out.J_rho.row(i) = L.A.row(0);
    out.drhod_dp.row(i).noalias() = Na.row(0) * L.A;
    out.drhod_dp(i, 3) += n[0];
  }
  // The platform with its payload.
  const PlatformInertia pi = platform_inertia(m, rd.cos_phi(), rd.sin_phi());
  out.dp(0, 3) += -pi.mwx * pdd[3] + pi.mwy * phid * phid;
  out.dp(1, 3) += -pi.mwy * pdd[3] - pi.mwx * phid * phid;
  out.dp(3, 3) += -pi.mwx * pdd[0] - pi.mwy * pdd[1];
  out.dpd(0, 3) -= 2.0 * pi.mwx * phid;
  out.dpd(1, 3) -= 2.0 * pi.mwy * phid;
  Vec4 unused;
  rd.reduced_system(m, Wrench::Zero(), out.Mr, unused);
}

Status state_derivative_jacobians(const Model& m, const Vec8& y, const Vec4& F, const Vec4& tau, const Wrench& we,
                                  unsigned stops, Vec8& ydot, Mat8& A, Mat8x12& B, JointJacobians* joints) {
  if (!y.allFinite() || !F.allFinite() || !tau.allFinite() || !we.allFinite()) return Status::NonFinite;
  // The legs as lanes (leg_lanes_derivatives.hpp): the state derivative's
  // own kernel keeps its intermediates, one solve, then the legs' partials;
  // residual_partials' sums leg by leg, plus the platform's terms here.
  const PlatformConfig pc = platform_config(y.head<4>());
  const Pose pd = y.tail<4>();
  LegPartialSums P;
  const Status s = leg_partial_sums(m, pc, pd, generalized_forces(m, F, tau, we), stops, P);
  if (s != Status::Ok) return s;
  const Pose& pdd = P.pdd;
  const double phid = pd[3];
  const PlatformInertia pi = platform_inertia(m, pc.cphi, pc.sphi);
  P.dp(0, 3) += -pi.mwx * pdd[3] + pi.mwy * phid * phid;
  P.dp(1, 3) += -pi.mwy * pdd[3] - pi.mwx * phid * phid;
  P.dp(3, 3) += -pi.mwx * pdd[0] - pi.mwy * pdd[1];
  P.dpd(0, 3) -= 2.0 * pi.mwx * phid;
  P.dpd(1, 3) -= 2.0 * pi.mwy * phid;
  // dpdd/dx = -Mr^{-1} dR/dx; dR/dF = -J_rho^T, dR/dtau = -(2 pi/p) J_rho^T, dR/dwe = -I.
  // Mr is symmetric positive definite (solve_platform's LDL^T succeeded) and
  // 4x4: its explicit inverse (cofactors) is far cheaper than a
  // factorisation with 20 right-hand sides.
  const Mat4 Mr_inv = ReducedDynamics::reduced_mass(m, P.sums, pc).inverse();
  ydot << pd, pdd;
  A.topRows<4>().setZero();
  A.topRightCorner<4, 4>().setIdentity();
  A.bottomLeftCorner<4, 4>().noalias() = -(Mr_inv * P.dp);
  A.bottomRightCorner<4, 4>().noalias() = -(Mr_inv * P.dpd);
  B.topRows<4>().setZero();
  B.block<4, 4>(4, 0).noalias() = Mr_inv * P.J_rho.transpose();
  B.block<4, 4>(4, 4) = Mr_inv;
  B.block<4, 4>(4, 8) = m.drive_ratio * B.block<4, 4>(4, 0);
  if (!A.allFinite() || !B.allFinite()) return Status::Singular;
  if (joints) {
    joints->J_rho = P.J_rho;
    joints->drhod_dp = P.drhod_dp;
  }
  return Status::Ok;
}

}  // namespace pkm
