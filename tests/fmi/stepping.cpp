// SPDX-License-Identifier: BSD-2-Clause
// Communication steps of the FMU binaries through the raw FMI 2.0
// functions: the static forces hold the home pose (CVODE and RK4), a failed
// step is discarded with the last good state kept, input derivatives are
// interpolated within a step, the inverse FMU's static forces, its output
// groups (the same values whichever is read first) and its
// refusal of unreachable poses; bad, overflowing, vanishing, too long and
// past-stopTime steps, huge finite inputs, and the motion's independence of
// the start time.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"

namespace {

using namespace pkm_test;

class Stepping : public FmuTest {};

TEST_F(Stepping, HoldsTheHomePoseWithTheStaticForces) {
  PlantFmu p;
  ASSERT_NE(p.c, nullptr);
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set("F[" + std::to_string(i) + "]", kStaticForce), fmi2OK);
  double t = 0.0;
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    ASSERT_EQ(lib.fmi2DoStep(p.c, t, 1e-3, fmi2True), fmi2OK) << "step " << k << "\n" << p.log.dump();
    t = (k + 1) * 1e-3;
    const double dev[4] = {p.get("x"), p.get("y"), p.get("z") - 0.05, p.get("phi")};
    for (double d : dev) worst = std::max(worst, std::abs(d));
  }
  EXPECT_LE(worst, 1e-9) << "largest deviation from the home pose over 2 s";
  double last;
  ASSERT_EQ(lib.fmi2GetRealStatus(p.c, fmi2LastSuccessfulTime, &last), fmi2OK);
  EXPECT_NEAR(last, 2.0, 1e-12);
  EXPECT_LT(p.get("constraint_residual"), 1e-12);
  EXPECT_NEAR(p.get("rho[1]"), 0.0443193423, 1e-10);  // docs/model.md golden pose
  EXPECT_NEAR(p.get("theta2[2]"), -0.8606121019, 1e-10);
  EXPECT_TRUE(std::isfinite(p.get("jacobian_condition")));
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  EXPECT_TRUE(p.log.messages.empty()) << p.log.dump();
}

TEST_F(Stepping, Rk4HoldsTheHomePoseToo) {
  PlantFmu p;
  ASSERT_EQ(p.set_int("solver", 1), fmi2OK);
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set("F[" + std::to_string(i) + "]", kStaticForce), fmi2OK);
  for (int k = 0; k < 200; ++k) ASSERT_EQ(lib.fmi2DoStep(p.c, k * 1e-2, 1e-2, fmi2True), fmi2OK);
  EXPECT_NEAR(p.get("z"), 0.05, 1e-9);
  EXPECT_NEAR(p.get("x"), 0.0, 1e-9);
}

TEST_F(Stepping, AFailedStepIsDiscardedWithTheLastGoodStateKept) {
  for (int solver : {0, 1}) {
    SCOPED_TRACE(solver == 0 ? "CVODE" : "RK4");
    PlantFmu p;
    ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
    p.initialize();
    // A large horizontal push drives the platform out of the workspace.
    ASSERT_EQ(p.set("Fe[1]", 50.0), fmi2OK);
    double t = 0.0;
    const double h = 0.01;
    fmi2Status st = fmi2OK;
    fmi2FMUstate good = nullptr;
    int k = 0;
    for (; k < 100; ++k) {
      ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &good), fmi2OK);
      st = lib.fmi2DoStep(p.c, t, h, fmi2True);
      if (st != fmi2OK) break;
      t += h;
    }
    ASSERT_EQ(st, fmi2Discard) << "after " << k << " steps\n" << p.log.dump();
    EXPECT_TRUE(p.log.contains("failed")) << p.log.dump();  // discards are reported by default
    EXPECT_EQ(p.log.messages.back().status, fmi2Discard);
    double last = -1.0;
    ASSERT_EQ(lib.fmi2GetRealStatus(p.c, fmi2LastSuccessfulTime, &last), fmi2OK);
    EXPECT_GE(last, t);
    EXPECT_LT(last, t + h);
    if (solver == 0) {
      EXPECT_EQ(last, t) << "CVODE keeps the state of the step start";
    }
    fmi2Boolean terminated = fmi2False;
    ASSERT_EQ(lib.fmi2GetBooleanStatus(p.c, fmi2Terminated, &terminated), fmi2OK);
    EXPECT_EQ(terminated, fmi2True);
    // The outputs at the last good point are finite.
    for (double v : p.outputs()) EXPECT_TRUE(std::isfinite(v));
    EXPECT_LT(p.get("constraint_residual"), 1e-9);
    // No further steps; but back to a saved state, the instance can go on.
    EXPECT_EQ(lib.fmi2DoStep(p.c, last, h, fmi2True), fmi2Error);
    ASSERT_EQ(lib.fmi2SetFMUstate(p.c, good), fmi2OK) << p.log.dump();
    ASSERT_EQ(p.set("Fe[1]", 0.0), fmi2OK);
    EXPECT_EQ(lib.fmi2DoStep(p.c, t, 1e-3, fmi2True), fmi2OK) << p.log.dump();
    lib.fmi2FreeFMUstate(p.c, &good);
  }
}

