// SPDX-License-Identifier: BSD-2-Clause
// The regressor (regressor.hpp, R1-R2) in the reduced, leg-partitioned form
// of the inverse dynamics (inverse_lanes.hpp): the legs' closed-form
// kinematics as four lanes, each leg's A_i^T D_i for the per-leg parameters'
// columns, the platform's and payload's columns from the platform's motion
// alone, then J_rho^T Y = Z for all columns with one 4x4 inverse.
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

/// (R1) at the platform motion (pc's pose, pd, pdd) with the external
/// wrench `we`, into out (Y, F0, rho, rhod, pose_d, pose_dd, beyond_stops;
/// not out.pose). Unreachable if a leg is out of reach, Singular at a leg
/// or parallel singularity. Each function here runs the Best copy
/// (lanes::Kernel); its overload with `kind` the copy asked for, or answers
/// InvalidArgument where this build, processor or kernel has none (the
/// regressor has no one-leg Scalar copy).
Status regressor_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd, const Wrench& we,
                       RegressorSample& out);
Status regressor_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Pose& pdd, const Wrench& we,
                       RegressorSample& out, lanes::Kernel kind);

/// (R1) at the pose pc from the sliders' rates and accelerations: pd =
/// A_rho^{-1} rhod, pdd = A_rho^{-1} (rhodd - b_rho), then as regressor_lanes.
Status joint_regressor_lanes(const Model& m, const PlatformConfig& pc, const Vec4& rhod, const Vec4& rhodd,
                             const Wrench& we, RegressorSample& out);
Status joint_regressor_lanes(const Model& m, const PlatformConfig& pc, const Vec4& rhod, const Vec4& rhodd,
                             const Wrench& we, RegressorSample& out, lanes::Kernel kind);

/// The sliders' positions rho at pc and A_rho = d rho / d pose (the forward
/// kinematics' Newton step). Unreachable, Singular as regressor_lanes.
Status slider_positions_lanes(const Model& m, const PlatformConfig& pc, Vec4& rho, Mat4& Arho);
Status slider_positions_lanes(const Model& m, const PlatformConfig& pc, Vec4& rho, Mat4& Arho, lanes::Kernel kind);

}  // namespace pkm
