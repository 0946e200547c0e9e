// SPDX-License-Identifier: BSD-2-Clause
// The four legs' velocities and accelerations as lanes from their
// closed-form positions (leg_position_lanes.hpp) and the platform's motion:
// A_i = [L_i^{-1}, L_i^{-1} (e_z x attach)], qd_i = A_i pd and
// qdd_i = A_i pdd + b_i (reduced_dynamics.hpp). Shared by the reduced
// inverse dynamics (inverse_lanes.cpp) and the regressor (regressor_lanes.cpp).
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/leg_position_lanes.hpp"

namespace pkm::lane_legs {

struct LegJacobian {
  using Pack = lanes::Pack;
  Pack l00, l01, l10, l11, l20, l21;  // L_i^{-1}'s first two columns (its third is e_0)
  Pack a03, a13, a23;                 // A_i's phi column
};

struct LegMotion : LegJacobian {
  Pack rd, t1d, t2d;     // qd_i
  Pack rdd, t1dd, t2dd;  // qdd_i
};

/// A_i's entries; A_rho's row i is (l00_i, l01_i, 1, a03_i).
PKM_LANES_INLINE LegJacobian leg_jacobian(const Model& m, const LegPosition<lanes::Pack>& lp) {
  using lanes::Pack;
  const Params& p = m.p;
  const Pack c1 = lp.c1, s1 = lp.s1, c2 = lp.c2, s2 = lp.s2, ax = lp.ax, ay = lp.ay;
  // L_i^{-1} = J_i^{-1} Rz(beta_i)^T in closed form (prepare_leg_kinematics).
  const double l = p.l, hp = p.h_prime;
  const Pack a = -l * s1 * c2 + hp * c1, b = l * c1 * c2 + hp * s1;
  const Pack e = -l * c1 * s2, f = -l * s1 * s2, g = l * c2;
  const Pack inv_D = 1.0 / (a * f - b * e);
  const Pack j00 = b * g * inv_D, j01 = -a * g * inv_D;
  const Pack j10 = f * inv_D, j11 = -e * inv_D;
  const Pack j20 = -b * inv_D, j21 = a * inv_D;
  const Pack cb = lanes::pack(m.cos_beta[0], m.cos_beta[1], m.cos_beta[2], m.cos_beta[3]);
  const Pack sb = lanes::pack(m.sin_beta[0], m.sin_beta[1], m.sin_beta[2], m.sin_beta[3]);
  LegJacobian o;
  o.l00 = cb * j00 - sb * j01, o.l10 = cb * j10 - sb * j11, o.l20 = cb * j20 - sb * j21;
  o.l01 = sb * j00 + cb * j01, o.l11 = sb * j10 + cb * j11, o.l21 = sb * j20 + cb * j21;
  // A_i = [L_i^{-1}, L_i^{-1} (e_z x attach)].
  o.a03 = o.l01 * ax - o.l00 * ay, o.a13 = o.l11 * ax - o.l10 * ay, o.a23 = o.l21 * ax - o.l20 * ay;
  return o;
}

/// qd_i and qdd_i of the platform motion (pd, pdd) from A_i (lj).
PKM_LANES_INLINE LegMotion leg_motion(const Model& m, const LegPosition<lanes::Pack>& lp, const LegJacobian& lj,
                                      const Pose& pd, const Pose& pdd) {
  using lanes::Pack;
  const Params& p = m.p;
  const Pack c1 = lp.c1, s1 = lp.s1, c2 = lp.c2, s2 = lp.s2, ax = lp.ax, ay = lp.ay;
  const double l = p.l, hp = p.h_prime;
  const Pack cb = lanes::pack(m.cos_beta[0], m.cos_beta[1], m.cos_beta[2], m.cos_beta[3]);
  const Pack sb = lanes::pack(m.sin_beta[0], m.sin_beta[1], m.sin_beta[2], m.sin_beta[3]);
  const Pack l00 = lj.l00, l01 = lj.l01, l10 = lj.l10, l11 = lj.l11, l20 = lj.l20, l21 = lj.l21;
  const Pack a03 = lj.a03, a13 = lj.a13, a23 = lj.a23;
  LegMotion o;
  static_cast<LegJacobian&>(o) = lj;
  // qd_i = A_i pd.
  const double phid = pd[3];
  const Pack rd = l00 * pd[0] + l01 * pd[1] + pd[2] + a03 * phid;
  const Pack t1d = l10 * pd[0] + l11 * pd[1] + a13 * phid;
  const Pack t2d = l20 * pd[0] + l21 * pd[1] + a23 * phid;
  // b_i = -L_i^{-1} gamma_i, gamma_i = Rz(beta_i) leg_point_quadratic + attach phid^2.
  const Pack q0 = (-l * c1 * c2 - hp * s1) * t1d * t1d + 2 * l * s1 * s2 * t1d * t2d - l * c1 * c2 * t2d * t2d;
  const Pack q1 = (-l * s1 * c2 + hp * c1) * t1d * t1d - 2 * l * c1 * s2 * t1d * t2d - l * s1 * c2 * t2d * t2d;
  const Pack q2 = -l * s2 * t2d * t2d;
  const double w2 = phid * phid;
  const Pack g0 = (cb * q0 - sb * q1) + ax * w2, g1 = (sb * q0 + cb * q1) + ay * w2;
  // qdd_i = A_i pdd + b_i.
  o.rdd = l00 * pdd[0] + l01 * pdd[1] + pdd[2] + a03 * pdd[3] - (l00 * g0 + l01 * g1 + q2);
  o.t1dd = l10 * pdd[0] + l11 * pdd[1] + a13 * pdd[3] - (l10 * g0 + l11 * g1);
  o.t2dd = l20 * pdd[0] + l21 * pdd[1] + a23 * pdd[3] - (l20 * g0 + l21 * g1);
  o.rd = rd, o.t1d = t1d, o.t2d = t2d;
  return o;
}

}  // namespace pkm::lane_legs
