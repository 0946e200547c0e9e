// SPDX-License-Identifier: BSD-2-Clause
// Fixed-size Eigen types and index conventions shared by the whole core.
//
// Coordinates (docs/model.md "Coordinates and equations"), n = 16:
//   q = [rho1, th1_1, th2_1, rho2, th1_2, th2_2, rho3, th1_3, th2_3,
//        rho4, th1_4, th2_4, x, y, z, phi]
// Constraints: m = 12, three per leg (Eq. 15). Degrees of freedom: 4.
#pragma once

#include <Eigen/Dense>

namespace pkm {

constexpr int kLegs = 4;
constexpr int kN = 16;        // redundant coordinates
constexpr int kM = 12;        // loop-closure constraints
constexpr int kPlatform = 12; // index of x in q

/// Index of leg i's first coordinate (rho_i) in q.
constexpr int leg_offset(int leg) { return 3 * leg; }

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Matrix<double, 4, 1>;
using Vec8 = Eigen::Matrix<double, 8, 1>;
using Vec10 = Eigen::Matrix<double, 10, 1>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Vec16 = Eigen::Matrix<double, 16, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat16 = Eigen::Matrix<double, 16, 16>;
using Mat12x16 = Eigen::Matrix<double, 12, 16>;

/// Platform pose (x, y, z, phi) and its derivatives share this type.
using Pose = Vec4;

/// External platform wrench (Fx, Fy, Fz, Mz) acting on (x, y, z, phi).
using Wrench = Vec4;

}  // namespace pkm
