// SPDX-License-Identifier: BSD-2-Clause
// Classical fixed-step Runge-Kutta (4th order), the paper's integrator.
#pragma once

#include "pkm4puu/base/status.hpp"
#include "pkm4puu/base/types.hpp"

namespace pkm {

/// One step of size h from (t, y). `f(t, y, ydot)` returns a Status; on any
/// failure y is left unchanged and that status returned.
template <class Derivative, class Vec>
Status rk4_step(Derivative& f, double t, double h, Vec& y) {
  Vec k1, k2, k3, k4;
  Status s = f(t, y, k1);
  if (s != Status::Ok) return s;
  s = f(t + 0.5 * h, Vec(y + (0.5 * h) * k1), k2);
  if (s != Status::Ok) return s;
  s = f(t + 0.5 * h, Vec(y + (0.5 * h) * k2), k3);
  if (s != Status::Ok) return s;
  s = f(t + h, Vec(y + h * k3), k4);
  if (s != Status::Ok) return s;
  y += (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  return Status::Ok;
}

}  // namespace pkm
