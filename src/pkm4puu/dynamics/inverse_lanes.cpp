// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/inverse_lanes.hpp"

#include <cmath>
#include <algorithm>

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/leg_motion_lanes.hpp"
#include "pkm4puu/dynamics/leg_position_lanes.hpp"
#include "pkm4puu/machine/passive_force.hpp"


namespace pkm {
namespace {

using lanes::Pack;

// m ? a : b lane by lane.
PKM_LANES_INLINE Pack choose(const lanes::Mask& m, const Pack& a, const Pack& b) {
#if PKM_LANES_VECTOR_EXTENSIONS
  return (Pack)((m & (lanes::Mask)a) | (~m & (lanes::Mask)b));
#else
  Pack r;
  for (int i = 0; i < kLegs; ++i) r.v[i] = m.v[i] ? a.v[i] : b.v[i];
  return r;
#endif
}

// atan2(y, x) lane by lane for finite (x, y) != (0, 0), to about an ulp of
// pi: the ratio of the smaller to the larger magnitude in [0, 1], Cephes'
// atan there (a rational approximation of degree 4/5 in z = t^2 after the
// reduction t -> (t - 1)/(t + 1) above 0.66, with pi/4's lower bits), then
// the octant. No libm call: the legs' angles for four legs at once.
// kLowerRight: x >= +0 and y <= 0 in every lane (theta2 of the elbow-down
// branch), so the x < 0 branch never applies and y's sign is the result's:
// 0 - r is r's negative, and +0 for y = -0 as the general case's r = +0.
template <bool kLowerRight = false>
PKM_LANES_INLINE Pack atan2_lanes(const Pack& y, const Pack& x) {
  const Pack ay = lanes::abs(y), ax = lanes::abs(x);
  const auto steep = lanes::gt(ay - ax, 0.0);
  // t = num/den in [0, 1]; above 0.66 (t - 1)/(t + 1) = (num - den)/(num + den): one division either way.
  const Pack num = choose(steep, ax, ay), den = choose(steep, ay, ax);
  const auto upper = lanes::gt(num - 0.66 * den, 0.0);
  const Pack u = choose(upper, num - den, num) / choose(upper, num + den, den);
  const Pack z = u * u;
  const Pack P = (((-8.750608600031904122785e-1 * z - 1.615753718733365076637e1) * z - 7.500855792314704667340e1) * z -
                  1.228866684490136173410e2) * z - 6.485021904942025371773e1;
  const Pack Q = ((((z + 2.485846490142306297962e1) * z + 1.650270098316988542046e2) * z + 4.328810604912902668951e2) *
                      z + 4.853903996359136964868e2) * z + 1.945506571482613964425e2;
  const Pack w = u * (z * P / Q) + u;
  const lanes::Pack zero = lanes::broadcast(0.0);
  const double kPio4 = 0.78539816339744830962, kMoreBits = 6.123233995736765886130e-17;
  Pack r = choose(upper, w + 0.5 * kMoreBits + kPio4, w);                     // atan(t), t in [0, 1]
  r = choose(steep, (1.5707963267948966 - r) + kMoreBits, r);                // |y| > |x|
  if (kLowerRight) return zero - r;
  r = choose(lanes::lt(x, 0.0), (3.141592653589793 - r) + 2.0 * kMoreBits, r);  // x < 0
  return choose(lanes::lt(y, 0.0), zero - r, r);
}

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
// tau_i; their A_i^T tau_i summed, the platform's terms added and J_rho^T F
// = that solved. Unreachable before Singular, as the servo-constraint path.
template <bool kFull>
PKM_LANES_INLINE Status legs_inverse(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd,
                                     const Wrench& we, InverseDynamicsResult* full, InverseActuators* act) {
  const Params& p = m.p;
  const lane_legs::LegPosition<Pack> lp = lane_legs::leg_position(p, pc, lane_legs::lane_inputs(m));
  if (lanes::any(lp.out_of_reach)) return Status::Unreachable;
  const Pack c2 = lp.c2, s2 = lp.s2;
  if (lanes::any(lanes::lt(lanes::abs(c2 * s2), kLegSingularFloor))) return Status::Singular;
  if (kFull) {
    // The angles (q only) first, stored at once: their divisions and
    // polynomials then run beside the forces' work instead of after it (the
    // compiler would otherwise sink them to their use).
    // leg_inverse_kinematics' theta1 = atan2(qy, qx) + atan2(h', A) lies in
    // (-pi, 3 pi/2]: atan2(s1, c1) + 2 pi where that is below 0 and qy is not.
    const Pack th1 = atan2_lanes(lp.s1, lp.c1);
    const Pack th2 = atan2_lanes<true>(s2, c2);  // theta2 in [-pi/2, 0]: elbow-down, c2 >= 0 >= s2
    for (int i = 0; i < kLegs; ++i) {
      double t1 = lanes::lane(th1, i);
      if (!std::signbit(lanes::lane(lp.qy, i)) && t1 < 0.0) t1 += 6.283185307179586;
      full->q[leg_offset(i) + 1] = t1;
      full->q[leg_offset(i) + 2] = lanes::lane(th2, i);
    }
  }
  // A_i, qd_i, qdd_i (leg_motion_lanes.hpp).
  const lane_legs::LegMotion lm = lane_legs::leg_motion(m, lp, lane_legs::leg_jacobian(m, lp), pd, pdd);
  const Pack l00 = lm.l00, l01 = lm.l01, l10 = lm.l10, l11 = lm.l11, l20 = lm.l20, l21 = lm.l21;
  const Pack a03 = lm.a03, a13 = lm.a13, a23 = lm.a23;
  const Pack rd = lm.rd, t1d = lm.t1d, t2d = lm.t2d, rdd = lm.rdd, t1dd = lm.t1dd, t2dd = lm.t2dd;
  const double l = p.l, w2 = pd[3] * pd[3];
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
  // tau_i without the passive force: J_rho^T F = rhs - J_rho^T F_passive, so
  // the total force on rho_i, F_i + F_passive,i, comes from the system and
  // F_passive,i is subtracted from it alone. The multipliers then do not
  // see the passive forces at all (to the bit: they do not depend on z, dz).
  const Pack tau0 = m00 * rdd + m02 * t2dd + dM13 * t2d * t2d + G0;
  const Pack tau1 = m11 * t1dd + dM22 * t1d * t2d;
  const Pack tau2 = m02 * rdd + m22 * t2dd - 0.5 * dM22 * t1d * t1d + G2;
  // A_i^T tau_i summed over the legs; J_rho^T's columns (l00, l01, 1, a03).
  const Pack c[4] = {l00 * tau0 + l10 * tau1 + l20 * tau2, l01 * tau0 + l11 * tau1 + l21 * tau2, tau0,
                     a03 * tau0 + a13 * tau1 + a23 * tau2};
  double r[4];
  for (int n = 0; n < 4; ++n)
    r[n] = (lanes::lane(c[n], 0) + lanes::lane(c[n], 1)) + (lanes::lane(c[n], 2) + lanes::lane(c[n], 3));
  // The platform with its payload: M_p pdd + V_p + G_p - we (reduced_system's terms).
  const PlatformInertia pi = {m.platform_mass, m.platform_Izz, pc.cphi * m.payload_mx - pc.sphi * m.payload_my,
                              pc.sphi * m.payload_mx + pc.cphi * m.payload_my};  // platform_inertia
  Vec4 rhs;
  rhs[0] = r[0] + (pi.mass * pdd[0] - pi.mwy * pdd[3] - pi.mwx * w2 - we[0]);
  rhs[1] = r[1] + (pi.mass * pdd[1] + pi.mwx * pdd[3] - pi.mwy * w2 - we[1]);
  rhs[2] = r[2] + (pi.mass * pdd[2] + pi.mass * p.g - we[2]);
  rhs[3] = r[3] + (-pi.mwy * pdd[0] + pi.mwx * pdd[1] + pi.Izz * pdd[3] - we[3]);
  // J_rho^T F = rhs: J_rho^T's rows (l00_i), (l01_i), (1), (a03_i) over
  // the legs i. Eigen's closed-form 4x4 inverse (cofactors, vectorised), a
  // third of a pivoted LU's time and as good here: forward dynamics driven by
  // these F gives back pdd within 2e-14 along the auto-test path (the
  // general path's: 3e-14). At a parallel singularity it is not finite.
  double row[3][kLegs];
  Mat4 JrT;
  for (int j = 0; j < kLegs; ++j) {
    row[0][j] = lanes::lane(l00, j);
    row[1][j] = lanes::lane(l01, j);
    row[2][j] = lanes::lane(a03, j);
    JrT.col(j) << row[0][j], row[1][j], 1.0, row[2][j];
  }
  const Vec4 Ft = JrT.inverse() * rhs;  // F + F_passive
  const Pack passive = passive_lanes(p, lp.rho, rd);
  const Vec4 F(Ft[0] - lanes::lane(passive, 0), Ft[1] - lanes::lane(passive, 1), Ft[2] - lanes::lane(passive, 2),
               Ft[3] - lanes::lane(passive, 3));
  if (!F.allFinite()) return Status::Singular;
  const Pack rho = lp.rho;
  if (kFull) {
    InverseDynamicsResult& o = *full;
    // Leg i's rows of Eq. 1: lambda_i = L_i^{-T} ((F_i + F_passive,i) e_0 - tau_i) (Eq. 10).
    const Pack v0 = lanes::pack(Ft[0], Ft[1], Ft[2], Ft[3]) - tau0;
    const Pack lam0 = l00 * v0 - l10 * tau1 - l20 * tau2, lam1 = l01 * v0 - l11 * tau1 - l21 * tau2;
    for (int i = 0; i < kLegs; ++i) {
      const int at = leg_offset(i);
      o.q[at] = lanes::lane(rho, i);  // the angles are in place
      o.qd.segment<3>(at) << lanes::lane(rd, i), lanes::lane(t1d, i), lanes::lane(t2d, i);
      o.qdd.segment<3>(at) << lanes::lane(rdd, i), lanes::lane(t1dd, i), lanes::lane(t2dd, i);
      o.lambda.segment<3>(3 * i) << lanes::lane(lam0, i), lanes::lane(lam1, i), lanes::lane(v0, i);
    }
    o.q.segment<4>(kPlatform) = pc.pose;
    o.qd.segment<4>(kPlatform) = pd;
    o.qdd.segment<4>(kPlatform) = pdd;
    o.F = F;
    o.tau = F / m.drive_ratio;
    o.beyond_stops = stops_passed(p, Vec4(lanes::lane(rho, 0), lanes::lane(rho, 1), lanes::lane(rho, 2),
                                          lanes::lane(rho, 3)));
  } else {
    InverseActuators& o = *act;
    const Pack measure = lanes::abs(c2 * s2);
    o.leg_measure_min = 0.5;  // the largest |c2 s2| = |sin(2 theta2)| / 2
    for (int i = 0; i < kLegs; ++i) {
      o.rho[i] = lanes::lane(rho, i);
      o.rhod[i] = lanes::lane(rd, i);
      o.leg_measure[i] = lanes::lane(measure, i);
      o.leg_measure_min = std::min(o.leg_measure_min, o.leg_measure[i]);
    }
    for (int i = 0; i < kLegs; ++i) o.J_rho.row(i) << row[0][i], row[1][i], 1.0, row[2][i];
    o.F = F;
    o.tau = F / m.drive_ratio;
    o.beyond_stops = stops_passed(p, o.rho);
  }
  return Status::Ok;
}

template <bool kFull>
using InverseCopies = lanes::Copies<decltype(legs_inverse<kFull>), legs_inverse<kFull>>;

// Both entry points, inlined: the product's with `kind` the constant Best
// (only Model::avx is asked at run time), the tests' with the copy asked for.
PKM_LANES_INLINE Status inverse_entry(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd,
                                      const Wrench& we, InverseDynamicsResult* full, InverseActuators* act,
                                      lanes::Kernel kind) {
  if (!pose.allFinite() || !pd.allFinite() || !pdd.allFinite() || !we.allFinite()) return Status::NonFinite;
  PlatformConfig pc;
#if defined(__GLIBC__)
  // platform_config's cos and sin in one call (glibc's sincos: the same
  // values), which the FMU's link-time optimisation does not always fuse.
  pc.pose = pose;
  ::sincos(pose[3], &pc.sphi, &pc.cphi);
#else
  pc = platform_config(pose);
#endif
  if (full)
    return lanes::run<InverseCopies<true>>(kind, m.avx, Status::InvalidArgument, m, pc, pd, pdd, we, full, nullptr);
  return lanes::run<InverseCopies<false>>(kind, m.avx, Status::InvalidArgument, m, pc, pd, pdd, we, nullptr, act);
}

}  // namespace

Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseDynamicsResult* full, InverseActuators* act) {
  return inverse_entry(m, pose, pd, pdd, we, full, act, lanes::Kernel::Best);
}

Status reduced_inverse(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd, const Wrench& we,
                       InverseDynamicsResult* full, InverseActuators* act, lanes::Kernel kind) {
  return inverse_entry(m, pose, pd, pdd, we, full, act, kind);
}

}  // namespace pkm
