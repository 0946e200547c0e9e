// SPDX-License-Identifier: BSD-2-Clause
// The stiff fixed-step solver: ROS2 (Verwer, Spee, Blom, Hundsdorfer 1999),
// a two-stage linearly implicit Rosenbrock method, L-stable, of order 2 for
// any Jacobian approximation (a W-method), with gamma = 1 + 1/sqrt(2):
//   (I - gamma h J) k1 = f(t, y) + gamma h f_t
//   (I - gamma h J) k2 = f(t + h, y + h k1) - 2 k1 - gamma h f_t
//   y1 = y + h (3/2 k1 + 1/2 k2)
// J is the analytic Jacobian of the pose and velocity rows; the energy
// integrals do not act back on the motion and take J = 0 there (their rows
// become the explicit trapezoid of the stage rates, also order 2). Fixed
// size, one LU of 8x8 per step: constant cost, no allocation.
#pragma once

#include <Eigen/LU>

#include "pkm4puu/integrators/located_step.hpp"

namespace pkm {

constexpr double kRos2Gamma = 1.0 + 0.70710678118654752440;

/// One ROS2 step of size h from (t, y). `sys` provides
///   Status rates(double t, const Vec10& x, Vec10& xdot)
///   Status jacobian(double t, const Vec10& x, double h, Vec10& xdot, Eigen::Matrix<double, 8, 8>& A, Vec8& f_t)
/// (xdot the rates at (t, x), A = d(pose, velocity rates)/d(pose, velocity),
/// f_t their time derivative over [t, t + h] through the inputs). On
/// failure y is left unchanged.
template <class System>
Status ros2_step(System& sys, double t, double h, Vec10& y) {
  using Mat8 = Eigen::Matrix<double, 8, 8>;
  Vec10 f0, f1;
  Mat8 A;
  Vec8 ft;
  Status s = sys.jacobian(t, y, h, f0, A, ft);
  if (s != Status::Ok) return s;
  const double gh = kRos2Gamma * h;
  const Eigen::PartialPivLU<Mat8> W(Mat8(Mat8::Identity() - gh * A));
  Vec10 k1, k2;
  k1.head<8>() = W.solve(Vec8(f0.head<8>() + gh * ft));
  k1.tail<2>() = f0.tail<2>();
  if (!k1.allFinite()) return Status::SolverFailure;
  s = sys.rates(t + h, Vec10(y + h * k1), f1);
  if (s != Status::Ok) return s;
  k2.head<8>() = W.solve(Vec8(f1.head<8>() - 2.0 * k1.head<8>() - gh * ft));
  k2.tail<2>() = f1.tail<2>() - 2.0 * k1.tail<2>();
  const Vec10 y1 = y + h * (1.5 * k1 + 0.5 * k2);
  if (!y1.allFinite()) return Status::SolverFailure;
  y = y1;
  return Status::Ok;
}

/// located_fixed_step with ROS2.
template <class System>
Status located_rosenbrock_step(System& sys, double t0, double t1, InnerSteps& inner, Vec10& x,
                               unsigned& mode, Vec4& rho, bool& rho_valid, long& switches, double& t,
                               WorkBudget& budget) {
  auto step = [&sys](double tt, double h, Vec10& xx) { return ros2_step(sys, tt, h, xx); };
  return located_fixed_step(sys, step, t0, t1, inner, x, mode, rho, rho_valid, switches, t, budget);
}

}  // namespace pkm