TEST_F(Stepping, InputDerivativesInterpolateWithinAStep) {
  // One step of 20 ms with F = F0 + dF (t - t0) against 200 steps of 0.1 ms
  // with the inputs held at their midpoint values: the same ramp, sampled.
  // RK4 with 0.1 ms steps in both, so that the only difference is the
  // sampling, O(1/n^2) relative (CVODE's rtol would hide it).
  PlantFmu ramp, steps;
  for (PlantFmu* p : {&ramp, &steps}) {
    ASSERT_EQ(p->set_int("solver", 1), fmi2OK);
    ASSERT_EQ(p->set("rk4_step", 1e-4), fmi2OK);
    p->initialize();
  }
  const double F0 = kStaticForce, dF = 0.5, T = 0.02;
  for (int i = 1; i <= 4; ++i) {
    const std::string F = "F[" + std::to_string(i) + "]";
    ASSERT_EQ(ramp.set(F, F0), fmi2OK);
    ASSERT_EQ(ramp.set_derivative(F, i == 1 ? dF : 0.0), fmi2OK);
  }
  ASSERT_EQ(lib.fmi2DoStep(ramp.c, 0.0, T, fmi2True), fmi2OK);
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    const double tm = (k + 0.5) * T / n;
    for (int i = 1; i <= 4; ++i)
      ASSERT_EQ(steps.set("F[" + std::to_string(i) + "]", F0 + (i == 1 ? dF * tm : 0.0)), fmi2OK);
    ASSERT_EQ(lib.fmi2DoStep(steps.c, k * T / n, T / n, fmi2True), fmi2OK);
  }
  const double dz = ramp.get("z") - 0.05;
  EXPECT_GT(std::abs(dz), 1e-8) << "the ramp moved the platform";
  EXPECT_NEAR(ramp.get("z"), steps.get("z"), 1e-4 * std::abs(dz));
  EXPECT_NEAR(ramp.get("dz"), steps.get("dz"), 1e-4 * std::abs(ramp.get("dz")));
  // After the step the input holds its value at the new time ...
  EXPECT_NEAR(ramp.get("F[1]"), F0 + dF * T, 1e-15);
  EXPECT_EQ(ramp.get("F[2]"), F0);
  // ... and setting the value clears the derivative: constant from now on.
  PlantFmu held;
  held.initialize();
  for (int i = 1; i <= 4; ++i) {
    const std::string F = "F[" + std::to_string(i) + "]";
    ASSERT_EQ(held.set_derivative(F, 3.0), fmi2OK);
    ASSERT_EQ(held.set(F, kStaticForce), fmi2OK);
  }
  for (int k = 0; k < 10; ++k) ASSERT_EQ(lib.fmi2DoStep(held.c, k * 1e-2, 1e-2, fmi2True), fmi2OK);
  EXPECT_NEAR(held.get("z"), 0.05, 1e-12);
  EXPECT_EQ(held.get("F[1]"), kStaticForce);
  // Higher orders are ignored with a warning; non-inputs are errors.
  const fmi2ValueReference f1 = ramp.vr("F[1]"), x = ramp.vr("x");
  const fmi2Integer order2 = 2;
  const double one = 1.0;
  EXPECT_EQ(lib.fmi2SetRealInputDerivatives(ramp.c, &f1, 1, &order2, &one), fmi2Warning);
  EXPECT_EQ(ramp.set_derivative("x", 1.0), fmi2Error);
  (void)x;
  // The inverse FMU does not interpolate.
  InverseFmu inv;
  EXPECT_EQ(inv.set_derivative("x", 1.0), fmi2Error);
}


