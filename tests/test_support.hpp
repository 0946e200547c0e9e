// SPDX-License-Identifier: BSD-2-Clause
// Shared helpers of the unit tests: random reachable states, finite
// differences and the reference model's Lagrangian terms (all derived from
// the spec, never from the code's outputs).
#pragma once

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/model/model.hpp"
#include "reference_model.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"

namespace pkm_test {

using namespace pkm;

/// The model of valid parameters (a failure otherwise).
inline Model model_of(const Params& p) {
  Model m;
  std::string why;
  EXPECT_EQ(make_model(p, m, &why), Status::Ok) << why;
  return m;
}

/// Every machine term of the dynamics on: rotors, an off-centre payload,
/// viscous and Coulomb friction with a velocity scale that keeps tanh's
/// slope visible (the derivatives' and the inverse dynamics' tests).
inline Params every_machine_term() {
  Params p;
  p.rotor_inertia = 2e-7;
  p.friction_viscous = 1.5;
  p.friction_coulomb = 0.2;
  p.friction_velocity = 0.05;
  p.payload_mass = 0.3;
  p.payload_com = {0.02, -0.012};
  p.payload_Izz = 1.2e-4;
  return p;
}

inline Model default_model(double g = 9.81) {
  Params p;
  p.g = g;
  return model_of(p);
}

/// A random pose inside the auto-test's neighbourhood of the workspace,
/// with a random velocity; q and qd on the constraint manifold.
struct RandomState {
  Pose pose, vel;
  Vec16 q, qd;
};

inline RandomState random_state(const Model& m, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RandomState s;
  s.pose = Pose(0.008 * u(gen), 0.008 * u(gen), 0.06 + 0.012 * u(gen), 0.08 * u(gen));
  s.vel = Pose(0.2 * u(gen), 0.2 * u(gen), 0.2 * u(gen), 1.5 * u(gen));
  EXPECT_EQ(closed_form_position(m, s.pose, s.q), Status::Ok);
  EXPECT_EQ(solve_velocity(m, s.q, s.vel, s.qd), Status::Ok);
  return s;
}

/// A random vector with entries in [-scale, scale].
template <int N>
Eigen::Matrix<double, N, 1> random_vec(unsigned seed, double scale) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v[i] = u(gen);
  return v;
}

/// A motion of the platform: pose, rate, acceleration, external wrench.
struct Motion {
  Pose pose, vel, acc;
  Wrench we;
};

/// A random state with accelerations within `acc` (m/s^2; the rotation's ten
/// times that, rad/s^2) and an external wrench within `we` (N; its moment a
/// tenth, N*m).
inline Motion random_motion(const Model& m, unsigned seed, double acc = 2.0, double we = 1.0) {
  const RandomState s = random_state(m, seed);
  const Vec4 a = random_vec<4>(seed + 1000, acc), w = random_vec<4>(seed + 2000, we);
  return {s.pose, s.vel, Pose(a[0], a[1], a[2], 10.0 * a[3]), Wrench(w[0], w[1], w[2], 0.1 * w[3])};
}

/// A path's motion at t (no wrench).
template <class Path>
Motion path_motion(const Path& path, double t) {
  Motion x{Pose::Zero(), Pose::Zero(), Pose::Zero(), Wrench::Zero()};
  path.eval(t, x.pose, x.vel, x.acc);
  return x;
}

/// The inverse dynamics of a motion (a failure where it does not solve).
inline InverseDynamicsResult inverse_dynamics_of(const Model& m, const Motion& mo) {
  InverseDynamicsResult r;
  EXPECT_EQ(inverse_dynamics(m, mo.pose, mo.vel, mo.acc, mo.we, r), Status::Ok);
  return r;
}

/// Fourth-order central difference of s -> f(s) at s = 0.
template <class F>
auto d_ds(F f, double h) -> decltype(f(0.0)) {
  return (f(-2 * h) - 8 * f(-h) + 8 * f(h) - f(2 * h)) / (12 * h);
}

