// SPDX-License-Identifier: BSD-2-Clause
// The state derivative's Jacobians with the legs as lanes: the hot path's
// leg kernel (leg_lanes.hpp) keeps what the partials need, the reduced
// system is solved once, and a second pass over the four legs as lanes adds
// each leg's share of dR/dp and dR/dpd (residual_partials' formulas,
// reduced_dynamics_derivatives.hpp, with the zeros of J_i^{-1}, A_i and M_i
// written out).
#pragma once

#include "pkm4puu/dynamics/leg_lanes.hpp"

namespace pkm {

struct LegPartialSums {
  LegSums sums;                // leg_sums' (the same bits)
  Pose pdd = Pose::Zero();     // the state derivative's (the same bits)
  Mat4 dp = Mat4::Zero();      // sum over the legs of their share of dR/dp (no platform)
  Mat4 dpd = Mat4::Zero();     // ... of dR/dpd
  Mat4 J_rho = Mat4::Zero();   // d rho/dp
  Mat4 drhod_dp = Mat4::Zero();  // d rhod/dp
};

/// The legs' sums, pdd and the legs' partials at (pc, pd) with the applied
/// forces f (on rho_i at leg_offset(i); the platform's four entries are the
/// external wrench) plus the passive joint forces (stops as in leg_sums).
/// Statuses as leg_sums, Singular from the solve.
Status leg_partial_sums(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                        LegPartialSums& out, lanes::Kernel kind = lanes::Kernel::Best);

}  // namespace pkm
