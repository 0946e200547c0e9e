#include "reduced_dynamics_derivatives.hpp"

#include "lagrangian.hpp"
#include "lagrangian_derivatives.hpp"
#include "leg_kinematics_derivatives.hpp"
#include "machine.hpp"
#include "minimal_state.hpp"

namespace pkm {
namespace {

Mat3 rz_beta(const Model& m, int leg) {
  const double c = m.cos_beta[leg], s = m.sin_beta[leg];
  Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
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
    const Vec3 qdd = L.A * pdd + L.b;
    Vec3 w = L.M * (L.A * pdd) - L.r;  // M qdd + V + G - f (the r of add_leg)
    w[0] -= F_extra[i];
    const Mat3 Rz = rz_beta(m, i);
    const Vec3& r = L.attach;
    const LegPointCurvature k = leg_point_curvature(p, L.c);
    const Mat3 Eqd = leg_point_hessian_times(k, qd);
    // N = d qd_i/dp (header comment).
    Mat34 X = Rz * (Eqd * L.A);
    X.col(3) += r * phid;
    const Mat34 N = -(L.Linv * X);
    // Q = d qdd_i/dp.
    X.noalias() = Rz * ((leg_point_hessian_times(k, qdd) + leg_point_third_times(k, qd)) * L.A + 2.0 * Eqd * N);
    X.col(3) += pdd[3] * r + phid * phid * Vec3(-r.y(), r.x(), 0.0);
    const Mat34 Q = -(L.Linv * X);
    // S = d(A_i^T)/dp w_i, through mu = L^{-T} w in the leg frame.
    const Vec3 mu = L.Linv.transpose() * w;
    const Vec3 mu_leg = Rz.transpose() * mu;
    const double h11 = mu_leg.dot(k.p11), h12 = mu_leg.dot(k.p12), h22 = mu_leg.dot(k.p22);
    const Vec4 a1 = L.A.row(1).transpose(), a2 = L.A.row(2).transpose();
    const Vec4 g1 = h11 * a1 + h12 * a2, g2 = h12 * a1 + h22 * a2;
    out.dp.noalias() -= g1 * a1.transpose() + g2 * a2.transpose();
    out.dp(3, 3) -= mu.dot(r);
    // The leg's own terms and its joint's passive force.
    LegTermsPartials W = leg_terms_partials(p, L.c, qd, qdd);
    const PassiveSlopes ps = passive_joint_force_slopes(p, i, stops, L.c.rho, qd[0]);
    W.dq(0, 0) -= ps.drho;
    W.dqd(0, 0) -= ps.drhod;
    out.dp.noalias() += L.A.transpose() * (W.dq * L.A + W.dqd * N + L.M * Q);
    out.dpd.noalias() += L.A.transpose() * (W.dqd * L.A + 2.0 * L.M * N);
    out.J_rho.row(i) = L.A.row(0);
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
                                  unsigned stops, Vec8& ydot, Mat8& A, Mat8x12& B) {
  if (!y.allFinite() || !F.allFinite() || !tau.allFinite() || !we.allFinite()) return Status::NonFinite;
  ReducedDynamics rd;
  Status s = reduced_terms(m, y, generalized_forces(m, F, tau, we), stops, rd);
  if (s != Status::Ok) return s;
  Pose pdd;
  s = rd.solve_platform(m, we, pdd);
  if (s != Status::Ok) return s;
  const Pose pd = y.tail<4>();
  ResidualPartials P;
  residual_partials(m, rd, pd, pdd, Vec4::Zero(), stops, P);
  // dpdd/dx = -Mr^{-1} dR/dx; dR/dF = -J_rho^T, dR/dtau = -(2 pi/p) J_rho^T, dR/dwe = -I.
  Eigen::Matrix<double, 4, 8 + kPlantInputs> rhs;
  rhs << -P.dp, -P.dpd, P.J_rho.transpose(), Mat4::Identity(), m.drive_ratio * P.J_rho.transpose();
  const Eigen::LDLT<Mat4> ldlt(P.Mr);
  const Eigen::Matrix<double, 4, 8 + kPlantInputs> sol = ldlt.solve(rhs);
  if (!sol.allFinite()) return Status::Singular;
  ydot << pd, pdd;
  A.setZero();
  A.topRightCorner<4, 4>().setIdentity();
  A.bottomRows<4>() = sol.leftCols<8>();
  B.setZero();
  B.bottomRows<4>() = sol.rightCols<kPlantInputs>();
  return Status::Ok;
}

}  // namespace pkm
