// SPDX-License-Identifier: BSD-2-Clause
// The FMU binaries' state machine, driven through the raw FMI 2.0 functions
// as an importer would (dlopen): version and platform, calls out of the
// co-simulation state machine's order before, during and after
// initialisation and after a failed step, functions this FMU does not
// provide, reset, independent instances, status kinds the standard does not
// define, and the error policy as a table. Each answer is what the standard
// prescribes, nothing crashes, nothing is written outside the instance
// (canaries around every output buffer), and an instance that was stepping
// goes on bit-identically to an untouched twin. (Arguments no call may
// take, NULL and foreign handles among them: bad_arguments.cpp.)
// Every misuse prints a row of the hardening table ("| tried | answer | kept |").
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"
#include "reference_model.hpp"

namespace {

using namespace pkm_test;

TEST_F(StateMachine, VersionAndPlatform) {
  EXPECT_STREQ(lib.fmi2GetVersion(), "2.0");
  EXPECT_STREQ(lib.fmi2GetTypesPlatform(), "default");
}

TEST_F(StateMachine, OutOfOrderCallsAreErrorsWithoutEffect) {
  PlantFmu p;
  ASSERT_NE(p.c, nullptr);
  double value = 0.0;
  const fmi2ValueReference x = p.vr("x");
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);          // before initialisation
  EXPECT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2Error);               // not in initialisation mode
  EXPECT_EQ(lib.fmi2GetReal(p.c, &x, 1, &value), fmi2Error);               // no outputs yet
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2Error);
  fmi2Status st;
  EXPECT_EQ(lib.fmi2GetStatus(p.c, fmi2DoStepStatus, &st), fmi2Error);
  EXPECT_TRUE(p.log.contains("illegal call sequence")) << p.log.dump();
  // A NULL component is an error, not a crash.
  EXPECT_EQ(lib.fmi2DoStep(nullptr, 0.0, 1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(lib.fmi2GetReal(nullptr, &x, 1, &value), fmi2Error);
  lib.fmi2FreeInstance(nullptr);

  // The instance is still usable: the normal sequence works.
  ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
  ASSERT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2OK);
  EXPECT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2Error);  // too late
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
  ASSERT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2OK);
  EXPECT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2Error);
  // Parameters are fixed after initialisation, outputs never settable.
  EXPECT_EQ(p.set("l", 0.09), fmi2Error);
  EXPECT_EQ(p.set("x", 0.01), fmi2Error);
  EXPECT_EQ(p.set_int("solver", 1), fmi2Error);
  EXPECT_NEAR(p.get("l"), 0.08, 0.0);
  // Wrong step arguments.
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.5, 1e-3, fmi2True), fmi2Error);  // not the current time
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 0.0, fmi2True), fmi2Error);
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, -1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2OK) << p.log.dump();
  EXPECT_EQ(lib.fmi2GetStatus(p.c, fmi2DoStepStatus, &st), fmi2OK);
  EXPECT_EQ(st, fmi2OK);
  EXPECT_EQ(lib.fmi2CancelStep(p.c), fmi2Error);
  EXPECT_EQ(lib.fmi2GetRealOutputDerivatives(p.c, &x, 1, nullptr, &value), fmi2Error);
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  EXPECT_EQ(lib.fmi2DoStep(p.c, 1e-3, 1e-3, fmi2True), fmi2Error);  // after termination
  EXPECT_EQ(lib.fmi2Reset(p.c), fmi2OK);
}

