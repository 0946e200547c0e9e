#include "leg_kinematics_derivatives.hpp"

namespace pkm {

LegPointCurvature leg_point_curvature(const Params& p, const LegConfig& c) {
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

Mat3 leg_point_hessian_times(const LegPointCurvature& k, const Vec3& v) {
  Mat3 E;
  E.col(0).setZero();
  E.col(1) = k.p11 * v[1] + k.p12 * v[2];
  E.col(2) = k.p12 * v[1] + k.p22 * v[2];
  return E;
}

Mat3 leg_point_third_times(const LegPointCurvature& k, const Vec3& v) {
  const double aa = v[1] * v[1], ab = 2.0 * v[1] * v[2], bb = v[2] * v[2];
  Mat3 T;
  T.col(0).setZero();
  T.col(1) = k.p111 * aa + k.p112 * ab + k.p122 * bb;
  T.col(2) = k.p112 * aa + k.p122 * ab + k.p222 * bb;
  return T;
}

}  // namespace pkm