TEST_F(Stepping, InverseAtRestAtHomeGivesTheStaticForces) {
  InverseFmu inv;
  ASSERT_NE(inv.c, nullptr);
  inv.initialize();
  FmuLibrary& ilib = inverse_library();
  double sum = 0.0;
  for (int i = 1; i <= 4; ++i) {
    const double F = inv.get("F[" + std::to_string(i) + "]");
    EXPECT_NEAR(F, kStaticForce, 1e-9) << "F[" << i << "]";
    sum += F;
  }
  EXPECT_NEAR(sum, 10.622464200, 1e-9);
  EXPECT_NEAR(inv.get("rho[2]"), 0.0443193423, 1e-10);
  EXPECT_EQ(inv.get("drho[2]"), 0.0);
  // Time advances; the outputs follow the inputs at each communication point.
  ASSERT_EQ(ilib.fmi2DoStep(inv.c, 0.0, 1e-3, fmi2True), fmi2OK);
  ASSERT_EQ(inv.set("x", 0.005), fmi2OK);
  ASSERT_EQ(inv.set("y", -0.005), fmi2OK);
  ASSERT_EQ(inv.set("z", 0.07), fmi2OK);
  ASSERT_EQ(inv.set("phi", 4.0 * kPi / 180.0), fmi2OK);
  EXPECT_NEAR(inv.get("rho[1]"), 0.0676488698, 1e-10);  // docs/model.md golden pose
  EXPECT_NEAR(inv.get("rho[4]"), 0.0792527515, 1e-10);
  // Gravity off, at rest: no force.
  InverseFmu zero_g;
  ASSERT_EQ(zero_g.set("g", 0.0), fmi2OK);
  zero_g.initialize();
  for (int i = 1; i <= 4; ++i) EXPECT_NEAR(zero_g.get("F[" + std::to_string(i) + "]"), 0.0, 1e-15);
}