TEST_F(StateMachine, ResetReturnsToTheStartValues) {
  PlantFmu a;
  ASSERT_EQ(a.set("z0", 0.06), fmi2OK);
  a.initialize();
  ASSERT_EQ(a.set("F[2]", 3.0), fmi2OK);
  ASSERT_EQ(lib.fmi2DoStep(a.c, 0.0, 1e-2, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Reset(a.c), fmi2OK);
  a.initialize();
  EXPECT_EQ(a.get("z0"), 0.05);
  EXPECT_EQ(a.get("F[2]"), kStaticForce);  // its start value (docs/model.md)
  EXPECT_EQ(a.get("z"), 0.05);
  PlantFmu b;
  b.initialize();
  ASSERT_EQ(lib.fmi2DoStep(a.c, 0.0, 1e-2, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2DoStep(b.c, 0.0, 1e-2, fmi2True), fmi2OK);
  EXPECT_TRUE(bit_identical(a.outputs(), b.outputs()));
}

TEST_F(StateMachine, SeveralInstancesDoNotInterfere) {
  auto solo = [&](double force, std::vector<double>& trace) {
    PlantFmu p;
    ASSERT_EQ(p.set("dy0", force * 1e-3), fmi2OK);
    p.initialize();
    for (int k = 0; k < 100; ++k) {
      ASSERT_EQ(p.set("F[1]", kStaticForce + force), fmi2OK);
      ASSERT_EQ(lib.fmi2DoStep(p.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
      const auto o = p.outputs();
      trace.insert(trace.end(), o.begin(), o.end());
    }
  };
  std::vector<double> a_solo, b_solo;
  solo(0.1, a_solo);
  solo(-0.2, b_solo);
  PlantFmu a("a", false), b("b", false);
  ASSERT_EQ(a.set("dy0", 0.1e-3), fmi2OK);
  ASSERT_EQ(b.set("dy0", -0.2e-3), fmi2OK);
  a.initialize();
  b.initialize();
  std::vector<double> a_trace, b_trace;
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(b.set("F[1]", kStaticForce - 0.2), fmi2OK);
    ASSERT_EQ(a.set("F[1]", kStaticForce + 0.1), fmi2OK);
    ASSERT_EQ(lib.fmi2DoStep(a.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
    ASSERT_EQ(lib.fmi2DoStep(b.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
    const auto ob = b.outputs();
    const auto oa = a.outputs();
    a_trace.insert(a_trace.end(), oa.begin(), oa.end());
    b_trace.insert(b_trace.end(), ob.begin(), ob.end());
  }
  EXPECT_TRUE(bit_identical(a_trace, a_solo));
  EXPECT_TRUE(bit_identical(b_trace, b_solo));
}

TEST_F(StateMachine, CallsOutOfOrderBeforeInitialisation) {
  PlantFmu p;
  ASSERT_NE(p.c, nullptr);
  const fmi2ValueReference x = p.vr("x");
  double buf[3] = {kCanary, kCanary, kCanary};
  fmi2Status st = fmi2Pending;
  fmi2Real r = kCanary;
  fmi2Boolean b = 77;
  EXPECT_EQ(p.step(0.0, 1e-3), fmi2Error);
  EXPECT_EQ(p.exit(), fmi2Error);
  EXPECT_EQ(lib.fmi2GetReal(p.c, &x, 1, &buf[1]), fmi2Error);
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2Error);
  EXPECT_EQ(lib.fmi2GetStatus(p.c, fmi2DoStepStatus, &st), fmi2Error);
  EXPECT_EQ(lib.fmi2GetRealStatus(p.c, fmi2LastSuccessfulTime, &r), fmi2Error);
  EXPECT_EQ(lib.fmi2GetBooleanStatus(p.c, fmi2Terminated, &b), fmi2Error);
  EXPECT_EQ(lib.fmi2GetRealOutputDerivatives(p.c, &x, 1, nullptr, &buf[1]), fmi2Error);
  EXPECT_EQ(lib.fmi2CancelStep(p.c), fmi2Error);
  for (double v : buf) EXPECT_EQ(v, kCanary);
  EXPECT_EQ(st, fmi2Pending);
  EXPECT_EQ(r, kCanary);
  EXPECT_EQ(b, 77);
  EXPECT_TRUE(p.log.contains("not allowed in state Instantiated (illegal call sequence)")) << p.log.dump();
  // Then the normal sequence works.
  p.initialize();
  EXPECT_EQ(p.step(0.0, 1e-3), fmi2OK);
  table_row("before initialisation (Instantiated): fmi2DoStep, fmi2ExitInitializationMode, fmi2GetReal(x), "
            "fmi2Terminate, fmi2GetStatus / GetRealStatus / GetBooleanStatus, fmi2GetRealOutputDerivatives, "
            "fmi2CancelStep",
            "fmi2Error each, \"<function>: not allowed in state Instantiated (illegal call sequence); the call has "
            "no effect\"",
            "yes: nothing written (guard values intact); setup, initialisation and steps then work");
}

TEST_F(StateMachine, CallsOutOfOrderDuringInitialisation) {
  PlantFmu p;
  ASSERT_EQ(p.setup(), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  EXPECT_EQ(p.setup(), fmi2Error);
  EXPECT_EQ(p.enter(), fmi2Error);
  EXPECT_EQ(p.step(0.0, 1e-3), fmi2Error);
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2Error);
  fmi2Real r = kCanary;
  EXPECT_EQ(lib.fmi2GetRealStatus(p.c, fmi2LastSuccessfulTime, &r), fmi2Error);
  EXPECT_EQ(r, kCanary);
  ASSERT_EQ(p.exit(), fmi2OK);
  EXPECT_EQ(p.exit(), fmi2Error);
  EXPECT_EQ(p.enter(), fmi2Error);
  EXPECT_EQ(p.setup(), fmi2Error);
  EXPECT_EQ(p.step(0.0, 1e-3), fmi2OK);
  table_row("in initialisation mode: fmi2SetupExperiment, fmi2EnterInitializationMode again, fmi2DoStep, "
            "fmi2Terminate, fmi2GetRealStatus; after it: fmi2ExitInitializationMode, fmi2EnterInitializationMode, "
            "fmi2SetupExperiment again",
            "fmi2Error each (illegal call sequence)", "yes: initialisation completes, steps work");
}

TEST_F(StateMachine, CallsAfterTermination) {
  PlantFmu p;
  double t = 0.0;
  prepare(p, t);
  ASSERT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(t, 1e-3), fmi2Error);
  EXPECT_EQ(p.set("F[1]", 1.0), fmi2Error);
  EXPECT_EQ(p.set_derivative("F[1]", 1.0), fmi2Error);
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2Error);
  EXPECT_EQ(p.enter(), fmi2Error);
  EXPECT_TRUE(bit_identical(p.all_reals(), before)) << "outputs stay readable and unchanged";
  EXPECT_EQ(lib.fmi2Reset(p.c), fmi2OK);
  p.initialize();
  EXPECT_EQ(p.step(0.0, 1e-3), fmi2OK);
  table_row("after fmi2Terminate: fmi2DoStep, fmi2SetReal(F[1]), fmi2SetRealInputDerivatives, fmi2Terminate "
            "again, fmi2EnterInitializationMode",
            "fmi2Error each (illegal call sequence); fmi2GetReal allowed",
            "yes: every variable bit-identical; fmi2Reset then works");
}

TEST_F(StateMachine, CallsInTheStepFailedState) {
  PlantFmu p;
  ASSERT_EQ(p.set_int("solver", 1), fmi2OK);
  p.initialize();
  ASSERT_EQ(p.set("Fe[1]", 50.0), fmi2OK);
  double t = 0.0;
  fmi2Status s = fmi2OK;
  while (s == fmi2OK && t < 1.0) {
    s = p.step(t, 1e-3);
    if (s == fmi2OK) t += 1e-3;
  }
  ASSERT_EQ(s, fmi2Discard);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(t, 1e-3), fmi2Error);
  EXPECT_EQ(p.set("Fe[1]", 0.0), fmi2Error);
  EXPECT_EQ(p.set_derivative("Fe[1]", 0.0), fmi2Error);
  EXPECT_EQ(p.setup(), fmi2Error);
  fmi2Status st = fmi2Pending;
  EXPECT_EQ(lib.fmi2GetStatus(p.c, fmi2DoStepStatus, &st), fmi2OK);
  EXPECT_EQ(st, fmi2OK) << "fmi2DoStep never pends";
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  EXPECT_EQ(p.last_successful_time(), t);
  EXPECT_TRUE(p.terminated());
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  table_row("after an fmi2Discard (StepFailed): fmi2DoStep again, fmi2SetReal / SetRealInputDerivatives of an "
            "input, fmi2SetupExperiment",
            "fmi2Error each (illegal call sequence); fmi2GetReal, fmi2GetStatus, fmi2GetRealStatus, "
            "fmi2GetBooleanStatus(fmi2Terminated) = true, fmi2Terminate allowed",
            "yes: every variable bit-identical, fmi2LastSuccessfulTime unchanged");
}

TEST_F(StateMachine, FunctionsThisFmuDoesNotProvide) {
  on_stepping_instance(
      "fmi2CancelStep (fmi2DoStep never returns fmi2Pending), fmi2GetRealOutputDerivatives "
      "(maxOutputDerivativeOrder = 0)",
      fmi2Error, "fmi2Error each, with the reason logged (\"not allowed in state StepComplete\", \"not provided\")",
      [&](PlantFmu& p, double) {
        const fmi2ValueReference x = p.vr("x");
        const fmi2Integer order = 1;
        double buf[3] = {kCanary, kCanary, kCanary};
        std::vector<fmi2Status> s = {lib.fmi2CancelStep(p.c),
                                     lib.fmi2GetRealOutputDerivatives(p.c, &x, 1, &order, &buf[1])};
        for (double v : buf) EXPECT_EQ(v, kCanary);
        return s;
      });
}

// The error policy (docs/robustness.md "Error policy", instance.hpp) as a table: each
// refusal, its status, and what the instance can still do without Reset.
// Errors found before anything changed leave the instance as it was,
// wherever they come from (FMI 2.0.4 allows an importer to give up after
// any fmi2Error; this FMU guarantees more). Discard leaves a valid
// instance: StepFailed (Co-Simulation) until a saved state is restored or
// the importer terminates, the inputs' domain for a get.
TEST_F(StateMachine, TheErrorPolicyAsATable) {
  struct Row {
    const char* refusal;
    fmi2Status expected;
    std::function<fmi2Status(PlantFmu&, double)> refuse;
    const char* after;
    std::function<void(PlantFmu&, double)> usable;
  };
  auto steps_on = [](PlantFmu& p, double t) {
    drive_forces(p, t);
    ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
  };
  const Row rows[] = {
      {"fmi2SetReal(F[1] = NaN)", fmi2Error, [](PlantFmu& p, double) { return p.set("F[1]", std::nan("")); },
       "unchanged, StepComplete: the next step", steps_on},
      {"fmi2DoStep(h = -1 ms)", fmi2Error, [](PlantFmu& p, double t) { return p.step(t, -1e-3); },
       "unchanged, StepComplete: the next step", steps_on},
      {"fmi2DoStep past stopTime (10 s)", fmi2Error, [](PlantFmu& p, double t) { return p.step(t, 20.0); },
       "unchanged, StepComplete: the next step", steps_on},
      {"fmi2SetFMUstate(state with time = NaN, checksum recomputed)", fmi2Error,
       [&](PlantFmu& p, double) {
         const std::vector<fmi2Byte> forged = forge(serialized_state(p), 55, std::nan(""));
         fmi2FMUstate bad = nullptr;
         EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, forged.data(), forged.size(), &bad), fmi2OK);
         const fmi2Status s = lib.fmi2SetFMUstate(p.c, bad);
         lib.fmi2FreeFMUstate(p.c, &bad);
         return s;
       },
       "unchanged, StepComplete: the next step", steps_on},
      {"fmi2DoStep with F[3] = 1e300 N (the step cannot be completed)", fmi2Discard,
       [](PlantFmu& p, double t) {
         EXPECT_EQ(p.set("F[3]", 1e300), fmi2OK);
         return p.step(t, 1e-3);
       },
       "StepFailed, state at fmi2LastSuccessfulTime: gets and status; fmi2DoStep and fmi2SetReal are Errors; a "
       "saved state restored, the steps go on",
       [&](PlantFmu& p, double t) {
         EXPECT_TRUE(p.terminated());
         EXPECT_EQ(p.last_successful_time(), t);
         EXPECT_TRUE(all_finite(p.outputs()));
         EXPECT_EQ(p.step(t, 1e-3), fmi2Error);
         EXPECT_EQ(p.set("F[3]", kStaticForce), fmi2Error);
         PlantFmu fresh("fresh");
         fresh.initialize();
         fmi2FMUstate home = nullptr;
         ASSERT_EQ(lib.fmi2GetFMUstate(fresh.c, &home), fmi2OK);
         ASSERT_EQ(lib.fmi2SetFMUstate(p.c, home), fmi2OK) << p.log.dump();
         lib.fmi2FreeFMUstate(fresh.c, &home);
         drive_forces(p, 0.0);
         EXPECT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
       }},
  };
  for (const Row& r : rows) {
    SCOPED_TRACE(r.refusal);
    PlantFmu p("policy");
    ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 0.0, fmi2True, 10.0), fmi2OK);  // stopTime 10 s
    ASSERT_EQ(p.enter(), fmi2OK);
    ASSERT_EQ(p.exit(), fmi2OK);
    double t = 0.0;
    for (int k = 0; k < 3; ++k, t += 1e-3) steps_on(p, t);
    const std::size_t logged = p.log.messages.size();
    EXPECT_EQ(r.refuse(p, t), r.expected) << p.log.dump();
    EXPECT_GT(p.log.messages.size(), logged) << "every refusal comes with its reason";
    r.usable(p, t);
    table_row(std::string("error policy: ") + r.refusal,
              r.expected == fmi2Error ? "fmi2Error, reason logged" : "fmi2Discard, reason logged", r.after);
  }
  // Initialisation refused: still in initialization mode, the parameter can be corrected.
  PlantFmu p("policy");
  ASSERT_EQ(p.set("l", 1e-3), fmi2OK);  // within [min, max], but a 1 mm rod reaches no pose
  ASSERT_EQ(p.setup(), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  EXPECT_EQ(p.exit(), fmi2Error);
  EXPECT_TRUE(p.log.contains("unreachable")) << p.log.dump();
  ASSERT_EQ(p.set("l", 0.08), fmi2OK) << p.log.dump();
  ASSERT_EQ(p.exit(), fmi2OK) << p.log.dump();
  steps_on(p, 0.0);
  table_row("error policy: fmi2ExitInitializationMode with l = 1 mm", "fmi2Error, reason logged",
            "InitializationMode: the parameter corrected, fmi2ExitInitializationMode succeeds (no fmi2Reset)");
  // The inverse FMU: a get beyond a singularity guard.
  InverseFmu inv;
  inv.initialize();
  const std::vector<double> good = inv.outputs();
  ASSERT_EQ(inv.set("x", ref::x_rod_horizontal(2) * (1.0 - 1e-9)), fmi2OK);  // leg 2's rod within 3e-5 rad of horizontal
  const fmi2ValueReference F1 = inv.vr("F[1]");
  double f = 0.0;
  EXPECT_EQ(inv.lib.fmi2GetReal(inv.c, &F1, 1, &f), fmi2Discard) << inv.log.dump();
  EXPECT_EQ(f, good[0]);
  ASSERT_EQ(inv.set("x", 0.0), fmi2OK);
  EXPECT_TRUE(bit_identical(inv.outputs(), good));
  table_row("error policy: inverse fmi2GetReal at a pose beyond a singularity guard", "fmi2Discard, reason logged",
            "the last good outputs handed out; inputs within the guards: fmi2OK again");
}

