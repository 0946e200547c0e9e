// SPDX-License-Identifier: BSD-2-Clause
// The actuator positions rho_1..4 (the sliders' heights) at a platform pose.
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// rho_1..4 by the closed-form leg inverse kinematics, the four legs as
/// lanes (dynamics/leg_lanes.cpp), bit for bit leg_inverse_kinematics leg
/// by leg. Status::Unreachable outside the workspace (rho untouched),
/// NonFinite for a non-finite pose.
Status actuator_positions(const Model& m, const Pose& pose, Vec4& rho);

}  // namespace pkm
