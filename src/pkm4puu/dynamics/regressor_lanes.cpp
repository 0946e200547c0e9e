// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/regressor_lanes.hpp"

#include <cmath>
#include <cstring>

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/leg_motion_lanes.hpp"
#include "pkm4puu/dynamics/leg_position_lanes.hpp"
#include "pkm4puu/machine/end_stops.hpp"

namespace pkm {
namespace {

using lanes::Pack;

/// The sums over the legs (lanes) of a, b, c, d as one pack, each in the
/// inverse dynamics' order (x0 + x1) + (x2 + x3): a 4x4 transpose by pair sums.
PKM_LANES_INLINE Pack regressor_leg_sums(const Pack& a, const Pack& b, const Pack& c, const Pack& d) {
#if PKM_LANES_VECTOR_EXTENSIONS
  const Pack ab = __builtin_shufflevector(a, b, 0, 4, 2, 6) + __builtin_shufflevector(a, b, 1, 5, 3, 7);
  const Pack cd = __builtin_shufflevector(c, d, 0, 4, 2, 6) + __builtin_shufflevector(c, d, 1, 5, 3, 7);
  return __builtin_shufflevector(ab, cd, 0, 1, 4, 5) + __builtin_shufflevector(ab, cd, 2, 3, 6, 7);
#else
  auto sum = [](const Pack& x) {
    return (lanes::lane(x, 0) + lanes::lane(x, 1)) + (lanes::lane(x, 2) + lanes::lane(x, 3));
  };
  return lanes::pack(sum(a), sum(b), sum(c), sum(d));
#endif
}

using RegressorZ = Eigen::Matrix<double, 4, kParams - 2>;  // B^T D for pi's entries before the friction's

/// Column j of Z = sum_i A_i^T D_i from D_i's column (d0, d1, d2) per leg.
PKM_LANES_INLINE void regressor_leg_column(const lane_legs::LegMotion& lm, const Pack& d0, const Pack& d1,
                                          const Pack& d2, RegressorZ& Z, int j) {
  const Pack col = regressor_leg_sums(lm.l00 * d0 + lm.l10 * d1 + lm.l20 * d2, lm.l01 * d0 + lm.l11 * d1 + lm.l21 * d2,
                                      d0, lm.a03 * d0 + lm.a13 * d1 + lm.a23 * d2);
  std::memcpy(Z.col(j).data(), &col, 4 * sizeof(double));
}

/// The legs at pc (closed form, elbow-down): Unreachable before Singular.
PKM_LANES_INLINE Status regressor_legs_at(const Model& m, const PlatformConfig& pc, lane_legs::LegPosition<Pack>& lp) {
  lp = lane_legs::leg_position(m.p, pc, lane_legs::lane_inputs(m));
  if (lanes::any(lp.out_of_reach)) return Status::Unreachable;
  if (lanes::any(lanes::lt(lanes::abs(lp.c2 * lp.s2), kLegSingularFloor))) return Status::Singular;
  return Status::Ok;
}

/// J_rho^T (A_rho's rows (l00_i, l01_i, 1, a03_i) as columns).
PKM_LANES_INLINE Mat4 regressor_jrho_transpose(const lane_legs::LegJacobian& lj) {
  Mat4 JrT;
  for (int j = 0; j < kLegs; ++j)
    JrT.col(j) << lanes::lane(lj.l00, j), lanes::lane(lj.l01, j), 1.0, lanes::lane(lj.a03, j);
  return JrT;
}

/// (R2) from the legs' positions and motion.
PKM_LANES_INLINE Status regressor_columns(const Model& m, const PlatformConfig& pc,
                                          const lane_legs::LegPosition<Pack>& lp, const lane_legs::LegMotion& lm,
                                          const Pose& pd, const Pose& pdd, const Wrench& we, RegressorSample& out) {
  const Params& p = m.p;
  const Pack c2 = lp.c2, s2 = lp.s2;
  const Pack rdd = lm.rdd, t1dd = lm.t1dd, t2dd = lm.t2dd, t1d = lm.t1d, t2d = lm.t2d;
  // D_i: the leg's rows of M qdd + V + G per parameter (lagrangian.hpp's
  // M_leg, leg_coriolis, leg_gravity differentiated in each parameter).
  const double g = p.g, l = p.l, k2 = m.drive_ratio * m.drive_ratio;
  const Pack zero = lanes::broadcast(0.0);
  const Pack sc = s2 * c2, cc = c2 * c2, w11 = t1d * t1d, w12 = 2.0 * sc * t1d * t2d;
  const Pack rg = rdd + g;
  RegressorZ Z;
  regressor_leg_column(lm, rg, zero, zero, Z, kPiSlider);
  regressor_leg_column(lm, rg + 0.5 * l * (c2 * t2dd - s2 * t2d * t2d), 0.25 * l * l * (cc * t1dd - w12),
                       0.5 * l * c2 * rg + 0.25 * l * l * (t2dd + sc * w11), Z, kPiRod);
  regressor_leg_column(lm, zero, s2 * s2 * t1dd + w12, zero - sc * w11, Z, kPiRodIx);
  regressor_leg_column(lm, zero, cc * t1dd - w12, sc * w11, Z, kPiRodIy);
  regressor_leg_column(lm, zero, zero, t2dd, Z, kPiRodIz);
  regressor_leg_column(lm, k2 * rdd, zero, zero, Z, kPiRotor);
  // The platform with its payload (lagrangian.hpp's M_p and V_p per parameter).
  const double c = pc.cphi, s = pc.sphi, w2 = pd[3] * pd[3];
  const Vec4 translational(pdd[0], pdd[1], pdd[2] + g, 0.0);
  Z.col(kPiPlatform) = translational;
  Z.col(kPiPayload) = translational;
  Z.col(kPiPlatformIzz) << 0.0, 0.0, 0.0, pdd[3];
  Z.col(kPiPayloadIzzP) << 0.0, 0.0, 0.0, pdd[3];
  Z.col(kPiPayloadMx) << -s * pdd[3] - c * w2, c * pdd[3] - s * w2, 0.0, -s * pdd[0] + c * pdd[1];
  Z.col(kPiPayloadMy) << -c * pdd[3] + s * w2, -s * pdd[3] - c * w2, 0.0, -c * pdd[0] - s * pdd[1];
  // J_rho^T Y = Z with J_rho^T's rows (l00_i), (l01_i), (1), (a03_i): the
  // closed-form 4x4 inverse as the inverse dynamics; not finite at a
  // parallel singularity.
  const Mat4 Jinv = regressor_jrho_transpose(lm).inverse();
  out.Y.leftCols<kParams - 2>().noalias() = Jinv * Z;
  out.F0.noalias() = -(Jinv * we);
  for (int i = 0; i < kLegs; ++i) {
    const double rhod = lanes::lane(lm.rd, i);
    out.rho[i] = lanes::lane(lp.rho, i);
    out.rhod[i] = rhod;
    // F = ... - F_fric - F_stop with F_fric = -b rhod - F_c tanh(rhod / v_s) (friction.hpp).
    out.Y(i, kPiViscous) = rhod;
    out.Y(i, kPiCoulomb) = std::tanh(rhod / p.friction_velocity);
  }
  out.beyond_stops = stops_passed(p, out.rho);
  if (out.beyond_stops != 0)  // F_stop is 0 within the travel
    for (int i = 0; i < kLegs; ++i) out.F0[i] -= stop_force(p, out.rho[i], out.rhod[i]);
  out.pose_d = pd;
  out.pose_dd = pdd;
  // One check for all 60 entries: a non-finite entry makes the sum non-finite
  // (Inf - Inf and NaN propagate); finite entries near 1e308 would too.
  return std::isfinite(out.Y.sum() + out.F0.sum()) ? Status::Ok : Status::Singular;
}

PKM_LANES_INLINE Status legs_regressor(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd,
                                       const Wrench& we, RegressorSample& out) {
  lane_legs::LegPosition<Pack> lp;
  const Status s = regressor_legs_at(m, pc, lp);
  if (s != Status::Ok) return s;
  const lane_legs::LegMotion lm = lane_legs::leg_motion(m, lp, lane_legs::leg_jacobian(m, lp), pd, pdd);
  return regressor_columns(m, pc, lp, lm, pd, pdd, we, out);
}

// rhod = A_rho pd; rhodd = A_rho pdd + b_rho (b_i's rho rows: qdd_i at pdd = 0).
PKM_LANES_INLINE Status legs_joint_regressor(const Model& m, const PlatformConfig& pc, const Vec4& rhod,
                                             const Vec4& rhodd, const Wrench& we, RegressorSample& out) {
  lane_legs::LegPosition<Pack> lp;
  const Status s = regressor_legs_at(m, pc, lp);
  if (s != Status::Ok) return s;
  const lane_legs::LegJacobian lj = lane_legs::leg_jacobian(m, lp);
  const Mat4 Ainv = regressor_jrho_transpose(lj).transpose().inverse();
  const Pose pd = Ainv * rhod;
  const Pack b_rho = lane_legs::leg_motion(m, lp, lj, pd, Pose::Zero()).rdd;
  const Pose pdd = Ainv * (rhodd - Vec4(lanes::lane(b_rho, 0), lanes::lane(b_rho, 1), lanes::lane(b_rho, 2),
                                        lanes::lane(b_rho, 3)));
  if (!pd.allFinite() || !pdd.allFinite()) return Status::Singular;
  return regressor_columns(m, pc, lp, lane_legs::leg_motion(m, lp, lj, pd, pdd), pd, pdd, we, out);
}

PKM_LANES_INLINE Status legs_sliders(const Model& m, const PlatformConfig& pc, Vec4& rho, Mat4& Arho) {
  lane_legs::LegPosition<Pack> lp;
  const Status s = regressor_legs_at(m, pc, lp);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) rho[i] = lanes::lane(lp.rho, i);
  Arho = regressor_jrho_transpose(lane_legs::leg_jacobian(m, lp)).transpose();
  return Status::Ok;
}

using RegressorCopies = lanes::Copies<decltype(legs_regressor), legs_regressor>;
using JointCopies = lanes::Copies<decltype(legs_joint_regressor), legs_joint_regressor>;
using SlidersCopies = lanes::Copies<decltype(legs_sliders), legs_sliders>;

}  // namespace