TEST_F(Stepping, InverseOutputGroupsAgreeWhicheverIsReadFirst) {
  // The outputs are computed by group, each on the first get that reads it
  // (forces; multipliers; condition number): read alone, in either order or
  // all at once after an input changed, each is the same, bit for bit, and
  // the forces and multipliers are the general path's (Newton on the servo
  // constraints, Eqs. 10-11 in full) to 1e-12.
  const char* in[16] = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi",
                        "ddx", "ddy", "ddz", "ddphi", "Fe[1]", "Fe[2]", "Fe[3]", "Me_z"};
  const double u[16] = {0.004, -0.003, 0.062, 0.05, 0.02, -0.01, 0.03, 0.2,
                        0.5, -0.3, 0.8, 4.0, 0.1, -0.2, 0.3, 0.01};
  std::vector<std::string> names;
  for (int i = 1; i <= 4; ++i) names.push_back(force_name(i));
  for (int i = 1; i <= 12; ++i) names.push_back("lambda[" + std::to_string(i) + "]");
  names.push_back("jacobian_condition");
  FmuLibrary& ilib = inverse_library();
  auto read = [&](InverseFmu& f, const std::vector<int>& which) {
    std::vector<fmi2ValueReference> vr;
    for (int k : which) vr.push_back(f.vr(names[static_cast<size_t>(k)]));
    std::vector<double> v(vr.size(), -1.0);
    EXPECT_EQ(ilib.fmi2GetReal(f.c, vr.data(), vr.size(), v.data()), fmi2OK) << f.log.dump();
    return v;
  };
  std::vector<int> all(names.size()), forces = {0, 1, 2, 3}, lambda, condition = {16};
  for (size_t k = 0; k < names.size(); ++k) all[k] = static_cast<int>(k);
  for (int k = 4; k < 16; ++k) lambda.push_back(k);
  InverseFmu a("a"), b("b"), c("c");
  for (InverseFmu* f : {&a, &b, &c}) {
    f->initialize();
    (void)read(*f, all);  // at the start values: every group valid
    for (int k = 0; k < 16; ++k) ASSERT_EQ(f->set(in[k], u[k]), fmi2OK);
  }
  const std::vector<double> together = read(a, all);
  const std::vector<double> lam_b = read(b, lambda), cond_b = read(b, condition), F_b = read(b, forces);
  const std::vector<double> F_c = read(c, forces), cond_c = read(c, condition), lam_c = read(c, lambda);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(F_b[static_cast<size_t>(k)], together[static_cast<size_t>(k)]);
    EXPECT_EQ(F_c[static_cast<size_t>(k)], together[static_cast<size_t>(k)]);
  }
  for (int k = 0; k < 12; ++k) {
    EXPECT_EQ(lam_b[static_cast<size_t>(k)], together[static_cast<size_t>(4 + k)]);
    EXPECT_EQ(lam_c[static_cast<size_t>(k)], together[static_cast<size_t>(4 + k)]);
  }
  EXPECT_EQ(cond_b[0], together[16]);
  EXPECT_EQ(cond_c[0], together[16]);
  pkm::Model m;
  ASSERT_EQ(pkm::make_model(pkm::Params{}, m), pkm::Status::Ok);
  pkm::InverseDynamicsResult g;
  ASSERT_EQ(pkm::inverse_dynamics_general(m, pkm::Pose(u[0], u[1], u[2], u[3]), pkm::Pose(u[4], u[5], u[6], u[7]),
                                          pkm::Pose(u[8], u[9], u[10], u[11]), pkm::Wrench(u[12], u[13], u[14], u[15]),
                                          g),
            pkm::Status::Ok);
  const double F_scale = g.F.cwiseAbs().maxCoeff(), lam_scale = g.lambda.cwiseAbs().maxCoeff();
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(together[static_cast<size_t>(k)], g.F[k], 1e-12 * F_scale);
  for (int k = 0; k < 12; ++k) EXPECT_NEAR(together[static_cast<size_t>(4 + k)], g.lambda[k], 1e-12 * lam_scale);
}

TEST_F(Stepping, InverseRejectsAnUnreachablePoseWithoutNaN) {
  InverseFmu inv;
  inv.initialize();
  FmuLibrary& ilib = inverse_library();
  ASSERT_EQ(inv.set("x", 0.2), fmi2OK);
  const fmi2ValueReference F1 = inv.vr("F[1]");
  double value = 12345.0;
  EXPECT_EQ(ilib.fmi2GetReal(inv.c, &F1, 1, &value), fmi2Error);
  EXPECT_EQ(value, 12345.0) << "nothing written";
  EXPECT_TRUE(inv.log.contains("unreachable")) << inv.log.dump();
  // Reachable again: outputs again.
  ASSERT_EQ(inv.set("x", 0.0), fmi2OK);
  EXPECT_NEAR(inv.get("F[1]"), kStaticForce, 1e-9);
}

