// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/inverse_lanes.hpp"

#include <cmath>
#include <cstring>
#include <utility>

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/leg_position_lanes.hpp"
#include "pkm4puu/machine/passive_force.hpp"

// An AVX variant beside the baseline where leg_lanes.cpp has one (the same
// condition; its comment says why not on Windows).
#if PKM_LANES_VECTOR_EXTENSIONS && defined(__x86_64__) && !defined(_WIN32) && !defined(__AVX__)
#define PKM_INVERSE_AVX_DISPATCH 1
#else
#define PKM_INVERSE_AVX_DISPATCH 0
#endif

namespace pkm {
namespace {

using lanes::Pack;

PKM_LANES_INLINE void put(double* dst, const Pack& v) { std::memcpy(dst, &v, sizeof(double) * kLegs); }

// The joints' passive forces (friction, a stop beyond it), as
// actuator_forces takes them: lane-wise in the plain case (no Coulomb
// friction, every slider within its travel), else the scalar function per lane.
PKM_LANES_INLINE Pack passive_lanes(const Params& p, const Pack& rho, const Pack& rhod) {
  if (p.friction_coulomb == 0.0 && !lanes::any(lanes::either(lanes::lt(rho, p.rho_min), lanes::gt(rho, p.rho_max))))
    return -p.friction_viscous * rhod + 0.0;
  double F[kLegs];
  for (int i = 0; i < kLegs; ++i) F[i] = passive_joint_force(p, lanes::lane(rho, i), lanes::lane(rhod, i));
  return lanes::pack(F[0], F[1], F[2], F[3]);
}

// The four legs as lanes: inverse kinematics, A_i's rows, qd_i, qdd_i,
// tau_i; their A_i^T tau_i summed into r and J_rho's rows into J (J_rho^T
// by columns). Unreachable before Singular, as the servo-constraint path.
PKM_LANES_INLINE Status legs_inverse(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd,
                                     InverseLegs& out, double r[4], double Jt[4][kLegs]) {
  const Params& p = m.p;
  const lane_legs::LegPosition<Pack> lp = lane_legs::leg_position(p, pc, lane_legs::lane_inputs(m));
  if (lanes::any(lp.out_of_reach)) return Status::Unreachable;
  const Pack c1 = lp.c1, s1 = lp.s1, c2 = lp.c2, s2 = lp.s2, ax = lp.ax, ay = lp.ay;
  if (lanes::any(lanes::lt(lanes::abs(c2 * s2), kLegSingularFloor))) return Status::Singular;
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
  const Pack l00 = cb * j00 - sb * j01, l10 = cb * j10 - sb * j11, l20 = cb * j20 - sb * j21;
  const Pack l01 = sb * j00 + cb * j01, l11 = sb * j10 + cb * j11, l21 = sb * j20 + cb * j21;
  // A_i = [L_i^{-1}, L_i^{-1} (e_z x attach)].
  const Pack a03 = l01 * ax - l00 * ay, a13 = l11 * ax - l10 * ay, a23 = l21 * ax - l20 * ay;
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
  const Pack rdd = l00 * pdd[0] + l01 * pdd[1] + pdd[2] + a03 * pdd[3] - (l00 * g0 + l01 * g1 + q2);
  const Pack t1dd = l10 * pdd[0] + l11 * pdd[1] + a13 * pdd[3] - (l10 * g0 + l11 * g1);
  const Pack t2dd = l20 * pdd[0] + l21 * pdd[1] + a23 * pdd[3] - (l20 * g0 + l21 * g1);
  // tau_i = M_i qdd_i + V_i + G_i - F_passive e_0 (leg_mass_matrix with the
  // rotor, leg_coriolis, leg_gravity; M01 = M12 = 0).
  const double m00 = p.m_slider + p.m_rod + m.reflected_mass, m22 = 0.25 * p.m_rod * l * l + p.I_rod[2];
  const Pack m02 = 0.5 * p.m_rod * l * c2;
  const Pack m11 = 0.25 * p.m_rod * l * l * c2 * c2 + p.I_rod[0] * s2 * s2 + p.I_rod[1] * c2 * c2;
  const Pack dM13 = -0.5 * p.m_rod * l * s2;
  const double k = p.I_rod[0] - p.I_rod[1] - 0.25 * p.m_rod * l * l;
  const Pack dM22 = 2.0 * k * s2 * c2;
  const double G0 = (p.m_slider + p.m_rod) * p.g;
  const Pack G2 = 0.5 * p.m_rod * p.g * l * c2;
  const Pack tau0 = m00 * rdd + m02 * t2dd + dM13 * t2d * t2d + G0 - passive_lanes(p, lp.rho, rd);
  const Pack tau1 = m11 * t1dd + dM22 * t1d * t2d;
  const Pack tau2 = m02 * rdd + m22 * t2dd - 0.5 * dM22 * t1d * t1d + G2;
  // A_i^T tau_i summed over the legs; J_rho^T's columns (l00, l01, 1, a03).
  const Pack c[4] = {l00 * tau0 + l10 * tau1 + l20 * tau2, l01 * tau0 + l11 * tau1 + l21 * tau2, tau0,
                     a03 * tau0 + a13 * tau1 + a23 * tau2};
  for (int n = 0; n < 4; ++n)
    r[n] = (lanes::lane(c[n], 0) + lanes::lane(c[n], 1)) + (lanes::lane(c[n], 2) + lanes::lane(c[n], 3));
  put(Jt[0], l00);
  put(Jt[1], l01);
  put(Jt[3], a03);
  put(out.a03, a03);
  put(out.rho, lp.rho);
  put(out.rhod, rd);
  put(out.rhodd, rdd);
  put(out.th1d, t1d);
  put(out.th1dd, t1dd);
  put(out.th2d, t2d);
  put(out.th2dd, t2dd);
  put(out.qx, lp.qx);
  put(out.qy, lp.qy);
  put(out.A, lp.A);
  put(out.c2, c2);
  put(out.s2, s2);
  const Pack L[6] = {l00, l01, l10, l11, l20, l21};
  for (int n = 0; n < 6; ++n) put(out.linv[n], L[n]);
  put(out.tau[0], tau0);
  put(out.tau[1], tau1);
  put(out.tau[2], tau2);
  return Status::Ok;
}

// a x = b for a 4x4 (overwritten) by Gaussian elimination with partial
// pivoting, written out (b in x); false for a zero pivot.
bool solve4(double a[4][kLegs], double x[4]) {
  for (int k = 0; k < 4; ++k) {
    int piv = k;
    for (int i = k + 1; i < 4; ++i)
      if (std::fabs(a[i][k]) > std::fabs(a[piv][k])) piv = i;
    if (!(std::fabs(a[piv][k]) > 0.0)) return false;  // also NaN
    if (piv != k) {
      for (int j = k; j < 4; ++j) std::swap(a[k][j], a[piv][j]);
      std::swap(x[k], x[piv]);
    }
    const double inv = 1.0 / a[k][k];
    for (int i = k + 1; i < 4; ++i) {
      const double f = a[i][k] * inv;
      for (int j = k + 1; j < 4; ++j) a[i][j] -= f * a[k][j];
      x[i] -= f * x[k];
    }
  }
  for (int i = 3; i >= 0; --i) {
    for (int j = i + 1; j < 4; ++j) x[i] -= a[i][j] * x[j];
    x[i] /= a[i][i];
  }
  return true;
}

Status legs_generic(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd, InverseLegs& out,
                    double r[4], double Jt[4][kLegs]) {
  return legs_inverse(m, pc, pd, pdd, out, r, Jt);
}

#if PKM_INVERSE_AVX_DISPATCH
__attribute__((target("avx"))) Status legs_avx(const Model& m, const PlatformConfig& pc, const Pose& pd,
                                               const Pose& pdd, InverseLegs& out, double r[4], double Jt[4][kLegs]) {
  return legs_inverse(m, pc, pd, pdd, out, r, Jt);
}
#endif

}  // namespace

Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseLegs& legs, Vec4& F) {
  if (!pose.allFinite() || !pd.allFinite() || !pdd.allFinite() || !we.allFinite()) return Status::NonFinite;
  const PlatformConfig pc = platform_config(pose);
  double r[4], Jt[4][kLegs];
#if PKM_INVERSE_AVX_DISPATCH
  const Status s = m.avx ? legs_avx(m, pc, pd, pdd, legs, r, Jt) : legs_generic(m, pc, pd, pdd, legs, r, Jt);
#else
  const Status s = legs_generic(m, pc, pd, pdd, legs, r, Jt);
#endif
  if (s != Status::Ok) return s;
  // The platform with its payload: M_p pdd + V_p + G_p - we (reduced_system's terms).
  const PlatformInertia pi = platform_inertia(m, pc.cphi, pc.sphi);
  const double w2 = pd[3] * pd[3];
  Vec4 rhs;
  rhs[0] = r[0] + (pi.mass * pdd[0] - pi.mwy * pdd[3] - pi.mwx * w2 - we[0]);
  rhs[1] = r[1] + (pi.mass * pdd[1] + pi.mwx * pdd[3] - pi.mwy * w2 - we[1]);
  rhs[2] = r[2] + (pi.mass * pdd[2] + pi.mass * m.p.g - we[2]);
  rhs[3] = r[3] + (-pi.mwy * pdd[0] + pi.mwx * pdd[1] + pi.Izz * pdd[3] - we[3]);
  Jt[2][0] = Jt[2][1] = Jt[2][2] = Jt[2][3] = 1.0;
  double x[4] = {rhs[0], rhs[1], rhs[2], rhs[3]};
  if (!solve4(Jt, x)) return Status::Singular;  // a parallel singularity
  F = Vec4(x[0], x[1], x[2], x[3]);
  return F.allFinite() ? Status::Ok : Status::Singular;
}

void reduced_inverse_lambda(const InverseLegs& g, const Vec4& F, Vec12& lambda) {
  for (int i = 0; i < kLegs; ++i) {
    const double v0 = F[i] - g.tau[0][i], v1 = -g.tau[1][i], v2 = -g.tau[2][i];
    lambda[3 * i] = g.linv[0][i] * v0 + g.linv[2][i] * v1 + g.linv[4][i] * v2;
    lambda[3 * i + 1] = g.linv[1][i] * v0 + g.linv[3][i] * v1 + g.linv[5][i] * v2;
    lambda[3 * i + 2] = v0;
  }
}

void reduced_inverse_angles(const InverseLegs& g, const Params& p, int i, double& theta1, double& theta2) {
  theta1 = std::atan2(g.qy[i], g.qx[i]) + std::atan2(p.h_prime, g.A[i]);
  theta2 = -std::acos(g.c2[i]);
}

}  // namespace pkm