Status regressor_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd, const Wrench& we,
                       RegressorSample& out) {
  return lanes::run<RegressorCopies>(lanes::Kernel::Best, m.avx, Status::InvalidArgument, m, pc, pd, pdd, we, out);
}
Status regressor_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd, const Wrench& we,
                       RegressorSample& out, lanes::Kernel kind) {
  return lanes::run<RegressorCopies>(kind, m.avx, Status::InvalidArgument, m, pc, pd, pdd, we, out);
}

Status joint_regressor_lanes(const Model& m, const PlatformConfig& pc, const Vec4& rhod, const Vec4& rhodd,
                             const Wrench& we, RegressorSample& out) {
  return lanes::run<JointCopies>(lanes::Kernel::Best, m.avx, Status::InvalidArgument, m, pc, rhod, rhodd, we, out);
}
Status joint_regressor_lanes(const Model& m, const PlatformConfig& pc, const Vec4& rhod, const Vec4& rhodd,
                             const Wrench& we, RegressorSample& out, lanes::Kernel kind) {
  return lanes::run<JointCopies>(kind, m.avx, Status::InvalidArgument, m, pc, rhod, rhodd, we, out);
}

Status slider_positions_lanes(const Model& m, const PlatformConfig& pc, Vec4& rho, Mat4& Arho) {
  return lanes::run<SlidersCopies>(lanes::Kernel::Best, m.avx, Status::InvalidArgument, m, pc, rho, Arho);
}
Status slider_positions_lanes(const Model& m, const PlatformConfig& pc, Vec4& rho, Mat4& Arho, lanes::Kernel kind) {
  return lanes::run<SlidersCopies>(kind, m.avx, Status::InvalidArgument, m, pc, rho, Arho);
}

}  // namespace pkm