TEST_F(StateMachine, StatusKindsTheStandardDoesNotDefine) {
  on_stepping_instance(
      "fmi2GetStatus(fmi2LastSuccessfulTime), fmi2GetRealStatus(fmi2DoStepStatus), fmi2GetIntegerStatus(any), "
      "fmi2GetBooleanStatus(fmi2DoStepStatus), fmi2GetStringStatus(fmi2PendingStatus) (nothing pending)",
      fmi2Discard, "fmi2Discard (FMI 2.0: the status is not available), value untouched",
      [&](PlantFmu& p, double) {
        fmi2Status st = fmi2Pending;
        fmi2Real r = kCanary;
        fmi2Integer i = -5;
        fmi2Boolean b = -5;
        fmi2String str = "canary";
        std::vector<fmi2Status> s = {lib.fmi2GetStatus(p.c, fmi2LastSuccessfulTime, &st),
                                     lib.fmi2GetRealStatus(p.c, fmi2DoStepStatus, &r),
                                     lib.fmi2GetIntegerStatus(p.c, fmi2DoStepStatus, &i),
                                     lib.fmi2GetBooleanStatus(p.c, fmi2DoStepStatus, &b),
                                     lib.fmi2GetStringStatus(p.c, fmi2PendingStatus, &str)};
        EXPECT_EQ(st, fmi2Pending);
        EXPECT_EQ(r, kCanary);
        EXPECT_EQ(i, -5);
        EXPECT_EQ(b, -5);
        EXPECT_STREQ(str, "canary");
        return s;
      },
      /*expect_message=*/false);
}

}  // namespace
