// SPDX-License-Identifier: BSD-2-Clause
// Second and third derivatives of the leg end point p_Q(rho, theta1, theta2)
// (leg_kinematics.hpp), in frame 0_i. p_Q is linear in rho, so only the
// theta derivatives are nonzero (subscripts 1 = theta1, 2 = theta2):
//   p_11 = (-l c1 c2 - h' s1, -l s1 c2 + h' c1, 0)
//   p_12 = ( l s1 s2,         -l c1 s2,         0)
//   p_22 = (-l c1 c2,         -l s1 c2,     -l s2)
//   p_111 = -(p_1 without z), p_112 = (l c1 s2, l s1 s2, 0),
//   p_122 = (l s1 c2, -l c1 c2, 0), p_222 = (l c1 s2, l s1 s2, -l c2)
// With H(u, v) = sum_jk p_jk u_j v_k the bilinear second derivative:
//   E(v) = d(J v)/dq,  E(v) u = H(u, v)
//   T(v) = d H(v, v)/dq  (H(v, v) = leg_point_quadratic)
#pragma once

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

struct LegPointCurvature {
  Vec3 p11, p12, p22;          // second derivatives
  Vec3 p111, p112, p122, p222; // third derivatives
};

// Inline: called per leg in the derivatives' hot path.
inline LegPointCurvature leg_point_curvature(const Params& p, const LegConfig& c) {
  const double l = p.l, hp = p.h_prime;
  LegPointCurvature k;
  k.p11 = {-l * c.c1 * c.c2 - hp * c.s1, -l * c.s1 * c.c2 + hp * c.c1, 0.0};
  k.p12 = {l * c.s1 * c.s2, -l * c.c1 * c.s2, 0.0};
  k.p22 = {-l * c.c1 * c.c2, -l * c.s1 * c.c2, -l * c.s2};
  k.p111 = {l * c.s1 * c.c2 - hp * c.c1, -l * c.c1 * c.c2 - hp * c.s1, 0.0};
  k.p112 = {l * c.c1 * c.s2, l * c.s1 * c.s2, 0.0};
  k.p122 = {l * c.s1 * c.c2, -l * c.c1 * c.c2, 0.0};
  k.p222 = {l * c.c1 * c.s2, l * c.s1 * c.s2, -l * c.c2};
  return k;
}

/// E(v) = d(J v)/d(rho, theta1, theta2) (header comment); column 0 is zero.
inline Mat3 leg_point_hessian_times(const LegPointCurvature& k, const Vec3& v) {
  Mat3 E;
  E.col(0).setZero();
  E.col(1) = k.p11 * v[1] + k.p12 * v[2];
  E.col(2) = k.p12 * v[1] + k.p22 * v[2];
  return E;
}

/// T(v) = d H(v, v)/d(rho, theta1, theta2); column 0 is zero.
inline Mat3 leg_point_third_times(const LegPointCurvature& k, const Vec3& v) {
  const double aa = v[1] * v[1], ab = 2.0 * v[1] * v[2], bb = v[2] * v[2];
  Mat3 T;
  T.col(0).setZero();
  T.col(1) = k.p111 * aa + k.p112 * ab + k.p122 * bb;
  T.col(2) = k.p112 * aa + k.p122 * ab + k.p222 * bb;
  return T;
}

}  // namespace pkm
