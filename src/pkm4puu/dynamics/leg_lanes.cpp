// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/leg_lanes.hpp"
#include "pkm4puu/dynamics/leg_lanes_kernel.hpp"

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/machine/passive_force.hpp"


namespace pkm {
namespace {

using namespace leg_lanes_kernel;


// The four legs' actuator positions as lanes; on failure the first failing
// leg's status (Unreachable, as leg_inverse_kinematics leg by leg), rho untouched.
PKM_LANES_INLINE Status positions_as_lanes(const Model& m, const PlatformConfig& pc, Vec4& rho) {
  const LegPosition<lanes::Pack> lp = leg_position(m.p, pc, lane_inputs(m));
  if (lanes::any(lp.out_of_reach)) return Status::Unreachable;
  for (int i = 0; i < kLegs; ++i) rho[i] = lanes::lane(lp.rho, i);
  return Status::Ok;
}

Status positions_scalar(const Model& m, const PlatformConfig& pc, Vec4& rho) {
  Vec4 r;
  for (int i = 0; i < kLegs; ++i) {
    const LegPosition<double> lp = leg_position(m.p, pc, leg_inputs(m, i, 0.0));
    if (lp.out_of_reach) return Status::Unreachable;
    r[i] = lp.rho;
  }
  rho = r;
  return Status::Ok;
}

Status positions_baseline(const Model& m, const PlatformConfig& pc, Vec4& rho) {
  return positions_as_lanes(m, pc, rho);
}

// The four legs as lanes, their contributions summed in leg order
// ((0 + leg 0) + leg 1) + ... as the scalar accumulation does.
PKM_LANES_INLINE Status legs_as_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f,
                                      unsigned stops, LegSums& sums) {
  LegInputs<lanes::Pack> in = lane_inputs(m);
  in.f_rho = lanes::pack(f[leg_offset(0)], f[leg_offset(1)], f[leg_offset(2)], f[leg_offset(3)]);
  LegContribution<lanes::Pack> c;
  const Status s = leg_contribution(m, 0, pc, pd, stops, in, c);
  if (s != Status::Ok) return s;
  sum_lanes(c, sums);
  return Status::Ok;
}

Status legs_scalar(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                   LegSums& sums) {
  for (double& x : sums.mr) x = 0.0;
  for (double& x : sums.rhs) x = 0.0;
  for (int i = 0; i < kLegs; ++i) {
    LegContribution<double> c;
    const Status s = leg_contribution(m, i, pc, pd, stops, leg_inputs(m, i, f[leg_offset(i)]), c);
    if (s != Status::Ok) return s;
    for (int n = 0; n < 10; ++n) sums.mr[n] += c.mr[n];
    for (int n = 0; n < 4; ++n) sums.rhs[n] += c.rhs[n];
    sums.rho[i] = c.rho;
    sums.rhod[i] = c.rhod;
  }
  return Status::Ok;
}

Status legs_baseline(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                    LegSums& sums) {
  return legs_as_lanes(m, pc, pd, f, stops, sums);
}

#if PKM_LANES_AVX_DISPATCH
// The same source compiled for AVX (no FMA: no contraction, the same bits).
PKM_LANES_AVX_TARGET Status legs_avx(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f,
                                     unsigned stops, LegSums& sums) {
  return legs_as_lanes(m, pc, pd, f, stops, sums);
}
PKM_LANES_AVX_TARGET Status positions_avx(const Model& m, const PlatformConfig& pc, Vec4& rho) {
  return positions_as_lanes(m, pc, rho);
}
#endif

}  // namespace

Status leg_sums(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                LegSums& sums, lanes::Kernel kind) {
  return lanes::run<legs_scalar, legs_baseline, PKM_LANES_AVX_COPY(legs_avx)>(kind, m.avx, Status::InvalidArgument, m,
                                                                             pc, pd, f, stops, sums);
}

Status lane_actuator_positions(const Model& m, const PlatformConfig& pc, Vec4& rho, lanes::Kernel kind) {
  return lanes::run<positions_scalar, positions_baseline, PKM_LANES_AVX_COPY(positions_avx)>(
      kind, m.avx, Status::InvalidArgument, m, pc, rho);
}

Status actuator_positions(const Model& m, const Pose& pose, Vec4& rho) {
  if (!pose.allFinite()) return Status::NonFinite;
  return lane_actuator_positions(m, platform_config(pose), rho);
}

}  // namespace pkm