/// d/ds f(s) at s = 0: central differences at h, h/2, h/4, h/8 and
/// Richardson's table (error O(h^8)); *err is the size of the last
/// correction, an estimate of the result's own error.
template <class F>
auto richardson(F f, double h, double* err) -> decltype(f(0.0)) {
  using V = decltype(f(0.0));
  constexpr int kLevels = 4;
  V T[kLevels];
  for (int k = 0; k < kLevels; ++k) {
    const double hk = h / (1 << k);
    T[k] = (f(hk) - f(-hk)) / (2 * hk);
    double factor = 4.0;
    for (int j = k - 1; j >= 0; --j, factor *= 4.0) T[j] = (factor * T[j + 1] - T[j]) / (factor - 1.0);
    if (k == kLevels - 1) *err = (T[0] - T[1]).cwiseAbs().maxCoeff();
  }
  return T[0];
}

/// Column by column: |analytic - difference|_max over the column's largest
/// analytic entry, and the same for the difference quotient's own error
/// estimate (the quotient must be reliable for the comparison to mean anything).
void expect_columns_match(const char* what, const Eigen::MatrixXd& an, const Eigen::MatrixXd& fd,
                          const Eigen::VectorXd& fd_err, double tol) {
  double worst = 0.0;
  for (int k = 0; k < an.cols(); ++k) {
    const double scale = std::max(an.col(k).cwiseAbs().maxCoeff(), 1e-12);
    const double rel = (an.col(k) - fd.col(k)).cwiseAbs().maxCoeff() / scale;
    EXPECT_LT(fd_err[k] / scale, 0.1 * tol) << what << " column " << k << ": the difference quotient is unreliable";
    EXPECT_LT(rel, tol) << what << " column " << k << ": relative difference " << rel << " (bound " << tol << ")";
    worst = std::max(worst, rel);
  }
  std::printf("%s: largest relative difference %.2e (bound %.0e)\n", what, worst, tol);
}

/// Relative difference with a floor on the scale.
template <class A, class B>
double rel_diff(const A& a, const B& b, double floor = 1e-300) {
  const double scale = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), floor});
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

/// The Lagrangian terms of Eq. 1 from the independent reference model's
/// energies (reference_model.hpp). M: the Hessian of T in qd by
/// polarisation, exact for a quadratic form.
inline Mat16 ref_mass_matrix(const ref::RefParams& r, const Vec16& q) {
  Mat16 H;
  const Vec16 zero = Vec16::Zero();
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const Vec16 ei = Vec16::Unit(i), ej = Vec16::Unit(j);
      H(i, j) = ref::kinetic_energy(r, q, ei + ej) - ref::kinetic_energy(r, q, ei) - ref::kinetic_energy(r, q, ej) +
                ref::kinetic_energy(r, q, zero);
    }
  return H;
}

/// dT/dqd at (q, qd). T is quadratic in qd, so the central difference with
/// a unit step is exact: (T(qd+e) - T(qd-e))/2.
inline Vec16 ref_momentum(const ref::RefParams& r, const Vec16& q, const Vec16& qd) {
  Vec16 p;
  for (int k = 0; k < kN; ++k) {
    Vec16 a = qd, b = qd;
    a[k] += 1.0;
    b[k] -= 1.0;
    p[k] = 0.5 * (ref::kinetic_energy(r, q, a) - ref::kinetic_energy(r, q, b));
  }
  return p;
}

/// d/dq_k of a scalar function of q, every k, by d_ds (step 1e-3).
template <class F>
Vec16 ref_gradient(F f, const Vec16& q) {
  Vec16 g;
  for (int k = 0; k < kN; ++k)
    g[k] = d_ds([&](double e) {
      Vec16 x = q;
      x[k] += e;
      return Eigen::Matrix<double, 1, 1>(f(x));
    }, 1e-3)[0];
  return g;
}

/// V = d/dt(dT/dqd) - dT/dq - M qdd = (d/ds dT/dqd(q + s qd, qd)) - dT/dq.
inline Vec16 ref_coriolis(const ref::RefParams& r, const Vec16& q, const Vec16& qd) {
  const Vec16 dpdt = d_ds([&](double e) { return ref_momentum(r, Vec16(q + e * qd), qd); }, 1e-3);
  return dpdt - ref_gradient([&](const Vec16& x) { return ref::kinetic_energy(r, x, qd); }, q);
}

/// G = dU/dq.
inline Vec16 ref_gravity(const ref::RefParams& r, const Vec16& q) {
  return ref_gradient([&](const Vec16& x) { return ref::potential_energy(r, x); }, q);
}

}  // namespace pkm_test
