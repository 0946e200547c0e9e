#include "reduced_dynamics.hpp"

#include "constraints.hpp"
#include "lagrangian.hpp"
#include "machine.hpp"

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

void ReducedDynamics::reset_platform_only(const PlatformConfig& pc, double phid) {
  Mr_.setZero();
  rhs_.setZero();
  cphi_ = pc.cphi;
  sphi_ = pc.sphi;
  phid_ = phid;
}

Status ReducedDynamics::add_leg_platform_only(const Model& m, int leg, const PlatformConfig& pc, const Pose& pd,
                                              double f_rho, unsigned stops, double& rho, double& rhod) {
  const Params& p = m.p;
  LegConfig c;
  Status s = leg_inverse_kinematics(m, leg, pc, c);
  if (s != Status::Ok) return s;
  if (leg_singularity_measure(p, c) < kLegSingularFloor) return Status::Singular;
  const Vec3 attach = rotated_attachment(m, leg, pc);
  // prepare_leg_kinematics: J_i^{-1} (its third column is e_0) and
  // L_i^{-1} = J_i^{-1} Rz(beta_i)^T (third column e_0 too).
  const double a = -p.l * c.s1 * c.c2 + p.h_prime * c.c1, b = p.l * c.c1 * c.c2 + p.h_prime * c.s1;
  const double e = -p.l * c.c1 * c.s2, f = -p.l * c.s1 * c.s2, g = p.l * c.c2;
  const double inv_D = 1.0 / (a * f - b * e);
  const double j00 = b * g * inv_D, j01 = -a * g * inv_D;
  const double j10 = f * inv_D, j11 = -e * inv_D;
  const double j20 = -b * inv_D, j21 = a * inv_D;
  const double cb = m.cos_beta[leg], sb = m.sin_beta[leg];
  const double l00 = cb * j00 - sb * j01, l10 = cb * j10 - sb * j11, l20 = cb * j20 - sb * j21;
  const double l01 = sb * j00 + cb * j01, l11 = sb * j10 + cb * j11, l21 = sb * j20 + cb * j21;
  // A_i = [L_i^{-1}, L_i^{-1} (e_z x attach)]: rows (l_k0, l_k1, [k == 0], a_k3).
  const double a03 = l01 * attach.x() - l00 * attach.y();
  const double a13 = l11 * attach.x() - l10 * attach.y();
  const double a23 = l21 * attach.x() - l20 * attach.y();
  // leg_velocity: qd_i = A_i pd.
  const double phid = pd[3];
  const double rd0 = l00 * pd[0] + l01 * pd[1] + pd[2] + a03 * phid;
  const double th1d = l10 * pd[0] + l11 * pd[1] + a13 * phid;
  const double th2d = l20 * pd[0] + l21 * pd[1] + a23 * phid;
  // add_leg.
  const Vec3 gamma = rotate_to_base(m, leg, leg_point_quadratic(p, c, th1d, th2d)) + attach * (phid * phid);
  const double b0 = -(l00 * gamma[0] + l01 * gamma[1] + gamma[2]);
  const double b1 = -(l10 * gamma[0] + l11 * gamma[1]);
  const double b2 = -(l20 * gamma[0] + l21 * gamma[1]);
  const Mat3 M = leg_mass_matrix(m, c);  // M01 = M12 = 0
  const double m00 = M(0, 0), m02 = M(0, 2), m11 = M(1, 1), m22 = M(2, 2);
  const Vec3 V = leg_coriolis(p, c, th1d, th2d, rd0);
  const Vec3 G = leg_gravity(p, c);
  const double F = f_rho + passive_joint_force(p, leg, stops, c.rho, rd0);
  const double r0 = F - V[0] - G[0] - (m00 * b0 + m02 * b2);
  const double r1 = -V[1] - m11 * b1;
  const double r2 = -V[2] - G[2] - (m02 * b0 + m22 * b2);
  // A^T M A, upper triangle; M A's rows, with A's column 2 = e_0.
  const double A[3][4] = {{l00, l01, 1.0, a03}, {l10, l11, 0.0, a13}, {l20, l21, 0.0, a23}};
  double MA[3][4];
  for (int k = 0; k < 4; ++k) {
    MA[0][k] = m00 * A[0][k] + m02 * A[2][k];
    MA[1][k] = m11 * A[1][k];
    MA[2][k] = m02 * A[0][k] + m22 * A[2][k];
  }
  for (int j = 0; j < 4; ++j) {
    if (j == 2) {  // A's column 2 is e_0
      for (int k = 2; k < 4; ++k) Mr_(2, k) += MA[0][k];
      continue;
    }
    for (int k = j; k < 4; ++k) Mr_(j, k) += A[0][j] * MA[0][k] + A[1][j] * MA[1][k] + A[2][j] * MA[2][k];
  }
  rhs_[0] += l00 * r0 + l10 * r1 + l20 * r2;
  rhs_[1] += l01 * r0 + l11 * r1 + l21 * r2;
  rhs_[2] += r0;
  rhs_[3] += a03 * r0 + a13 * r1 + a23 * r2;
  rho = c.rho;
  rhod = rd0;
  return Status::Ok;
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
  Mat4 Mr;
  Vec4 rhs;
  reduced_system(m, we, Mr, rhs);
  // LDL^T of the symmetric positive definite 4x4, written out (no square
  // roots): Mr = U^T D U with unit upper-triangular U, then two substitutions.
  double d[4];
  Mat4 U = Mat4::Identity();
  for (int j = 0; j < 4; ++j) {
    double dj = Mr(j, j);
    for (int k = 0; k < j; ++k) dj -= U(k, j) * U(k, j) * d[k];
    if (!(dj > 0.0)) return Status::Singular;  // also NaN
    d[j] = dj;
    for (int i = j + 1; i < 4; ++i) {
      double u = Mr(j, i);
      for (int k = 0; k < j; ++k) u -= U(k, j) * U(k, i) * d[k];
      U(j, i) = u / dj;
    }
  }
  for (int i = 0; i < 4; ++i)  // U^T z = rhs
    for (int k = 0; k < i; ++k) rhs[i] -= U(k, i) * rhs[k];
  for (int i = 0; i < 4; ++i) rhs[i] /= d[i];
  for (int i = 3; i >= 0; --i)  // U a = z / d
    for (int k = i + 1; k < 4; ++k) rhs[i] -= U(i, k) * rhs[k];
  a = rhs;
  return a.allFinite() ? Status::Ok : Status::Singular;
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
