// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/kinematics/constraints.hpp"

#include <cmath>
#include <limits>

namespace pkm {

LegConfig leg_config_from_q(const Vec16& q, int leg) {
  const int o = leg_offset(leg);
  return leg_config(q[o], q[o + 1], q[o + 2]);
}

PlatformConfig platform_config_from_q(const Vec16& q) {
  return platform_config(q.segment<4>(kPlatform));
}

Mat3 leg_block(const Model& m, int leg, const LegConfig& c) {
  const Mat3 J = leg_point_jacobian(m.p, c);
  Mat3 L;
  for (int k = 0; k < 3; ++k) L.col(k) = rotate_to_base(m, leg, J.col(k));
  return L;
}

Vec12 constraints(const Model& m, const Vec16& q) {
  const PlatformConfig pc = platform_config_from_q(q);
  Vec12 C;
  for (int i = 0; i < kLegs; ++i) {
    const Vec3 pq = leg_point(m.p, leg_config_from_q(q, i));
    C.segment<3>(3 * i) = m.B[i] + rotate_to_base(m, i, pq) - platform_point(m, i, pc);
  }
  return C;
}

void constraint_jacobian(const Model& m, const Vec16& q, Mat12x16& Cq) {
  Cq.setZero();
  const PlatformConfig pc = platform_config_from_q(q);
  for (int i = 0; i < kLegs; ++i) {
    Cq.block<3, 3>(3 * i, leg_offset(i)) = leg_block(m, i, leg_config_from_q(q, i));
    Cq.block<3, 4>(3 * i, kPlatform) = -platform_point_jacobian(m, i, pc);
  }
}

Vec12 constraint_gamma(const Model& m, const Vec16& q, const Vec16& qd) {
  const PlatformConfig pc = platform_config_from_q(q);
  const double phid = qd[kPlatform + 3];
  Vec12 g;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    const Vec3 quad = leg_point_quadratic(m.p, leg_config_from_q(q, i), qd[o + 1], qd[o + 2]);
    // Platform point: d2/dt2 [Rz(phi) r] = (e_z x Rz r) phidd - Rz r phid^2;
    // it enters C with a minus sign.
    g.segment<3>(3 * i) = rotate_to_base(m, i, quad) + rotated_attachment(m, i, pc) * (phid * phid);
  }
  return g;
}

Status actuator_jacobian(const Model& m, const Vec16& q, Mat4& J) {
  const PlatformConfig pc = platform_config_from_q(q);
  for (int i = 0; i < kLegs; ++i) {
    const LegConfig c = leg_config_from_q(q, i);
    if (leg_singularity_measure(m.p, c) < kLegSingularFloor) return Status::Singular;
    // C_i = 0 => L_i dq_i = P_i dpose; rho_i is the first row of L_i^{-1} P_i.
    const Mat3 Linv = leg_block(m, i, c).inverse();
    J.row(i) = Linv.row(0) * platform_point_jacobian(m, i, pc);
  }
  return Status::Ok;
}

double actuator_jacobian_condition(const Mat4& J) {
  Mat4 Js = J;
  Js.col(3) /= kConditionLength;
  const Eigen::JacobiSVD<Mat4> svd(Js);
  const Vec4 s = svd.singularValues();
  if (!(s[3] > 0.0)) return std::numeric_limits<double>::infinity();
  return s[0] / s[3];
}

double actuator_jacobian_condition(const Model& m, const Vec16& q) {
  Mat4 J;
  if (actuator_jacobian(m, q, J) != Status::Ok) return std::numeric_limits<double>::infinity();
  return actuator_jacobian_condition(J);
}

}  // namespace pkm
