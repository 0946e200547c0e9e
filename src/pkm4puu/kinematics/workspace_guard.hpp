// SPDX-License-Identifier: BSD-2-Clause
// Guards against singular configurations (docs/model.md "Working mode"):
//   - leg (serial) singularities: det(dC_i/d(rho, theta1, theta2)) / l^2 =
//     |cos theta2 sin theta2| goes to 0 when a rod turns horizontal
//     (theta2 -> 0, the edge of its reach) or vertical (theta2 -> -pi/2);
//   - parallel singularities: the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi)
//     (phi column divided by 0.1 m) loses rank: its condition number grows
//     without bound.
// The integrators check the state at the end of every step (RK4: every
// internal step; CVODE: every call), not in the state derivative (the hot
// path): a step that ends beyond a limit is undone and reported, so the
// kept state is always the last one within the limits.
#pragma once

#include <string>

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

struct GuardLimits {
  /// Largest admissible condition number of the actuator Jacobian. Along the
  /// paper's auto-test it stays at most 25.06; anywhere in the spec geometry's
  /// workspace with every |cos theta2 sin theta2| >= 0.05 it stays below 350.
  double max_jacobian_condition = 1e3;
  /// Smallest admissible |cos theta2 sin theta2| of every leg (0.5 at
  /// theta2 = -45 deg; 1e-2 is about 0.57 deg from a singular angle). Values
  /// below the numerical floor kLegSingularFloor act as that floor.
  double min_leg_measure = 1e-2;
};

/// Returns "" if the limits are usable, otherwise a message naming the
/// offending one.
std::string validate(const GuardLimits& g);

/// What check_configuration found.
struct GuardReport {
  Status status = Status::Ok;
  int leg = -1;                // the leg at fault (0-based), -1 for the whole machine
  double leg_measure = 0.0;    // |cos theta2 sin theta2| of that leg (Singular, leg >= 0)
  double condition = 0.0;      // exact condition number (Singular, leg < 0)
};

/// Checks a platform pose: every leg reachable elbow-down (else
/// Status::Unreachable), every leg measure at least the limit and the
/// actuator Jacobian's condition number at most the limit (else
/// Status::Singular), the pose finite (else Status::NonFinite).
/// Allocation free; the condition number is bounded cheaply first
/// (from det J and ||J||_F, then ||J||_F ||J^-1||_F) and computed exactly
/// (SVD) only when both bounds exceed the limit.
Status check_configuration(const Model& m, const Pose& pose, const GuardLimits& lim,
                           GuardReport* report = nullptr);

/// check_configuration's checks on what a caller already has from the legs'
/// inverse kinematics: J = d rho/d(x, y, z, phi) with its phi column divided
/// by kConditionLength (constraints.hpp), measure2[i] = (cos theta2_i sin
/// theta2_i)^2. Status::Ok or ::Singular, the report as check_configuration's.
Status check_jacobian(const Mat4& J, const Vec4& measure2, const GuardLimits& lim, GuardReport* report = nullptr);

/// A sentence for a failed check: which leg or the whole machine, which
/// quantity, its value, the limit or the geometric reason, and the
/// parameters involved.
std::string describe_configuration_failure(const Model& m, const Pose& pose, const GuardLimits& lim,
                                           const GuardReport& report);

/// The guards as event indicators (Model Exchange): positive within the
/// limits, zero on a limit, negative beyond it. z[0] = 1/cond(J) -
/// 1/max_jacobian_condition; z[1 + i] = |cos theta2 sin theta2| of leg i -
/// min_leg_measure. Status::Unreachable (z unchanged) if a leg cannot reach.
/// `condition`, if given, receives the condition number itself (+inf at a
/// parallel singularity): the one SVD serves both.
constexpr int kGuardIndicators = 5;

/// The extreme values validate() accepts, as a modelDescription declares them
/// (inclusive): the least double above 1 for max_jacobian_condition (a
/// condition number is at least 1), the greatest below 0.5 for
/// min_leg_measure (|cos theta2 sin theta2| is at most 0.5).
constexpr double kLeastConditionLimit = 1.0 + 0x1p-52;
constexpr double kGreatestLegMeasureLimit = 0.5 - 0x1p-54;
Status guard_indicators(const Model& m, const Pose& pose, const GuardLimits& lim, double z[kGuardIndicators],
                        double* condition = nullptr);

}  // namespace pkm
