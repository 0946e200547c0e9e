// SPDX-License-Identifier: BSD-2-Clause
// One leg's kinematics in its base frame 0_i (docs/model.md "One leg",
// Table I, standard DH). Everything here is per leg and allocation free.
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

/// A leg's configuration with its trigonometric values computed once.
struct LegConfig {
  double rho = 0;
  double c1 = 1, s1 = 0;  // cos, sin of theta1
  double c2 = 1, s2 = 0;  // cos, sin of theta2
};

/// Platform pose with cos/sin of phi computed once.
struct PlatformConfig {
  Pose pose = Pose::Zero();
  double cphi = 1, sphi = 0;
};

LegConfig leg_config(double rho, double theta1, double theta2);
PlatformConfig platform_config(const Pose& pose);

/// p_Q: leg end point Q in frame 0_i (spec: the product of Table I's rows).
Vec3 leg_point(const Params& p, const LegConfig& c);

/// J = dp_Q/d(rho, theta1, theta2), in frame 0_i.
Mat3 leg_point_jacobian(const Params& p, const LegConfig& c);

/// (J qd)_q qd: the part of d^2 p_Q/dt^2 quadratic in the leg's rates.
Vec3 leg_point_quadratic(const Params& p, const LegConfig& c, double th1d, double th2d);

/// Platform attachment point of leg i in G: p + Rz(phi) r_Qi.
Vec3 platform_point(const Model& m, int leg, const PlatformConfig& pc);

/// Rz(phi) r_Qi (its xy part; z is 0).
Vec3 rotated_attachment(const Model& m, int leg, const PlatformConfig& pc);

/// P_i = d(platform point)/d(x, y, z, phi) = [I3, e_z x Rz(phi) r_Qi].
Mat34 platform_point_jacobian(const Model& m, int leg, const PlatformConfig& pc);

/// Closed-form leg inverse kinematics (spec "Working mode"), elbow-down
/// branch: theta2 in (-pi/2, 0), theta1 = atan2(qy, qx) + atan2(h', A).
/// Fills the trigonometric values algebraically (no trig calls) and, if
/// `angles` is given, theta1 and theta2 themselves.
/// Returns Status::Unreachable when the point is out of the leg's reach.
struct LegAngles { double theta1, theta2; };
Status leg_inverse_kinematics(const Model& m, int leg, const PlatformConfig& pc,
                              LegConfig& out, LegAngles* angles = nullptr);

/// det(dC_i/d(rho, theta1, theta2)) / l^2 = A sin(theta2) / l: a
/// dimensionless measure of a leg singularity (link vertical or horizontal).
double leg_singularity_measure(const Params& p, const LegConfig& c);

/// Below this leg_singularity_measure a leg block is treated as singular
/// whatever the user's limits say (workspace_guard.hpp): the state
/// derivative, the servo Jacobian and the actuator Jacobian refuse it.
constexpr double kLegSingularFloor = 1e-12;

}  // namespace pkm