TEST_F(Stepping, BadCommunicationSteps) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  on_stepping_instance(
      "fmi2DoStep with communicationStepSize 0, -1e-3, NaN, +Inf, -Inf",
      fmi2Error, "fmi2Error, \"communicationStepSize = ... must be positive and finite; the call has no effect\"",
      [&](PlantFmu& p, double t) {
        return std::vector<fmi2Status>{p.step(t, 0.0), p.step(t, -1e-3), p.step(t, nan), p.step(t, inf),
                                       p.step(t, -inf)};
      });
  on_stepping_instance(
      "fmi2DoStep whose currentCommunicationPoint is not the FMU's time: t + 1 ms (skipping ahead), t - 1 ms "
      "(going back), 0, NaN, +Inf",
      fmi2Error,
      "fmi2Error, \"currentCommunicationPoint = ... differs from the FMU's time ...; the call has no effect\"",
      [&](PlantFmu& p, double t) {
        return std::vector<fmi2Status>{p.step(t + 1e-3, 1e-3), p.step(t - 1e-3, 1e-3), p.step(0.0, 1e-3),
                                       p.step(nan, 1e-3), p.step(inf, 1e-3)};
      });
}

// Issue 27 item 5: a first CVODE step of 1e-200 s passed the FMU's checks,
// then CVODE could not start (its first-step estimate squares the span) and
// the run was over (fmi2Discard, StepFailed). FMI 2.0.4 section 4.2.3
// (fmi2DoStep) and FMI 3.0.2 section 4.2.3: an argument the FMU cannot use is
// an Error; this FMU refuses it before any work, the instance unchanged. The
// bound is sqrt(DBL_MIN) = 2^-511 s (pkm::kMinCvodeSpan): accepted at it,
// refused below.
TEST_F(Stepping, AFirstCvodeStepTooShortToStartIsRefusedWithoutEffect) {
  PlantFmu p;
  p.initialize();
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(0.0, 1e-200), fmi2Error) << p.log.dump();
  EXPECT_TRUE(p.log.contains("shorter than CVODE can start with")) << p.log.dump();
  EXPECT_EQ(p.step(0.0, std::ldexp(1.0, -512)), fmi2Error);
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  const double shortest = std::ldexp(1.0, -511);  // sqrt(DBL_MIN): its square is the smallest normal double
  EXPECT_EQ(shortest * shortest, std::numeric_limits<double>::min());
  EXPECT_EQ(p.step(0.0, shortest), fmi2OK) << p.log.dump();
  EXPECT_EQ(p.step(shortest, 1e-3), fmi2OK) << p.log.dump();
}

TEST_F(Stepping, AStepWhoseEndOverflowsIsAnError) {
  PlantFmu p;
  p.initialize(1e308);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(1e308, 1e308), fmi2Error);
  EXPECT_TRUE(p.log.contains("is not finite; the call has no effect")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  EXPECT_EQ(p.last_successful_time(), 1e308);
  table_row("startTime = 1e308, then fmi2DoStep(1e308, 1e308): the step's end overflows to +Inf",
            "fmi2Error, \"currentCommunicationPoint + communicationStepSize = inf is not finite; the call has no "
            "effect\"",
            "yes: every variable bit-identical, time unchanged");
}

// At t = 1e15 a 1 ms step rounds away (the spacing of doubles
// there is 0.125 s): answering OK would advance nothing.
TEST_F(Stepping, AStepThatVanishesInTPlusHIsAnError) {
  PlantFmu p;
  p.initialize(1e15);
  ASSERT_EQ(1e15 + 1e-3, 1e15);  // the premise
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(1e15, 1e-3), fmi2Error);
  EXPECT_TRUE(p.log.contains("vanishes at currentCommunicationPoint")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  // The instance stays usable: a step that does advance.
  EXPECT_EQ(p.step(1e15, 1.0), fmi2OK) << p.log.dump();
  EXPECT_EQ(p.last_successful_time(), 1e15 + 1.0);
  table_row("startTime = 1e15, then fmi2DoStep(1e15, 1e-3): t + h == t in double precision",
            "fmi2Error, \"communicationStepSize = 0.001 vanishes at currentCommunicationPoint = 1e+15 ...\"",
            "yes: every variable bit-identical; a later step of 1 s succeeds");
}

