// SPDX-License-Identifier: BSD-2-Clause
// theta1 of each leg, continuous in time: the closed form gives it modulo
// 2 pi; a reference per leg, brought forward by whole turns, unwraps it.
#pragma once

#include <cmath>

#include "pkm4puu/base/types.hpp"
#include "pkm4puu/model/params.hpp"

namespace pkm {

/// |theta1| of a leg never comes near this: the closed form gives
/// |theta1| < 2 pi, and the legs keep the platform from turning a whole turn.
constexpr double kMaxTheta1 = 8.0 * kPi;

/// `angle` moved by whole turns next to `ref`.
inline double unwrap_near(double angle, double ref) {
  constexpr double two_pi = 2.0 * kPi;
  return angle + two_pi * std::round((ref - angle) / two_pi);
}

/// The references: each leg's theta1 at the last state they followed.
/// Continuity holds as long as theta1 moves less than pi between two
/// follow() calls, which the workspace guarantees between steps.
struct Theta1References {
  Vec4 ref = Vec4::Zero();

  /// Moves the references to the theta1 of q (unwrapped next to them).
  void follow(const Vec16& q) {
    for (int i = 0; i < kLegs; ++i) ref[i] = unwrap_near(q[leg_offset(i) + 1], ref[i]);
  }
  /// theta1 of every leg in q moved by whole turns next to its reference.
  void unwrap(Vec16& q) const {
    for (int i = 0; i < kLegs; ++i) {
      double& th1 = q[leg_offset(i) + 1];
      th1 = unwrap_near(th1, ref[i]);
    }
  }
};

}  // namespace pkm
