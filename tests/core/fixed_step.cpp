// SPDX-License-Identifier: BSD-2-Clause
// The fixed-step solvers are right or say so (docs/solvers.md): the stiff
// cases of issue 28 at 1 ms steps, RK4 (sub-stepped within its stability
// bound, or refused with a message) and ROS2 (solver = 2, under its error
// estimate) against CVODE at rtol 1e-10, the default drop's repeated
// impacts among them; the work budget and the cap on one advance, every
// solver; the energy audit as a run-time check; ROS2's order and its
// estimate's.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "pkm4puu/integrators/located_rosenbrock.hpp"
#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

// The platform at the home pose, no actuator force: it sinks under gravity.
const Pose kHome(0.0, 0.0, 0.05, 0.0);

SolverSettings settings_of(Solver solver, double rk4_step = 1e-3) {
  SolverSettings s;
  s.solver = solver;
  s.rk4_step = rk4_step;
  if (solver == Solver::Cvode) {  // the reference: BDF (stiff) at rtol 1e-10
    s.rtol = 1e-10;
    s.atol = 1e-12;
    s.cvode_method = CvodeMethod::BDF;
  }
  return s;
}

double audit_of(const Plant& plant) {
  MachineOutputs mo;
  EXPECT_EQ(plant.machine_outputs(InputSignal{}, mo), Status::Ok);
  return mo.kinetic_energy + mo.potential_energy - mo.actuator_work + mo.dissipated_energy;
}

}  // namespace

// The stiff cases (F = 0 from the home pose, 1 ms steps).
Params viscous_1000() {
  Params p;
  p.friction_viscous = 1000.0;
  return p;
}
Params coulomb_5() {
  Params p;
  p.friction_coulomb = 5.0;
  return p;
}
Params coulomb_10_stuck() {
  Params p;
  p.friction_coulomb = 10.0;
  p.friction_velocity = 1e-6;
  return p;
}
Params stiff_stops(double m_slider) {
  Params p;
  p.stop_damping = 1e6;
  p.stop_stiffness = 1e9;
  p.m_slider = m_slider;
  return p;
}

// The bounds (docs/solvers.md, "Accuracy"): RK4 sub-steps keep h |lambda| <=
// 0.1 on the stiff modes, whose error per sub-step is at most
// (0.1)^5 / 120 = 8.3e-8 of their amplitude and is contracted by
// R(-0.1) = 0.905 at every later sub-step: in all at most 8.3e-8 / 0.095 =
// 8.8e-7 of the velocity scale; with CVODE's rtol 1e-10 and a factor 10 for
// the non-stiff part's own h^4 error, 1e-5 of max |dz| (these cases have no
// second impact to magnify it). ROS2: 1 % of max |dz|, every step.
constexpr double kRk4Bound = 1e-5, kRosenbrockBound = 1e-2;

