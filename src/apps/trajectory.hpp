// SPDX-License-Identifier: BSD-2-Clause
// The spec's rest-to-rest motion (docs/model.md "The paper's two tests"):
//   pose(t) = P0 + (P1 - P0) s(t/T),  s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5,
// with zero velocity and acceleration at both ends; held at P0 before t = 0
// and at P1 after t = T.
#pragma once

#include "pkm4puu/base/types.hpp"

namespace pkm {

struct RestToRest {
  Pose p0 = Pose(0.0, 0.0, 0.05, 0.0);
  Pose p1 = Pose(0.005, -0.005, 0.07, 4.0 * 3.14159265358979323846 / 180.0);
  double duration = 2.0;  // s

  /// Pose, velocity and acceleration at time t.
  void eval(double t, Pose& p, Pose& pd, Pose& pdd) const;
};

/// s(tau) and its first two derivatives with respect to tau.
void quintic_blend(double tau, double& s, double& ds, double& dds);

}  // namespace pkm
