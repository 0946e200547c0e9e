// SPDX-License-Identifier: BSD-2-Clause
// The legs' lane kernel (internal to leg_lanes.cpp and
// leg_lanes_derivatives.cpp): one template for one leg (T = double) or the
// four legs as lanes (T = lanes::Pack), everything inlined into the
// translation unit that compiles it (with or without AVX).
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/leg_lanes.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/leg_position_lanes.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/model/model.hpp"

namespace pkm::leg_lanes_kernel {

// The legs' inputs and positions (leg_inverse_kinematics per lane) are the
// inverse dynamics' too: one definition, in leg_position_lanes.hpp.
using lane_legs::LegInputs;
using lane_legs::LegPosition;
using lane_legs::lane_inputs;
using lane_legs::leg_position;

// One leg (T = double) or the four legs as lanes (T = lanes::Pack): the
// arithmetic of leg_inverse_kinematics, prepare_leg_kinematics,
// leg_velocity and add_leg with the zeros and ones of J_i^{-1}, A_i and M_i
// written out, each expression in the same order (so the same bits lane by
// lane). `first` is the leg in lane 0.
template <class T>
struct LegContribution {
  T mr[10];  // A^T M A, upper triangle by rows: (0,0..3), (1,1..3), (2,2..3), (3,3)
  T rhs[4];  // A^T r
  T rho, rhod;
};

// What the derivatives' second pass (leg_lanes_derivatives.cpp) reuses of
// leg_contribution: the leg's angles, J_i^{-1} and A_i (their nonconstant
// entries), rates, b_i, r_i (applied and passive force included) and M_i.
template <class T>
struct LegKeep {
  T c1, s1, c2, s2, ax, ay;
  T j00, j01, j10, j11, j20, j21;  // J_i^{-1} rows (j_k0, j_k1, [k == 0])
  T l00, l01, l10, l11, l20, l21;  // L_i^{-1} rows (l_k0, l_k1, [k == 0])
  T a03, a13, a23;                 // A_i's column 3
  T qd0, qd1, qd2, b0, b1, b2, r0, r1, r2;
  T m02, m11;                      // M_i's nonconstant entries
};

// The passive joint force (friction, end stops) per lane: the scalar
// function itself (its tanh and branches), so the same bits; for the lanes
// its plain case written lane-wise.
PKM_LANES_INLINE double passive_force(const Params& p, int first, unsigned stops, double rho, double rhod) {
  return passive_joint_force(p, first, stops, rho, rhod);
}
PKM_LANES_INLINE lanes::Pack passive_force(const Params& p, int first, unsigned stops, const lanes::Pack& rho,
                                           const lanes::Pack& rhod) {
  // Without Coulomb friction and with no stop acting on any leg (all
  // within their travel, or none held): friction_force's -b rhod plus
  // stop_contact's 0.0, lane-wise, with no calls to spill around.
  if (p.friction_coulomb == 0.0 &&
      (stops == kStopsFromState
           ? !lanes::any(lanes::either(lanes::lt(rho, p.rho_min), lanes::gt(rho, p.rho_max)))
           : (stops & ((1u << (2 * kLegs)) - 1u)) == 0u))
    return -p.friction_viscous * rhod + 0.0;
  double F[lanes::kWidth];
  for (int i = 0; i < lanes::kWidth; ++i)
    F[i] = passive_joint_force(p, first + i, stops, lanes::lane(rho, i), lanes::lane(rhod, i));
  return lanes::pack(F[0], F[1], F[2], F[3]);
}

template <class T>
PKM_LANES_INLINE Status leg_contribution(const Model& m, int first, const PlatformConfig& pc, const Pose& pd,
                                         unsigned stops, const LegInputs<T>& in, LegContribution<T>& out,
                                         LegKeep<T>* keep = nullptr) {
  const Params& p = m.p;
  const LegPosition<T> lp = leg_position(p, pc, in);
  const T ax = lp.ax, ay = lp.ay, c1 = lp.c1, s1 = lp.s1, c2 = lp.c2, s2 = lp.s2, rho = lp.rho;
  const auto& out_of_reach = lp.out_of_reach;
  // leg_singularity_measure.
  const auto singular = lanes::lt(lanes::abs(c2 * s2), kLegSingularFloor);
  if (lanes::any(lanes::either(out_of_reach, singular))) {
    for (int i = 0; i < lanes::Traits<T>::width; ++i) {  // the first failing leg's status
      if (lanes::lane(out_of_reach, i)) return Status::Unreachable;
      if (lanes::lane(singular, i)) return Status::Singular;
    }
  }
  // prepare_leg_kinematics: J_i^{-1} (its third column is e_0) and
  // L_i^{-1} = J_i^{-1} Rz(beta_i)^T (third column e_0 too).
  const T a = -p.l * s1 * c2 + p.h_prime * c1, b = p.l * c1 * c2 + p.h_prime * s1;
  const T e = -p.l * c1 * s2, f = -p.l * s1 * s2, g = p.l * c2;
  const T inv_D = 1.0 / (a * f - b * e);
  const T j00 = b * g * inv_D, j01 = -a * g * inv_D;
  const T j10 = f * inv_D, j11 = -e * inv_D;
  const T j20 = -b * inv_D, j21 = a * inv_D;
  const T cb = in.cb, sb = in.sb;
  const T l00 = cb * j00 - sb * j01, l10 = cb * j10 - sb * j11, l20 = cb * j20 - sb * j21;
  const T l01 = sb * j00 + cb * j01, l11 = sb * j10 + cb * j11, l21 = sb * j20 + cb * j21;
  // A_i = [L_i^{-1}, L_i^{-1} (e_z x attach)]: rows (l_k0, l_k1, [k == 0], a_k3).
  const T a03 = l01 * ax - l00 * ay;
  const T a13 = l11 * ax - l10 * ay;
  const T a23 = l21 * ax - l20 * ay;
  // leg_velocity: qd_i = A_i pd.
  const double phid = pd[3];
  const T rd0 = l00 * pd[0] + l01 * pd[1] + pd[2] + a03 * phid;
  const T th1d = l10 * pd[0] + l11 * pd[1] + a13 * phid;
  const T th2d = l20 * pd[0] + l21 * pd[1] + a23 * phid;
  // add_leg: gamma = Rz(beta_i) leg_point_quadratic + attach phid^2.
  const double l = p.l, hp = p.h_prime;
  const T q0 = (-l * c1 * c2 - hp * s1) * th1d * th1d + 2 * l * s1 * s2 * th1d * th2d - l * c1 * c2 * th2d * th2d;
  const T q1 = (-l * s1 * c2 + hp * c1) * th1d * th1d - 2 * l * c1 * s2 * th1d * th2d - l * s1 * c2 * th2d * th2d;
  const T q2 = -l * s2 * th2d * th2d;
  const double w2 = phid * phid;
  const T gamma0 = (cb * q0 - sb * q1) + ax * w2;
  const T gamma1 = (sb * q0 + cb * q1) + ay * w2;
  const T gamma2 = q2 + 0.0 * w2;
  const T b0 = -(l00 * gamma0 + l01 * gamma1 + gamma2);
  const T b1 = -(l10 * gamma0 + l11 * gamma1);
  const T b2 = -(l20 * gamma0 + l21 * gamma1);
  // leg_mass_matrix (M01 = M12 = 0), leg_coriolis, leg_gravity.
  const double mr = p.m_rod;
  const double m00 = p.m_slider + mr + m.reflected_mass;
  const T m02 = 0.5 * mr * l * c2;
  const T m11 = 0.25 * mr * l * l * c2 * c2 + p.I_rod[0] * s2 * s2 + p.I_rod[1] * c2 * c2;
  const double m22 = 0.25 * mr * l * l + p.I_rod[2];
  const T dM13 = -0.5 * p.m_rod * p.l * s2;  // leg_mass_slopes
  const double k = p.I_rod[0] - p.I_rod[1] - 0.25 * p.m_rod * p.l * p.l;
  const T dM22 = 2.0 * k * s2 * c2;
  const T V0 = dM13 * th2d * th2d, V1 = dM22 * th1d * th2d, V2 = -0.5 * dM22 * th1d * th1d;
  const double G0 = (p.m_slider + p.m_rod) * p.g;
  const T G2 = 0.5 * p.m_rod * p.g * p.l * c2;
  const T F = in.f_rho + passive_force(p, first, stops, rho, rd0);
  const T r0 = F - V0 - G0 - (m00 * b0 + m02 * b2);
  const T r1 = -V1 - m11 * b1;
  const T r2_ = -V2 - G2 - (m02 * b0 + m22 * b2);
  // A^T M A, upper triangle; M A's rows, with A's column 2 = e_0.
  const T one = lanes::Traits<T>::constant(1.0), zero = lanes::Traits<T>::constant(0.0);
  const T Am[3][4] = {{l00, l01, one, a03}, {l10, l11, zero, a13}, {l20, l21, zero, a23}};
  T MA[3][4];
  for (int c = 0; c < 4; ++c) {
    MA[0][c] = m00 * Am[0][c] + m02 * Am[2][c];
    MA[1][c] = m11 * Am[1][c];
    MA[2][c] = m02 * Am[0][c] + m22 * Am[2][c];
  }
  int n = 0;
  for (int j = 0; j < 4; ++j) {
    for (int c = j; c < 4; ++c, ++n) {
      if (j == 2) {  // A's column 2 is e_0
        out.mr[n] = MA[0][c];
        continue;
      }
      out.mr[n] = Am[0][j] * MA[0][c] + Am[1][j] * MA[1][c] + Am[2][j] * MA[2][c];
    }
  }
  out.rhs[0] = l00 * r0 + l10 * r1 + l20 * r2_;
  out.rhs[1] = l01 * r0 + l11 * r1 + l21 * r2_;
  out.rhs[2] = r0;
  out.rhs[3] = a03 * r0 + a13 * r1 + a23 * r2_;
  out.rho = rho;
  out.rhod = rd0;
  if (keep) *keep = {c1,  s1,  c2,  s2,  ax,  ay,  j00, j01, j10, j11, j20, j21, l00, l01, l10, l11,
                     l20, l21, a03, a13, a23, rd0, th1d, th2d, b0, b1, b2, r0, r1, r2_, m02, m11};
  return Status::Ok;
}

inline LegInputs<double> leg_inputs(const Model& m, int leg, double f_rho) {
  return {m.B[leg].x(), m.B[leg].y(), m.B[leg].z(), m.cos_beta[leg], m.sin_beta[leg],
          m.r_Q[leg].x(), m.r_Q[leg].y(), f_rho};
}

// The four lanes' contributions summed in leg order ((0 + leg 0) + leg 1)
// + ..., as the scalar accumulation does.
PKM_LANES_INLINE void sum_lanes(const LegContribution<lanes::Pack>& c, LegSums& sums) {
  for (int n = 0; n < 10; ++n)
    sums.mr[n] = (((0.0 + lanes::lane(c.mr[n], 0)) + lanes::lane(c.mr[n], 1)) + lanes::lane(c.mr[n], 2)) +
                 lanes::lane(c.mr[n], 3);
  for (int n = 0; n < 4; ++n)
    sums.rhs[n] = (((0.0 + lanes::lane(c.rhs[n], 0)) + lanes::lane(c.rhs[n], 1)) + lanes::lane(c.rhs[n], 2)) +
                  lanes::lane(c.rhs[n], 3);
  for (int i = 0; i < kLegs; ++i) {
    sums.rho[i] = lanes::lane(c.rho, i);
    sums.rhod[i] = lanes::lane(c.rhod, i);
  }
}

// The four legs one at a time (the Scalar copies), summed as above; keep
// (if given) receives each leg's LegKeep. The first failing leg's status.
inline Status legs_one_at_a_time(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f,
                                 unsigned stops, LegSums& sums, LegKeep<double>* keep = nullptr) {
  for (double& x : sums.mr) x = 0.0;
  for (double& x : sums.rhs) x = 0.0;
  for (int i = 0; i < kLegs; ++i) {
    LegContribution<double> c;
    const Status s =
        leg_contribution(m, i, pc, pd, stops, leg_inputs(m, i, f[leg_offset(i)]), c, keep ? keep + i : nullptr);
    if (s != Status::Ok) return s;
    for (int n = 0; n < 10; ++n) sums.mr[n] += c.mr[n];
    for (int n = 0; n < 4; ++n) sums.rhs[n] += c.rhs[n];
    sums.rho[i] = c.rho;
    sums.rhod[i] = c.rhod;
  }
  return Status::Ok;
}

}  // namespace pkm::leg_lanes_kernel