/// Every step of `s` from `from` on within `bound` of the reference,
/// relative to max |dz_ref|.
void expect_agrees(const Params& p, Solver solver, double bound, int steps, int from = 1) {
  const SolverSettings ref_settings = settings_of(Solver::Cvode);
  Plant ref(model_of(p)), fix(model_of(p));
  ASSERT_EQ(ref.set_solver(ref_settings), Status::Ok);
  ASSERT_EQ(fix.set_solver(settings_of(solver)), Status::Ok) << "refused: " << fix.last_error();
  ASSERT_EQ(ref.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  ASSERT_EQ(fix.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  double worst = 0.0, scale = 0.0;
  std::vector<double> ref_dz, fix_dz;
  for (int k = 1; k <= steps; ++k) {
    ASSERT_EQ(ref.advance(k * 1e-3, InputSignal{}), Status::Ok) << ref.last_error();
    ASSERT_EQ(fix.advance(k * 1e-3, InputSignal{}), Status::Ok) << fix.last_error();
    ref_dz.push_back(ref.state()[6]);
    fix_dz.push_back(fix.state()[6]);
    scale = std::max(scale, std::fabs(ref.state()[6]));
  }
  for (int k = from - 1; k < steps; ++k) worst = std::max(worst, std::fabs(fix_dz[k] - ref_dz[k]));
  std::printf("solver %d: max |dz - dz_CVODE| from step %d on = %.3g of max |dz| = %.3g m/s (bound %.0e; "
              "first step %.3g)\n",
              static_cast<int>(solver), from, worst / scale, scale, bound, std::fabs(fix_dz[0] - ref_dz[0]) / scale);
  EXPECT_LE(worst, bound * scale);
}

TEST(FixedStep, ViscousFrictionOf1000IsSubsteppedByRk4AndStableInRosenbrock) {
  // Before: RK4 answered OK at dz = +93.7 m/s (CVODE -2.66e-3 m/s).
  expect_agrees(viscous_1000(), Solver::Rk4, kRk4Bound, 40);
  expect_agrees(viscous_1000(), Solver::Rosenbrock, kRosenbrockBound, 40);
}

TEST(FixedStep, CoulombFrictionOf5NAgreesWithCvode) {
  // Before: RK4 dz = -3.2e-3 m/s against CVODE's -5.9e-4 m/s, every step OK.
  expect_agrees(coulomb_5(), Solver::Rk4, kRk4Bound, 40);
  expect_agrees(coulomb_5(), Solver::Rosenbrock, kRosenbrockBound, 40);
}

TEST(FixedStep, StuckCoulombFrictionIsRefusedByRk4WithTheBoundAndHeldByRosenbrock) {
  // Before: RK4 slid at 1.7e-2 m/s where the machine is stuck.
  const Params p = coulomb_10_stuck();
  Plant plant(model_of(p));
  std::string why;
  EXPECT_EQ(plant.set_solver(settings_of(Solver::Rk4), &why), Status::InvalidArgument);
  // The bound, computed here: (F_c / v_s) / m_slider.
  char bound[32];  // formatted as the message does
  std::snprintf(bound, sizeof bound, "%.4g 1/s", (p.friction_coulomb / p.friction_velocity) / p.m_slider);
  const std::string parts[] = {"friction_coulomb = 10 N", "friction_velocity = 1e-06 m/s", bound, "solver = 2",
                               "rk4_step <="};
  for (const std::string& part : parts)
    EXPECT_NE(why.find(part), std::string::npos) << "missing '" << part << "' in: " << why;
  expect_agrees(p, Solver::Rosenbrock, kRosenbrockBound, 40);
}

TEST(FixedStep, StiffStopsRunOutOfTheWorkBudgetWithRk4AndComeToRestWithRosenbrock) {
  // Before: 0.18 s per 1 ms step (m_slider default), 1.6 s (1e-2 kg), hours (1e-6 kg).
  for (double m_slider : {Params{}.m_slider, 1e-2, 1e-6}) {
    const Params p = stiff_stops(m_slider);
    Plant rk4(model_of(p));
    ASSERT_EQ(rk4.set_solver(settings_of(Solver::Rk4)), Status::Ok);
    ASSERT_EQ(rk4.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
    Status s = Status::Ok;
    long rhs_before = 0;
    int k = 0;
    while (s == Status::Ok && k < 200) {
      rhs_before = rk4.rhs_evaluations();
      ++k;
      s = rk4.advance(k * 1e-3, InputSignal{});
    }
    ASSERT_EQ(s, Status::SolverFailure) << "m_slider = " << m_slider << ": RK4 must give up in the stiff contact";
    // One step of RK4 is 4 evaluations: the budget bounds the failing advance.
    EXPECT_LE(rk4.rhs_evaluations() - rhs_before, 4 * static_cast<long>(SolverSettings{}.work_budget));
    for (const char* part : {"work budget", "stop_stiffness = 1e+09 N/m", "stop_damping = 1e+06", "solver = 2"})
      EXPECT_NE(rk4.last_error().find(part), std::string::npos) << rk4.last_error();
    EXPECT_EQ(rk4.time(), (k - 1) * 1e-3) << "the state stays at the last whole step";

    // ROS2 lands and rests on the four stops: each carries a quarter of the
    // weight, the static holding force (F_hold, virtual work) at rest.
    Plant ros(model_of(p));
    ASSERT_EQ(ros.set_solver(settings_of(Solver::Rosenbrock)), Status::Ok);
    ASSERT_EQ(ros.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
    for (int j = 1; j <= 200; ++j) ASSERT_EQ(ros.advance(j * 1e-3, InputSignal{}), Status::Ok) << ros.last_error();
    MachineOutputs mo;
    ASSERT_EQ(ros.machine_outputs(InputSignal{}, mo), Status::Ok);
    EXPECT_LT(ros.state().tail<4>().cwiseAbs().maxCoeff(), 1e-9);
    // Equilibrium: the stop force k delta + d delta_dot holds F_hold up to
    // the damper's share at the residual rate and the spring's at the
    // rounding of rho (a closed form of the pose: a few ulps of the
    // machine's 0.1 m scale, 8 eps 0.1 m).
    const double rho_rounding = 8.0 * std::numeric_limits<double>::epsilon() * 0.1;
    for (int i = 0; i < kLegs; ++i)
      EXPECT_NEAR(mo.stop_force[i], mo.F_hold[i],
                  p.stop_damping * std::fabs(mo.rhod[i]) + p.stop_stiffness * rho_rounding);
  }
}

TEST(FixedStep, TheWorkBudgetCountsBisectionTrials) {
  // The default stops, RK4 with a budget of 10 inner steps per grid step: the
  // fall reaches the stops and the located contact (about 30 bisection
  // trials for a 1 ms step at 1e-12 s) cannot fit.
  Plant plant(model_of(Params{}));
  SolverSettings s = settings_of(Solver::Rk4);
  s.work_budget = 10;
  ASSERT_EQ(plant.set_solver(s), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  Status st = Status::Ok;
  for (int k = 1; k <= 200 && st == Status::Ok; ++k) st = plant.advance(k * 1e-3, InputSignal{});
  ASSERT_EQ(st, Status::SolverFailure);
  EXPECT_NE(plant.last_error().find("work_budget = 10"), std::string::npos) << plant.last_error();
  EXPECT_EQ(plant.contact_events(), 0) << "no contact was completed";
}

TEST(FixedStep, EnergyToleranceRefusesTheStepWhoseAuditResidualExceedsIt) {
  // RK4 through the default stops' bounce: its audit residual per step,
  // measured from outside (machine_outputs), then a tolerance of half the
  // largest: that step is refused with the figures and undone; twice it: none.
  const Params p;
  const int steps = 150;
  std::vector<double> residual;
  {
    Plant plant(model_of(p));
    ASSERT_EQ(plant.set_solver(settings_of(Solver::Rk4)), Status::Ok);
    ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
    double a = audit_of(plant);
    for (int k = 1; k <= steps; ++k) {
      ASSERT_EQ(plant.advance(k * 1e-3, InputSignal{}), Status::Ok);
      const double b = audit_of(plant);
      residual.push_back(std::fabs(b - a));
      a = b;
    }
  }
  const auto worst = std::max_element(residual.begin(), residual.end());
  ASSERT_GT(*worst, 0.0);
  const int k_worst = static_cast<int>(worst - residual.begin()) + 1;
  for (double factor : {0.5, 2.0}) {
    Plant plant(model_of(p));
    SolverSettings s = settings_of(Solver::Rk4);
    s.energy_tolerance = factor * *worst;
    ASSERT_EQ(plant.set_solver(s), Status::Ok);
    ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
    int k = 1;
    Status st = Status::Ok;
    for (; k <= steps; ++k) {
      const Vec8 y = plant.state();
      st = plant.advance(k * 1e-3, InputSignal{});
      if (st != Status::Ok) {
        EXPECT_EQ(plant.state(), y) << "the refused step is undone";
        break;
      }
    }
    if (factor < 1.0) {
      EXPECT_EQ(st, Status::SolverFailure);
      EXPECT_LE(k, k_worst) << "refused at the latest at the step of the largest residual";
      EXPECT_NE(plant.last_error().find("energy audit"), std::string::npos) << plant.last_error();
      EXPECT_NE(plant.last_error().find("energy_tolerance"), std::string::npos) << plant.last_error();
    } else {
      EXPECT_EQ(st, Status::Ok) << plant.last_error();
    }
  }
}

// A linear test system for ROS2 alone: four coupled, lightly damped
// oscillators x'' = -K x - C x' + b (1 + 50 t), the energy rows 0.
struct RampedOscillators {
  Eigen::Matrix<double, 8, 8> A;
  Vec8 b;
  RampedOscillators() {
    Mat4 K, C;
    K << 400, -50, 0, 0, -50, 300, -20, 0, 0, -20, 500, -40, 0, 0, -40, 250;
    C = 0.02 * K + 0.5 * Mat4::Identity();
    A.setZero();
    A.topRightCorner<4, 4>() = Mat4::Identity();
    A.bottomLeftCorner<4, 4>() = -K;
    A.bottomRightCorner<4, 4>() = -C;
    b.setZero();
    b.tail<4>() << 1.0, -2.0, 0.5, 3.0;
  }
  Vec8 f(double t, const Vec10& x) const { return A * x.head<8>() + (1.0 + 50.0 * t) * b; }
  Status rates(double t, const Vec10& x, Vec10& xdot) {
    xdot.head<8>() = f(t, x);
    xdot.tail<2>().setZero();
    return Status::Ok;
  }
  Status jacobian(double t, const Vec10& x, double, Vec10& xdot, Eigen::Matrix<double, 8, 8>& J, Vec8& f_t) {
    rates(t, x, xdot);
    J = A;
    f_t = 50.0 * b;
    return Status::Ok;
  }
};

TEST(FixedStep, RosenbrockIsOfOrderTwoAndItsEstimateOfOrderOne) {
  // Richardson, no reference needed: with y_h the state at T after steps of
  // h, |y_h - y_h/2| / |y_h/2 - y_h/4| = 2^p for a method of order p. The
  // embedded estimate of one step from the same point is the first-order
  // solution's local error: it falls by 2^2 per halving.
  RampedOscillators sys;
  Vec10 y0 = Vec10::Zero();
  y0.head<4>() << 0.01, -0.02, 0.005, 0.0;
  auto end_state = [&](double h) {
    Vec10 y = y0, e;
    const int n = static_cast<int>(std::lround(0.2 / h));
    for (int k = 0; k < n; ++k) EXPECT_EQ(ros2_step(sys, k * h, h, y, e), Status::Ok);
    return y;
  };
  std::vector<Vec10> y;
  for (double h : {2e-3, 1e-3, 5e-4, 2.5e-4}) y.push_back(end_state(h));
  for (size_t i = 0; i + 2 < y.size(); ++i) {
    const double order = std::log2((y[i] - y[i + 1]).norm() / (y[i + 1] - y[i + 2]).norm());
    std::printf("ROS2, Richardson: observed order %.3f\n", order);
    EXPECT_NEAR(order, 2.0, 0.15);
  }
  double previous = 0.0;
  for (double h : {4e-3, 2e-3, 1e-3, 5e-4}) {
    Vec10 y1 = y0, e;
    ASSERT_EQ(ros2_step(sys, 0.0, h, y1, e), Status::Ok);
    if (previous > 0.0) {
      const double order = std::log2(previous / e.norm());
      std::printf("ROS2's embedded estimate, h = %g s: falls as h^%.3f\n", h, order);
      EXPECT_NEAR(order, 2.0, 0.1);
    }
    previous = e.norm();
  }
}

TEST(FixedStep, RosenbrockAgreesWithCvodeAtEveryImpactOfTheDefaultDrop) {
  // The default machine dropped onto its stops (F = 0, the stops reached at
  // 95 ms, two more impacts before it rests): before, ROS2 answered every
  // step OK while 9.07 % of max |dz| off CVODE at the second impact (t =
  // 0.183 s), its rebound speed 0.405162 m/s against 0.407390 m/s. The
  // cause: its fixed sub-steps in the ringing contact (h omega = 0.05) left
  // 0.24 % in the rebound speed, which shifts the next impact in time by 2
  // dv / g; the contact's deceleration turns the shift into 38 times that
  // error. Its error estimate now keeps every step within its tolerance.
  expect_agrees(Params{}, Solver::Rosenbrock, kRosenbrockBound, 300);
}

TEST(FixedStep, RosenbrockAnswersDiscardWithItsEstimateWhereItsBudgetCannotMeetIt) {
  // 1e7 N/m stops, lightly damped (the default 100 N.s/m): the contact rings
  // at about 6e3 rad/s and ROS2's estimate asks for steps of about 3e-7 s,
  // 2000 per 1 ms grid step, twice the default budget: the step that reaches
  // the stops is refused with the estimate, the state kept at the last whole
  // step.
  Params p;
  p.stop_stiffness = 1e7;
  Plant plant(model_of(p));
  ASSERT_EQ(plant.set_solver(settings_of(Solver::Rosenbrock)), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  Status st = Status::Ok;
  int k = 0;
  while (st == Status::Ok && k < 200) st = plant.advance(++k * 1e-3, InputSignal{});
  ASSERT_EQ(st, Status::SolverFailure);
  EXPECT_EQ(plant.time(), (k - 1) * 1e-3);
  for (const char* part : {"work budget", "error estimate", "times its tolerance", "stop_stiffness = 1e+07", "CVODE"})
    EXPECT_NE(plant.last_error().find(part), std::string::npos) << plant.last_error();
  // With the budget it asks for, the same step is answered within 1 % of CVODE.
  SolverSettings more = settings_of(Solver::Rosenbrock);
  more.work_budget = 1e4;
  Plant ok(model_of(p)), ref(model_of(p));
  ASSERT_EQ(ok.set_solver(more), Status::Ok);
  ASSERT_EQ(ref.set_solver(settings_of(Solver::Cvode)), Status::Ok);
  ASSERT_EQ(ok.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  ASSERT_EQ(ref.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  double worst = 0.0, scale = 0.0;
  for (int j = 1; j <= k; ++j) {
    ASSERT_EQ(ok.advance(j * 1e-3, InputSignal{}), Status::Ok) << ok.last_error();
    ASSERT_EQ(ref.advance(j * 1e-3, InputSignal{}), Status::Ok);
    worst = std::max(worst, std::fabs(ok.state()[6] - ref.state()[6]));
    scale = std::max(scale, std::fabs(ref.state()[6]));
  }
  EXPECT_LE(worst, kRosenbrockBound * scale);
}

TEST(FixedStep, OneAdvanceIsBoundedWhateverItsLength) {
  // Before: RK4 at the stiffest declared stops took 1.5 / 14-17 / 205 s for
  // one advance of 1 / 10 / 100 s before giving up (a budget of work_budget
  // per grid step, 1e8 inner steps for 100 s). Now every advance is capped:
  // the fixed-step solvers at kMaxInnerStepsPerCall inner steps (RK4: 4
  // evaluations each; ROS2: one Jacobian and one evaluation), CVODE at
  // kMaxCvodeEvaluationsPerCall evaluations, whatever the span. Asserted on
  // the evaluations counted; the wall times are printed.
  const Params p = stiff_stops(1e-6);
  for (Solver solver : {Solver::Cvode, Solver::Rk4, Solver::Rosenbrock}) {
    for (double span : {10.0, 100.0}) {
      Plant plant(model_of(p));
      SolverSettings s;  // the defaults, as a user would leave them
      s.solver = solver;
      ASSERT_EQ(plant.set_solver(s), Status::Ok);
      ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
      const long before = plant.rhs_evaluations();
      const auto t0 = std::chrono::steady_clock::now();
      const Status st = plant.advance(span, InputSignal{});
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const long evaluations = plant.rhs_evaluations() - before;
      const double cap = solver == Solver::Cvode ? kMaxCvodeEvaluationsPerCall
                         : solver == Solver::Rk4 ? 4.0 * kMaxInnerStepsPerCall
                                                 : 2.0 * kMaxInnerStepsPerCall;
      std::printf("solver %d, one advance of %g s at the stiffest stops: %s after %ld evaluations (cap %.0f), %.3f s\n",
                  static_cast<int>(solver), span, status_name(st), evaluations, cap, seconds);
      EXPECT_LE(evaluations, cap);
      if (st != Status::Ok) {
        EXPECT_LT(plant.time(), span) << "a failed advance keeps the state at its start or its last whole step";
        EXPECT_EQ(st, Status::SolverFailure);
        EXPECT_NE(plant.last_error().find(solver == Solver::Cvode ? "the most one call may take" : "per call"),
                  std::string::npos)
            << plant.last_error();
      }
    }
  }
  // CVODE at its tightest declared tolerances over 100 s of the default
  // drop: the cap ends it, with the reason.
  Plant plant(model_of(Params{}));
  SolverSettings s;
  s.rtol = kMinRtol;
  s.atol = kMinAtol;
  ASSERT_EQ(plant.set_solver(s), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  EXPECT_EQ(plant.advance(100.0, InputSignal{}), Status::SolverFailure);
  EXPECT_LE(plant.rhs_evaluations(), kMaxCvodeEvaluationsPerCall + 10);  // and initialize()'s few
  EXPECT_NE(plant.last_error().find("the most one call may take"), std::string::npos) << plant.last_error();
  EXPECT_EQ(plant.time(), 0.0) << "CVODE's failed advance keeps the state at its start";
}