// At startTime 1e9 s, t + 1 ms rounds to a multiple of 0.12 us;
// the model used to integrate (t + h) - t, 7e-5 s lost over 1 s. It
// integrates the time since start: the motion is that of a start at 0.
TEST_F(Stepping, TheMotionDoesNotDependOnTheStartTime) {
  for (int solver : {0, 1}) {
    SCOPED_TRACE(solver == 0 ? "CVODE" : "RK4");
    PlantFmu late("late"), early("early");
    for (PlantFmu* p : {&late, &early}) {
      ASSERT_EQ(p->set_int("solver", solver), fmi2OK);
      const double start = p == &late ? 1e9 : 0.0;
      p->initialize(start);
      double t = start;
      for (int k = 0; k < 1000; ++k) {
        drive_forces(*p, k * 1e-3);  // the same forces at the same time since start
        ASSERT_EQ(p->step(t, 1e-3), fmi2OK) << p->log.dump();
        t += 1e-3;  // as a master counts: at 1e9 each addition rounds
      }
      EXPECT_EQ(p->get("time"), t) << "the FMU's time is the master's";
    }
    EXPECT_TRUE(bit_identical(late.outputs(), early.outputs()))
        << "x after 1 s: " << late.get("x") << " (start 1e9) vs " << early.get("x") << " (start 0)";
  }
  table_row("startTime = 1e9 s, 1000 steps of 1 ms (the master's t += h rounds at every step), CVODE and RK4",
            "fmi2OK; the model integrates the time since start (the sum of the step sizes)",
            "yes: every output after 1 s bit-identical to a run started at 0");
}

TEST_F(Stepping, AStepTooLongForCvodeIsDiscarded) {
  PlantFmu p;
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), kStaticForce + 0.01 * i), fmi2OK);
  ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(1e-3, 1e6), fmi2Discard);
  EXPECT_TRUE(p.log.contains("CVODE evaluated the state derivative 100000 times in this call")) << p.log.dump();
  EXPECT_TRUE(p.terminated());
  EXPECT_EQ(p.last_successful_time(), 1e-3);
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  table_row("CVODE, fmi2DoStep(h = 1e6 s): more than the 100000 evaluations one call may take",
            "fmi2Discard, fmi2Terminated = true (\"CVODE evaluated the state derivative 100000 times in this call "
            "..., the most one call may take\")",
            "yes: every variable bit-identical at fmi2LastSuccessfulTime = the step start");
}

// FMI 2.0.4 section 2.1.6 (fmi2SetupExperiment): "if the environment tries to
// compute past stopTime the FMU has to return fmi2Error"; a communication step
// ending past it computes past it.
TEST_F(Stepping, AStepPastTheStopTimeIsAnError) {
  PlantFmu p;
  p.initialize(0.0, 0.01);
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), kStaticForce), fmi2OK);
  for (int k = 0; k < 9; ++k) ASSERT_EQ(p.step(k * 1e-3, 1e-3), fmi2OK);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(0.009, 2e-3), fmi2Error);
  EXPECT_TRUE(p.log.contains("the end of the communication step at t = 0.0109")) << p.log.dump();
  EXPECT_TRUE(p.log.contains("lies past stopTime = 0.01")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  EXPECT_EQ(p.step(0.009, 1e-3 + 1e-15), fmi2OK) << "rounding of the last step is tolerated\n" << p.log.dump();
  EXPECT_EQ(p.step(0.01, 1e-3), fmi2Error);
  table_row("fmi2SetupExperiment(stopTimeDefined, stopTime = 0.01 s), then fmi2DoStep(0.009, 0.002) past it",
            "fmi2Error (FMI 2.0: computing past a defined stopTime), \"the end of the communication step at t = "
            "0.011 lies past stopTime = 0.01 ...; the call has no effect\"",
            "yes: every variable bit-identical; the step to exactly stopTime (within 1e-9 relative) succeeds");
}

