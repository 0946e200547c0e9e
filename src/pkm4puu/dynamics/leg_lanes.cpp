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
  return legs_one_at_a_time(m, pc, pd, f, stops, sums);
}

using LegsCopies = lanes::Copies<decltype(legs_as_lanes), legs_as_lanes>;
using PositionsCopies = lanes::Copies<decltype(positions_as_lanes), positions_as_lanes>;

}  // namespace

Status leg_sums(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                LegSums& sums, lanes::Kernel kind) {
  return lanes::run<LegsCopies, legs_scalar>(kind, m.avx, Status::InvalidArgument, m, pc, pd, f, stops, sums);
}

Status lane_actuator_positions(const Model& m, const PlatformConfig& pc, Vec4& rho, lanes::Kernel kind) {
  return lanes::run<PositionsCopies, positions_scalar>(kind, m.avx, Status::InvalidArgument, m, pc, rho);
}

Status actuator_positions(const Model& m, const Pose& pose, Vec4& rho) {
  if (!pose.allFinite()) return Status::NonFinite;
  return lane_actuator_positions(m, platform_config(pose), rho);
}

}  // namespace pkm
