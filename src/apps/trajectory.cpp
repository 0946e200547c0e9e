// SPDX-License-Identifier: BSD-2-Clause
#include "apps/trajectory.hpp"

namespace pkm {

void quintic_blend(double tau, double& s, double& ds, double& dds) {
  if (tau <= 0.0) {
    s = ds = dds = 0.0;
    return;
  }
  if (tau >= 1.0) {
    s = 1.0;
    ds = dds = 0.0;
    return;
  }
  const double t2 = tau * tau, t3 = t2 * tau;
  s = t3 * (10.0 + tau * (-15.0 + 6.0 * tau));
  ds = t2 * (30.0 + tau * (-60.0 + 30.0 * tau));
  dds = tau * (60.0 + tau * (-180.0 + 120.0 * tau));
}

void RestToRest::eval(double t, Pose& p, Pose& pd, Pose& pdd) const {
  double s, ds, dds;
  quintic_blend(t / duration, s, ds, dds);
  const Pose d = p1 - p0;
  p = p0 + d * s;
  pd = d * (ds / duration);
  pdd = d * (dds / (duration * duration));
}

}  // namespace pkm
