// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/reduced_dynamics.hpp"

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/leg_lanes.hpp"

namespace pkm {

Status ReducedDynamics::prepare_leg(const Model& m, int leg, const LegConfig& c,
                                    const PlatformConfig& pc) {
  const Status s = prepare_leg_kinematics(m, leg, c, pc);
  if (s != Status::Ok) return s;
  legs_[leg].M = leg_mass_matrix(m, c);
  return Status::Ok;
}

Status ReducedDynamics::prepare_leg_kinematics(const Model& m, int leg, const LegConfig& c,
                                               const PlatformConfig& pc) {
  if (leg_singularity_measure(m.p, c) < kLegSingularFloor) return Status::Singular;
  Leg& L = legs_[leg];
  L.c = c;
  L.attach = rotated_attachment(m, leg, pc);
  // L_i = Rz(beta_i) J_i with J_i = [0 a e; 0 b f; 1 0 g] (leg_point_jacobian),
  // so L_i^{-1} = J_i^{-1} Rz(beta_i)^T in closed form, D = a f - b e = det J_i.
  const Params& p = m.p;
  const double a = -p.l * c.s1 * c.c2 + p.h_prime * c.c1, b = p.l * c.c1 * c.c2 + p.h_prime * c.s1;
  const double e = -p.l * c.c1 * c.s2, f = -p.l * c.s1 * c.s2, g = p.l * c.c2;
  const double inv_D = 1.0 / (a * f - b * e);
  Mat3& Jinv = L.Jinv;
  Jinv << b * g * inv_D, -a * g * inv_D, 1.0,
          f * inv_D,     -e * inv_D,     0.0,
          -b * inv_D,    a * inv_D,      0.0;
  const double cb = m.cos_beta[leg], sb = m.sin_beta[leg];
  L.Linv.col(0) = cb * Jinv.col(0) - sb * Jinv.col(1);
  L.Linv.col(1) = sb * Jinv.col(0) + cb * Jinv.col(1);
  L.Linv.col(2) = Jinv.col(2);
  // A_i = L_i^{-1} P_i with P_i = [I3, e_z x Rz(phi) r_Qi].
  L.A.leftCols<3>() = L.Linv;
  L.A.col(3) = L.Linv.col(1) * L.attach.x() - L.Linv.col(0) * L.attach.y();
  cphi_ = pc.cphi;
  sphi_ = pc.sphi;
  return Status::Ok;
}

void ReducedDynamics::add_leg(const Model& m, int leg, const Vec3& qd_leg, double phid, double F) {
  Leg& L = legs_[leg];
  const Vec3 gamma = rotate_to_base(m, leg, leg_point_quadratic(m.p, L.c, qd_leg[1], qd_leg[2])) +
                     L.attach * (phid * phid);
  L.b = -(L.Linv * gamma);
  const Vec3 f(F, 0.0, 0.0);
  L.r = f - leg_coriolis(m.p, L.c, qd_leg[1], qd_leg[2], qd_leg[0]) - leg_gravity(m.p, L.c) - L.M * L.b;
  if (leg == 0) {
    Mr_.setZero();
    rhs_.setZero();
    phid_ = phid;
  }
  // A^T M A with M's zeros (M01 = M12 = 0) and the result's symmetry.
  Mat34 MA;
  MA.row(0) = L.M(0, 0) * L.A.row(0) + L.M(0, 2) * L.A.row(2);
  MA.row(1) = L.M(1, 1) * L.A.row(1);
  MA.row(2) = L.M(0, 2) * L.A.row(0) + L.M(2, 2) * L.A.row(2);
  for (int j = 0; j < 4; ++j)
    for (int k = j; k < 4; ++k) Mr_(j, k) += L.A.col(j).dot(MA.col(k));
  rhs_.noalias() += L.A.transpose() * L.r;
}

namespace {

// The reduced system with the platform, its payload and the external
// wrench (reduced_system's arithmetic, on the upper triangle only) and its
// LDL^T solution: solve_platform's and the hot path's one solver. mr: the
// legs' A^T M A, upper triangle by rows; rhs: the legs' A^T r.
Status solve_reduced(const Model& m, const Wrench& we, const double mr[10], const double rhs_legs[4], double cphi,
                     double sphi, double phid, Pose& a) {
  const PlatformInertia pi = platform_inertia(m, cphi, sphi);
  double M[4][4] = {{mr[0], mr[1], mr[2], mr[3]},  // the upper triangle
                    {0.0, mr[4], mr[5], mr[6]},
                    {0.0, 0.0, mr[7], mr[8]},
                    {0.0, 0.0, 0.0, mr[9]}};
  M[0][0] += pi.mass;
  M[1][1] += pi.mass;
  M[2][2] += pi.mass;
  M[3][3] += pi.Izz;
  M[0][3] -= pi.mwy;
  M[1][3] += pi.mwx;
  double rhs[4];
  for (int j = 0; j < 4; ++j) rhs[j] = rhs_legs[j] + we[j];
  const double w2 = phid * phid;
  rhs[0] += pi.mwx * w2;
  rhs[1] += pi.mwy * w2;
  rhs[2] -= pi.mass * m.p.g;
  // LDL^T of the symmetric positive definite 4x4, written out (no square
  // roots): Mr = U^T D U with unit upper-triangular U, then two substitutions.
  double d[4], U[4][4];  // U's strictly upper triangle
  for (int j = 0; j < 4; ++j) {
    double dj = M[j][j];
    for (int k = 0; k < j; ++k) dj -= U[k][j] * U[k][j] * d[k];
    if (!(dj > 0.0)) return Status::Singular;  // also NaN
    d[j] = dj;
    for (int i = j + 1; i < 4; ++i) {
      double u = M[j][i];
      for (int k = 0; k < j; ++k) u -= U[k][j] * U[k][i] * d[k];
      U[j][i] = u / dj;
    }
  }
  for (int i = 0; i < 4; ++i)  // U^T z = rhs
    for (int k = 0; k < i; ++k) rhs[i] -= U[k][i] * rhs[k];
  for (int i = 0; i < 4; ++i) rhs[i] /= d[i];
  for (int i = 3; i >= 0; --i)  // U a = z / d
    for (int k = i + 1; k < 4; ++k) rhs[i] -= U[i][k] * rhs[k];
  a = Pose(rhs[0], rhs[1], rhs[2], rhs[3]);
  return a.allFinite() ? Status::Ok : Status::Singular;
}

}  // namespace

Status ReducedDynamics::platform_derivative(const Model& m, const PlatformConfig& pc, const Pose& pd,
                                            const Vec16& f, unsigned stops, Vec4* rho, Vec4* rhod, Pose& pdd,
                                            lanes::Kernel kind) {
  LegSums sums;
  const Status s = leg_sums(m, pc, pd, f, stops, sums, kind);
  if (s != Status::Ok) return s;
  if (rho) *rho = Vec4(sums.rho[0], sums.rho[1], sums.rho[2], sums.rho[3]);
  if (rhod) *rhod = Vec4(sums.rhod[0], sums.rhod[1], sums.rhod[2], sums.rhod[3]);
  return solve_leg_sums(m, f.segment<4>(kPlatform), sums, pc, pd[3], pdd);
}

Status ReducedDynamics::solve_leg_sums(const Model& m, const Wrench& we, const LegSums& sums,
                                       const PlatformConfig& pc, double phid, Pose& pdd) {
  return solve_reduced(m, we, sums.mr, sums.rhs, pc.cphi, pc.sphi, phid, pdd);
}

Mat4 ReducedDynamics::reduced_mass(const Model& m, const LegSums& sums, const PlatformConfig& pc) {
  const PlatformInertia pi = platform_inertia(m, pc.cphi, pc.sphi);
  Mat4 Mr;
  int n = 0;
  for (int j = 0; j < 4; ++j)
    for (int k = j; k < 4; ++k) Mr(j, k) = sums.mr[n++];
  Mr.diagonal() += Vec4(pi.mass, pi.mass, pi.mass, pi.Izz);
  Mr(0, 3) -= pi.mwy;
  Mr(1, 3) += pi.mwx;
  Mr.triangularView<Eigen::StrictlyLower>() = Mr.transpose();
  return Mr;
}

void ReducedDynamics::reduced_system(const Model& m, const Wrench& we, Mat4& Mr, Vec4& rhs) const {
  // The upper triangle of the reduced mass matrix (add_leg fills only it),
  // plus the platform with its payload (lagrangian.hpp): M_p, V_p, G_p.
  const PlatformInertia pi = platform_inertia(m, cphi_, sphi_);
  Mr = Mr_;
  Mr.diagonal() += Vec4(pi.mass, pi.mass, pi.mass, pi.Izz);
  Mr(0, 3) -= pi.mwy;
  Mr(1, 3) += pi.mwx;
  Mr.triangularView<Eigen::StrictlyLower>() = Mr.transpose();
  rhs = rhs_ + we;
  const double w2 = phid_ * phid_;
  rhs[0] += pi.mwx * w2;
  rhs[1] += pi.mwy * w2;
  rhs[2] -= pi.mass * m.p.g;
}

Status ReducedDynamics::solve_platform(const Model& m, const Wrench& we, Pose& a) const {
  double mr[10];
  int n = 0;
  for (int j = 0; j < 4; ++j)
    for (int k = j; k < 4; ++k) mr[n++] = Mr_(j, k);
  const double rhs[4] = {rhs_[0], rhs_[1], rhs_[2], rhs_[3]};
  return solve_reduced(m, we, mr, rhs, cphi_, sphi_, phid_, a);
}

Status ReducedDynamics::solve(const Model& m, const Wrench& we, Vec16& qdd, Vec12& lambda) {
  Pose a;
  const Status s = solve_platform(m, we, a);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& L = legs_[i];
    const Vec3 qdd_i = L.A * a + L.b;
    qdd.segment<3>(leg_offset(i)) = qdd_i;
    lambda.segment<3>(3 * i) = L.Linv.transpose() * (L.r - L.M * (L.A * a));
  }
  qdd.segment<4>(kPlatform) = a;
  return lambda.allFinite() ? Status::Ok : Status::Singular;
}

}  // namespace pkm
