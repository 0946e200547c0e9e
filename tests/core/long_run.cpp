// SPDX-License-Identifier: BSD-2-Clause
// Hardening, long run: one hour of simulated time under CVODE (Adams, rtol
// 1e-12, atol 1e-14, one continuous integration: no restarts) with small
// sinusoidal actuator forces about the static ones, near the home pose.
//
// Checked at every quadrature node (three per 10 ms, 1.08e6 in all):
//   - the loop closures: ||C(q)|| <= 1e-10 m;
//   - the energy balance. The mechanism is conservative (no friction), so
//     with T the kinetic and U the potential energy (lagrangian.hpp, the
//     same T and U whose Lagrange equations the integrator solves), the
//     power balance d(T + U)/dt = sum_i F_i drho_i holds: Eq. 1's
//     generalised forces act on the rho_i only, C_q^T lambda does no work on
//     motions with C_q qd = 0, and the external wrench is zero here. Hence
//         r(t) = T(t) + U(t) - T(0) - U(0) - W(t),  W(t) = int_0^t sum_i F_i(s) drho_i(s) ds,
//     must stay 0. W is integrated alongside by 3-point Gauss-Legendre on
//     every 10-ms interval from the integrator's exact states at the nodes
//     (drho_i from the closed-form leg velocities); the forces are at most
//     ~2 Hz and the mechanism's modes at most ~4 Hz, so the rule's error
//     (~(omega h)^6 / 2e9) is far below rounding. |r| is compared with the
//     work itself (max |W|) and, more strictly, with the largest kinetic
//     energy of the run: both ratios must stay below 1e-6.
#include <chrono>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "pkm4puu/kinematics/constraints.hpp"
#include "hardening_table.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace {

using namespace pkm;

constexpr double kStaticForce = 2.655616050;

/// F_i(t) = F_static + a_i cos(w_i t): zero-mean velocities (cosines), so the
/// platform (free to move vertically: z is neutrally stable under the static
/// forces) oscillates about home instead of drifting.
struct Forces {
  double a[4] = {0.01, 0.012, 0.008, 0.011};                       // N
  double w[4] = {2 * kPi * 1.3, 2 * kPi * 0.7, 2 * kPi * 1.9, 2 * kPi * 1.1};  // rad/s
  void at(double t, Vec4& F) const {
    for (int i = 0; i < 4; ++i) F[i] = kStaticForce + a[i] * std::cos(w[i] * t);
  }
  static void eval(void* self, double t, Vec4& F, Wrench& we) {
    static_cast<const Forces*>(self)->at(t, F);
    we.setZero();
  }
};

struct Point {
  double E, power, residual_C, kinetic;
  Pose pose;
};

Point evaluate(const Plant& plant, const Forces& forces) {
  const Model& m = plant.model();
  Vec16 q, qd;
  EXPECT_EQ(expand_state(m, plant.state(), q, qd), Status::Ok);
  Vec4 F;
  forces.at(plant.time(), F);
  Point p;
  p.kinetic = kinetic_energy(m, q, qd);
  p.E = p.kinetic + potential_energy(m, q);
  p.power = 0.0;
  for (int i = 0; i < kLegs; ++i) p.power += F[i] * qd[leg_offset(i)];
  p.residual_C = constraints(m, q).norm();
  p.pose = plant.state().head<4>();
  return p;
}

TEST(HardeningLongRun, OneHourUnderCvodeKeepsTheConstraintsAndTheEnergyBalance) {
  Model model;
  ASSERT_EQ(make_model(Params{}, model), Status::Ok);
  Plant plant(model);
  SolverSettings s;
  s.solver = Solver::Cvode;
  s.cvode_method = CvodeMethod::Adams;
  s.rtol = 1e-12;
  s.atol = 1e-14;
  ASSERT_EQ(plant.set_solver(s), Status::Ok);
  const Pose home(0.0, 0.0, 0.05, 0.0);
  ASSERT_EQ(plant.initialize(0.0, home, Pose::Zero()), Status::Ok);
  Forces forces;
  const InputSignal input{&Forces::eval, &forces};

  const double T_end = 3600.0, h = 0.01;
  const double gx[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const Point start = evaluate(plant, forces);
  double W = 0.0, max_r = 0.0, max_W = 0.0, max_T = 0.0, max_C = start.residual_C, t_worst = 0.0;
  Pose max_dev = Pose::Zero();
  const auto wall = std::chrono::steady_clock::now();
  const long n = std::lround(T_end / h);
  for (long k = 0; k < n; ++k) {
    const double a = k * h, b = (k + 1) * h;
    double sum = 0.0;
    for (int j = 0; j < 3; ++j) {
      const Status st = plant.advance(0.5 * (a + b) + 0.5 * h * gx[j], input, /*continuous=*/true);
      ASSERT_EQ(st, Status::Ok) << "at t = " << plant.time() << ": " << plant.last_error();
      const Point p = evaluate(plant, forces);
      sum += gw[j] * p.power;
      max_C = std::max(max_C, p.residual_C);
    }
    W += 0.5 * h * sum;
    const Status st = plant.advance(b, input, /*continuous=*/true);
    ASSERT_EQ(st, Status::Ok) << "at t = " << plant.time() << ": " << plant.last_error();
    const Point p = evaluate(plant, forces);
    const double r = std::fabs(p.E - start.E - W);
    if (r > max_r) {
      max_r = r;
      t_worst = b;
    }
    max_W = std::max(max_W, std::fabs(W));
    max_T = std::max(max_T, p.kinetic);
    max_C = std::max(max_C, p.residual_C);
    max_dev = max_dev.cwiseMax((p.pose - home).cwiseAbs());
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  EXPECT_NEAR(plant.time(), T_end, 1e-9);
  EXPECT_LE(max_C, 1e-10) << "||C(q)|| over the hour";
  EXPECT_LE(max_r / max_W, 1e-6) << "energy balance relative to the actuators' work";
  EXPECT_LE(max_r / max_T, 1e-6) << "energy balance relative to the largest kinetic energy";
  // Near the home pose all along.
  EXPECT_LE(max_dev[0], 1e-3);
  EXPECT_LE(max_dev[1], 1e-3);
  EXPECT_LE(max_dev[2], 3e-3);
  EXPECT_LE(max_dev[3], 0.05);
  char figures[600];
  std::snprintf(figures, sizeof figures,
                "3600 s simulated in %.1f s wall, %ld state derivatives; max ||C(q)|| = %.2e m; max |T+U-E0-W| = "
                "%.2e J (at t = %.0f s) against max |W| = %.3e J (ratio %.1e) and max T = %.3e J (ratio %.1e); "
                "max |x|, |y|, |z-z0|, |phi| = %.1e m, %.1e m, %.1e m, %.1e rad",
                seconds, plant.rhs_evaluations(), max_C, max_r, t_worst, max_W, max_r / max_W, max_T,
                max_r / max_T, max_dev[0], max_dev[1], max_dev[2], max_dev[3]);
  std::printf("%s\n", figures);
  pkm_test::table_row("long run: 1 h of F_i = F_static + ~0.01 N cos(w_i t) near home, CVODE Adams rtol 1e-12",
                      "completes (no discard)", figures);
}

}  // namespace