TEST_F(Stepping, TooManyRk4StepsAreRefusedBeforeAnyWork) {
  // The smallest rk4_step its range allows (1e-6 s): a 0.2 s step needs 2e5
  // RK4 steps, twice what one call may take (1e5 inner steps, whatever the
  // step's length: docs/solvers.md "The work budget").
  PlantFmu p("refused"), twin("twin");
  for (PlantFmu* q : {&p, &twin}) {
    slow_rk4(*q);
    drive_forces(*q, 0.0);
  }
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(0.0, 0.2), fmi2Error);
  EXPECT_TRUE(p.log.contains("more than the 100000 inner steps one call may take")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  // Usable as it was (no Reset, no SetFMUstate): the next step is the twin's.
  ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
  ASSERT_EQ(twin.step(0.0, 1e-3), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs()));
  table_row("RK4 with rk4_step = 1e-6 s (the smallest its range allows), then fmi2DoStep(h = 0.2 s): 2e5 RK4 steps",
            "fmi2Error at once, \"a communication step of 0.2 s needs 2e+05 fixed steps of rk4_step = 1e-06 s, more "
            "than the 100000 inner steps one call may take ...; the call has no effect\"",
            "yes: every variable bit-identical; the next step bit-identical to an untouched twin's");
}

TEST_F(Stepping, OneLongStepAtTheStiffestStopsEndsWithinItsCap) {
  // Before: RK4 at stop_stiffness 1e9, stop_damping 1e6 spent 14-17 s in
  // fmi2DoStep(0, 10 s) and 205 s in fmi2DoStep(0, 100 s) before its
  // Discard. Now every call is capped (1e5 inner steps of RK4 or ROS2, 1e5
  // evaluations of CVODE; tests/core/fixed_step.cpp asserts the work
  // counted): each solver answers OK or Discard with the reason. The wall
  // times are printed.
  for (int solver : {0, 1, 2}) {
    for (double span : {10.0, 100.0}) {
      PlantFmu p;
      ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
      ASSERT_EQ(p.set("stop_stiffness", 1e9), fmi2OK);
      ASSERT_EQ(p.set("stop_damping", 1e6), fmi2OK);
      ASSERT_EQ(p.set("m_slider", 1e-6), fmi2OK);
      p.initialize();
      for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), 0.0), fmi2OK);
      const auto t0 = std::chrono::steady_clock::now();
      const fmi2Status st = p.step(0.0, span);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("solver %d, fmi2DoStep(0, %g s) at the stiffest stops: %s in %.3f s\n", solver, span,
                  st == fmi2OK ? "fmi2OK" : st == fmi2Discard ? "fmi2Discard" : "another status", seconds);
      ASSERT_TRUE(st == fmi2OK || st == fmi2Discard) << p.log.dump();
      if (st == fmi2Discard) {
        EXPECT_TRUE(p.log.contains("per call") || p.log.contains("the most one call may take")) << p.log.dump();
      }
    }
  }
}

TEST_F(Stepping, HugeFiniteInputsEndTheStepWithADiscard) {
  for (int solver : {0, 1}) {
    PlantFmu p;
    ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
    p.initialize();
    const std::vector<double> before = p.outputs();
    ASSERT_EQ(p.set("F[3]", 1e300), fmi2OK);
    EXPECT_EQ(p.step(0.0, 1e-3), fmi2Discard) << p.log.dump();
    EXPECT_TRUE(p.terminated());
    EXPECT_EQ(p.last_successful_time(), 0.0);
    const std::vector<double> after = p.outputs();
    EXPECT_TRUE(all_finite(after));
    // The state is that of t = 0; only lambda (which depends on the input at t) differs.
    for (std::size_t k = 0; k < 24; ++k) EXPECT_EQ(after[k], before[k]) << "pose, velocity, rho, drho, theta1, theta2";
  }
  table_row("F[3] = 1e300 N (finite, absurd), then fmi2DoStep, CVODE and RK4",
            "fmi2Discard, fmi2Terminated = true (RK4: \"pose unreachable\"; CVODE: \"the corrector convergence test "
            "failed repeatedly or with |h| = hmin\" -- before the fixes CVODE 6.4 reported success there, with the "
            "state unchanged)",
            "yes: pose and velocity bit-identical at fmi2LastSuccessfulTime = 0, all outputs finite");
}

}  // namespace
