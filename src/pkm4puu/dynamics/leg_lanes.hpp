// SPDX-License-Identifier: BSD-2-Clause
// The derivative's legs as lanes: the leg arithmetic of the hot path
// (leg inverse kinematics, the legs' velocities and their share of the
// reduced system) for the four legs at once, in packed doubles
// (base/lanes.hpp), with an AVX variant where the processor has it. Each
// lane keeps the scalar expressions' order: the same bits as leg by leg.
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"
#include "pkm4puu/model/model.hpp"

namespace pkm {

/// The four legs' sums for the reduced system.
struct LegSums {
  double mr[10];  // sum over the legs of A^T M A, upper triangle by rows
  double rhs[4];  // sum over the legs of A^T r
  double rho[kLegs], rhod[kLegs];
};

/// The legs' sums at the platform state (pc, pd) with the applied forces
/// f (on rho_i at leg_offset(i)) plus the passive joint forces (stops held
/// as `stops`). On failure the status of the first failing leg
/// (Unreachable, Singular), as leg by leg; InvalidArgument for a copy
/// (lanes::Kernel) this build or processor does not have.
Status leg_sums(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                LegSums& sums, lanes::Kernel kind = lanes::Kernel::Best);

/// The actuator positions rho_1..4 by the legs' inverse kinematics of
/// leg_sums (actuator_positions without the finiteness check). On failure
/// Status::Unreachable (the first failing leg's), rho untouched;
/// InvalidArgument for an unavailable copy.
Status lane_actuator_positions(const Model& m, const PlatformConfig& pc, Vec4& rho,
                               lanes::Kernel kind = lanes::Kernel::Best);

}  // namespace pkm
