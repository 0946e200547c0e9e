// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/kinematics/leg_kinematics.hpp"

#include <cmath>

#include "pkm4puu/base/sin_cos.hpp"

namespace pkm {

LegConfig leg_config(double rho, double theta1, double theta2) {
  LegConfig c;
  c.rho = rho;
  c.c1 = std::cos(theta1);
  c.s1 = std::sin(theta1);
  c.c2 = std::cos(theta2);
  c.s2 = std::sin(theta2);
  return c;
}

PlatformConfig platform_config(const Pose& pose) {
  PlatformConfig pc;
  pc.pose = pose;
  sin_cos(pose[3], pc.sphi, pc.cphi);  // base/sin_cos.hpp: libm's, but not MinGW's slow one
  return pc;
}

Vec3 leg_point(const Params& p, const LegConfig& c) {
  return {p.l * c.c1 * c.c2 + p.h_prime * c.s1,
          p.l * c.s1 * c.c2 - p.h_prime * c.c1,
          c.rho + p.h + p.l * c.s2};
}

Mat3 leg_point_jacobian(const Params& p, const LegConfig& c) {
  Mat3 J;
  J << 0.0, -p.l * c.s1 * c.c2 + p.h_prime * c.c1, -p.l * c.c1 * c.s2,
       0.0,  p.l * c.c1 * c.c2 + p.h_prime * c.s1, -p.l * c.s1 * c.s2,
       1.0,  0.0,                                   p.l * c.c2;
  return J;
}

Vec3 leg_point_quadratic(const Params& p, const LegConfig& c, double a, double b) {
  // d2p/dth1^2 a^2 + 2 d2p/dth1dth2 a b + d2p/dth2^2 b^2
  const double l = p.l, hp = p.h_prime;
  return {(-l * c.c1 * c.c2 - hp * c.s1) * a * a + 2 * l * c.s1 * c.s2 * a * b - l * c.c1 * c.c2 * b * b,
          (-l * c.s1 * c.c2 + hp * c.c1) * a * a - 2 * l * c.c1 * c.s2 * a * b - l * c.s1 * c.c2 * b * b,
          -l * c.s2 * b * b};
}

Vec3 rotated_attachment(const Model& m, int leg, const PlatformConfig& pc) {
  const Vec3& r = m.r_Q[leg];
  return {pc.cphi * r.x() - pc.sphi * r.y(), pc.sphi * r.x() + pc.cphi * r.y(), 0.0};
}

Vec3 platform_point(const Model& m, int leg, const PlatformConfig& pc) {
  return pc.pose.head<3>() + rotated_attachment(m, leg, pc);
}

Mat34 platform_point_jacobian(const Model& m, int leg, const PlatformConfig& pc) {
  const Vec3 r = rotated_attachment(m, leg, pc);
  Mat34 P;
  P << 1, 0, 0, -r.y(),
       0, 1, 0,  r.x(),
       0, 0, 1,  0.0;
  return P;
}

Status leg_inverse_kinematics(const Model& m, int leg, const PlatformConfig& pc,
                              LegConfig& out, LegAngles* angles) {
  const Params& p = m.p;
  const Vec3 qt = rotate_to_leg(m, leg, platform_point(m, leg, pc) - m.B[leg]);
  const double r2 = qt.x() * qt.x() + qt.y() * qt.y();
  const double A2 = r2 - p.h_prime * p.h_prime;
  if (!(A2 >= 0.0)) return Status::Unreachable;  // also catches NaN
  const double A = std::sqrt(A2);
  if (!(A <= p.l)) return Status::Unreachable;
  // theta1 = psi + delta with psi = atan2(qy, qx), delta = atan2(h', A):
  // cos/sin by the angle-sum identities, with |q~_xy|^2 = A^2 + h'^2 = r2.
  out.c1 = (qt.x() * A - qt.y() * p.h_prime) / r2;
  out.s1 = (qt.y() * A + qt.x() * p.h_prime) / r2;
  out.c2 = A / p.l;
  // 0 <= A <= l gives 0 <= c2 <= 1 and c2^2 <= 1 after rounding: the
  // clamp only guards the sign (a comparison, not a call to fmax).
  const double s2sq = 1.0 - out.c2 * out.c2;
  out.s2 = -std::sqrt(s2sq > 0.0 ? s2sq : 0.0);  // elbow-down
  out.rho = qt.z() - p.h - p.l * out.s2;
  if (angles) {
    angles->theta1 = std::atan2(qt.y(), qt.x()) + std::atan2(p.h_prime, A);
    angles->theta2 = -std::acos(out.c2);
  }
  return Status::Ok;
}

double leg_singularity_measure(const Params& p, const LegConfig& c) {
  // det J = l^2 c2 s2 = l A sin(theta2) with A = l c2 (spec "Working mode").
  (void)p;
  return std::fabs(c.c2 * c.s2);
}

}  // namespace pkm
