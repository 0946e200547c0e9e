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
// Its error estimate is the pair's embedded first-order solution
// y + h k1 (the linearly implicit Euler step), at no extra cost:
//   y1 - (y + h k1) = h (k1 + k2) / 2,
// the local error of the first-order solution, O(h^2): an upper bound of
// ROS2's own, O(h^3), where the step resolves the motion. It is filtered
// through (I - gamma H J)^-1 with H = max(h, h_filter) (Shampine's filter,
// which RADAU5 applies with H = h): that leaves the share of the modes with
// |lambda| H << 1 as it is and divides a mode's by about 1 + gamma H
// |lambda| beyond. With H = h it removes what the embedded solution, not
// L-stable (its factor at h lambda -> -inf is 1 - 1/gamma), adds on a stiff
// mode that ROS2 damps; with H > h it also discounts the error on a mode
// that decays within H, which the motion itself damps before the grid
// step's end (a stiff damper stopping the platform within microseconds),
// so H is at most the time left to it. Where the steps are H or longer the
// filter reuses ROS2's factorisation. Neither sees where the linearisation
// itself fails over the step (Coulomb friction breaking away from rest:
// tanh(v / v_s) leaves its linear range within nanometres per second): so
// the estimate is, component by component, at least h |f(y + h k1) - f(y)
// - h (J k1 + f_t)|, the change the linear prediction of the second
// stage's rates misses (O(h^3) where f is smooth on the step's scale).
#pragma once

#include <algorithm>

#include <Eigen/LU>

#include "pkm4puu/integrators/located_step.hpp"

namespace pkm {

constexpr double kRos2Gamma = 1.0 + 0.70710678118654752440;

/// One ROS2 step of size h from (t, y). `sys` provides
///   Status rates(double t, const Vec10& x, Vec10& xdot)
///   Status jacobian(double t, const Vec10& x, double h, Vec10& xdot, Eigen::Matrix<double, 8, 8>& A, Vec8& f_t)
/// (xdot the rates at (t, x), A = d(pose, velocity rates)/d(pose, velocity),
/// f_t their time derivative over [t, t + h] through the inputs). `error`
/// receives the embedded estimate h (k1 + k2) / 2, filtered through
/// (I - gamma max(h, h_filter) J)^-1. On failure y is left unchanged.
template <class System>
Status ros2_step(System& sys, double t, double h, Vec10& y, Vec10& error, double h_filter = 0.0) {
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
  error = (0.5 * h) * (k1 + k2);
  if (h >= h_filter) {
    error.head<8>() = W.solve(Vec8(error.head<8>()));
  } else {
    const Eigen::PartialPivLU<Mat8> F(Mat8(Mat8::Identity() - (kRos2Gamma * h_filter) * A));
    error.head<8>() = F.solve(Vec8(error.head<8>()));
  }
  // The linearisation over the step: the rates at the second stage against
  // their prediction from J, times h, the change of the state it misses.
  const Vec8 missed = h * (f1.head<8>() - f0.head<8>() - h * (A * k1.head<8>() + ft));
  error.head<8>() = error.head<8>().cwiseAbs().cwiseMax(missed.cwiseAbs());
  y = y1;
  return Status::Ok;
}

/// located_fixed_step with ROS2 under its error control, the estimate
/// filtered with H up to h_filter but no longer than the time from the
/// step's end to t1 (ros2_step); `sys` also provides
///   double error_norm(const Vec10& error, const Vec10& y0, const Vec10& y1, double h)
/// the estimate of the step of h from y0 to y1 in units of the tolerance (at
/// most 1: accepted).
template <class System>
Status located_rosenbrock_step(System& sys, double t0, double t1, const InnerSteps& inner, StepControl& control,
                               Vec10& x, unsigned& mode, Vec4& rho, bool& rho_valid, long& switches, double& t,
                               WorkBudget& budget, double h_filter) {
  auto step = [&sys, h_filter, t1](double tt, double h, Vec10& xx, double& estimate) {
    const Vec10 y0 = xx;
    Vec10 error;
    // An error lasts to t1 at least: decay counts only within the time left.
    const Status s = ros2_step(sys, tt, h, xx, error, std::min(h_filter, t1 - (tt + h)));
    if (s == Status::Ok) estimate = sys.error_norm(error, y0, xx, h);
    return s;
  };
  return located_fixed_step(sys, step, t0, t1, inner, control, x, mode, rho, rho_valid, switches, t, budget);
}

}  // namespace pkm
