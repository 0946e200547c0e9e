// SPDX-License-Identifier: BSD-2-Clause
// The clauses of both FMI versions that the state tables leave to the text
// (the tables themselves: state_table.cpp), one test each: FMI 3.0's Discard
// leaving the state before the call, Model Exchange's time rules and
// stopTime (what is computed past it), Event Mode's time by version, and
// FMI 3.0's logging while it is off.

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "any_version.hpp"
#include "fmi/state_machine.hpp"

namespace {

using namespace pkm_test;

// FMI 3.0.2 section 4.2.3 (fmi3DoStep) and 2.2.3 (fmi3Discard): a Discard
// leaves the FMU in the state before the call, still in Step Mode, so that the
// importer can retry. Both integrators: CVODE (F[3] = 1e300 N) and RK4 (the
// leg-singularity guard failing an internal step of a communication step).
void discard_and_retry(int solver) {
  Any a(3, false);
  ASSERT_NE(a.c, nullptr);
  const std::uint32_t solver_vr = vr("solver");
  const std::int32_t sv = solver;
  ASSERT_EQ(fmi3().fmi3SetInt32(a.c, &solver_vr, 1, &sv, 1), fmi3OK);
  if (solver == 1) {
    ASSERT_EQ(a.set("rk4_step", 1e-4), fmi3OK);
    ASSERT_EQ(a.set("rho_min", -1.0), fmi3OK);  // leg 2's slider would rest on its end stop on the way
  }
  ASSERT_EQ(a.enter(), fmi3OK);
  ASSERT_EQ(a.exit(), fmi3OK);
  // RK4: Fe[1] = 5 N turns leg 2's rod horizontal in about 0.15 s; CVODE: a
  // force no step can follow.
  ASSERT_EQ(a.set(solver == 1 ? "Fe[1]" : "F[3]", solver == 1 ? 5.0 : 1e300), fmi3OK);
  double t = 0.0;
  const double h = 1e-3;
  int s = fmi3OK;
  std::vector<double> before;
  fmi3Boolean event = fmi3False, terminate = fmi3True, early = fmi3True;
  double last = NAN;
  for (int k = 0; k < 1000 && s == fmi3OK; ++k) {
    before = a.reals();
    s = fmi3().fmi3DoStep(a.c, t, h, fmi3True, &event, &terminate, &early, &last);
    if (s == fmi3OK) t += h;
  }
  ASSERT_EQ(s, fmi3Discard) << a.log.dump();
  if (solver == 1) {
    // The model's own last good point lies inside the step (whole RK4 steps
    // were good): what the FMU must not stay at.
    const std::string key = "the last good state is at t = ";
    double inside = NAN;
    for (const auto& m : a.log.messages)
      if (m.text.find(key) != std::string::npos) inside = std::stod(m.text.substr(m.text.find(key) + key.size()));
    EXPECT_GT(inside, t) << a.log.dump();
  }
  EXPECT_EQ(last, t) << "lastSuccessfulTime: the time at the call";
  EXPECT_EQ(terminate, fmi3False) << "the computation may continue";
  int got = fmi3Error;
  EXPECT_TRUE(bit_identical(a.reals(&got), before)) << "every variable as before the call";
  EXPECT_EQ(got, fmi3OK);
  // Still in Step Mode: new inputs (CVODE), or a shorter step (RK4: one
  // internal step, which was good), retried from the same time.
  ASSERT_EQ(a.set("F[1]", kStaticForce), fmi3OK) << a.log.dump();
  if (solver == 0) {
    ASSERT_EQ(a.set("F[3]", kStaticForce), fmi3OK);
  }
  const double retry = solver == 1 ? 1e-4 : h;
  EXPECT_EQ(a.step(t, retry), fmi3OK) << a.log.dump();
  double time = NAN;
  const std::uint32_t time_vr = 0;
  ASSERT_EQ(fmi3().fmi3GetFloat64(a.c, &time_vr, 1, &time, 1), fmi3OK);
  EXPECT_EQ(time, t + retry);
}

TEST(StateTable, Fmi3DiscardWithCvodeLeavesTheStateBeforeTheCall) { discard_and_retry(0); }
TEST(StateTable, Fmi3DiscardWithRk4LeavesTheStateBeforeTheCall) { discard_and_retry(1); }

// FMI 3.0.2 section 3.2.1 (fmi3SetTime) and FMI 2.0.4 section 3.2.2
// (fmi2CompletedIntegratorStep): time not before startTime nor the last
// EnterEventMode. (Past stopTime: the next test.)
TEST(StateTable, ModelExchangeTimeStaysWithinStartAndHistory) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, true);
    ASSERT_EQ(a.enter(1.0, 2.0), fmi2OK) << a.log.dump();  // startTime 1 s, stopTime 2 s
    ASSERT_EQ(a.exit(), fmi2OK);
    ASSERT_EQ(a.continuous(), fmi2OK);
    EXPECT_EQ(a.set_time(0.5), fmi2Error) << "before startTime";
    EXPECT_EQ(a.set_time(2.0), fmi2OK) << "stopTime itself";
    EXPECT_EQ(a.set_time(1.1), fmi2OK) << "back in time, within the current step";
    EXPECT_EQ(a.completed(), fmi2OK);  // at 1.1
    EXPECT_EQ(a.set_time(1.3), fmi2OK);
    EXPECT_EQ(a.event(), fmi2OK);  // an event at 1.3
    ASSERT_EQ(a.continuous(), fmi2OK);
    EXPECT_EQ(a.set_time(1.25), fmi2Error) << "back past the last event";
    EXPECT_EQ(a.set_time(1.3), fmi2OK);
    std::vector<double> dx(plant().n_states);
    EXPECT_EQ(version == 2 ? a.lib.fmi2GetDerivatives(a.c, dx.data(), dx.size())
                           : +fmi3().fmi3GetContinuousStateDerivatives(a.c, dx.data(), dx.size()),
              fmi2OK);
  }
}

// FMI 2.0.4 section 2.1.6 (fmi2SetupExperiment) and FMI 3.0.2 section 2.3.2
// (fmi3EnterInitializationMode): "if the environment tries to compute past
// stopTime the FMU has to return Error". What is computed is what is accepted:
// in Continuous-Time Mode a variable-step integrator evaluates trial points
// (SetTime, SetContinuousStates, GetDerivatives, GetEventIndicators, Get) and
// may go back over them (FMI 3.0.2 section 2.2.6: "solvers might need to jump
// back and forth in time"; section 3.2.1: fmi3SetTime's bounds are all lower
// ones); fmi2/fmi3CompletedIntegratorStep says "all inputs and state
// variables have valid (accepted) values" (FMI 2.0.4 section 3.2.2, FMI 3.0.2
// section 3.2.1); an event is handled at its time; a communication step ends
// at t + h. Each of these past stopTime is an Error with no effect. Event
// Mode is never entered past stopTime, so no event update computes past it.
TEST(StateTable, PastStopTimeTrialEvaluationsAreAcceptedWhatAdvancesIsRefused) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    const bool v2 = version == 2;
    Any a(version, true);
    ASSERT_EQ(a.enter(0.0, 1.0), fmi2OK) << a.log.dump();  // stopTime 1 s
    ASSERT_EQ(a.exit(), fmi2OK);
    ASSERT_EQ(a.continuous(), fmi2OK);
    const std::size_t nx = plant().n_states, nz = plant().n_event_indicators;
    std::vector<double> x(nx, NAN), dx(nx, NAN), z(nz, NAN);
    ASSERT_EQ(v2 ? +a.lib.fmi2GetContinuousStates(a.c, x.data(), nx)
                 : +fmi3().fmi3GetContinuousStates(a.c, x.data(), nx),
              fmi2OK);
    // A trial point past stopTime, as CVODE's last internal step makes it.
    EXPECT_EQ(a.set_time(1.05), fmi2OK) << a.log.dump();
    EXPECT_EQ(v2 ? +a.lib.fmi2SetContinuousStates(a.c, x.data(), nx)
                 : +fmi3().fmi3SetContinuousStates(a.c, x.data(), nx),
              fmi2OK);
    EXPECT_EQ(v2 ? +a.lib.fmi2GetDerivatives(a.c, dx.data(), nx)
                 : +fmi3().fmi3GetContinuousStateDerivatives(a.c, dx.data(), nx),
              fmi2OK);
    EXPECT_EQ(v2 ? +a.lib.fmi2GetEventIndicators(a.c, z.data(), nz)
                 : +fmi3().fmi3GetEventIndicators(a.c, z.data(), nz),
              fmi2OK);
    EXPECT_TRUE(std::isfinite(dx[5]) && std::isfinite(z[0])) << "evaluated at the trial point";
    double time = NAN;
    EXPECT_EQ(a.get("time", time), fmi2OK);
    EXPECT_EQ(time, 1.05);
    // Accepting that point, or an event there, computes past stopTime.
    const std::vector<double> before = a.reals();
    EXPECT_EQ(a.completed(), fmi2Error);
    EXPECT_NE(a.log.last().find("the integrator step accepted at t = 1.05"), std::string::npos) << a.log.dump();
    EXPECT_NE(a.log.last().find("lies past stopTime = 1"), std::string::npos) << a.log.dump();
    EXPECT_EQ(a.event(), fmi2Error);
    EXPECT_NE(a.log.last().find("an event at t = 1.05"), std::string::npos) << a.log.dump();
    EXPECT_TRUE(bit_identical(a.reals(), before)) << "no effect";
    // Still in Continuous-Time Mode: back to stopTime, accepted there, an event there.
    EXPECT_EQ(a.set_time(1.0), fmi2OK) << a.log.dump();
    EXPECT_EQ(a.completed(), fmi2OK) << a.log.dump();
    EXPECT_EQ(a.event(), fmi2OK) << a.log.dump();
    // Neither version sets the time of an FMU with states in Event Mode
    // (the next test).
    EXPECT_EQ(a.set_time(1.05), fmi2Error);
    EXPECT_NE(a.log.last().find("not allowed"), std::string::npos) << a.log.dump();
    EXPECT_EQ(a.get("time", time), fmi2OK);
    EXPECT_EQ(time, 1.0);
    // Co-Simulation: a communication step ending past stopTime.
    Any cs(version, false);
    ASSERT_EQ(cs.enter(0.0, 1e-3), fmi2OK) << cs.log.dump();
    ASSERT_EQ(cs.exit(), fmi2OK);
    const std::vector<double> at_start = cs.reals();
    EXPECT_EQ(cs.step(0.0, 2e-3), fmi2Error);
    EXPECT_NE(cs.log.last().find("the end of the communication step at t = 0.002 lies past stopTime"),
              std::string::npos)
        << cs.log.dump();
    EXPECT_TRUE(bit_identical(cs.reals(), at_start)) << "no effect";
    EXPECT_EQ(cs.step(0.0, 1e-3), fmi2OK) << "up to stopTime itself\n" << cs.log.dump();
  }
}

// FMI 2.0.4 section 3.2.3: fmi2EnterEventMode is allowed in Event Mode,
// fmi2SetTime there "only for a Pure Discrete-Time FMU" (condition 8) once
// fmi2NewDiscreteStates has answered newDiscreteStatesNeeded = false: the
// inverse FMU, which has no continuous states, and not the plant. Past a
// defined stopTime that time is refused (FMI 2.0.4 section 2.1.6). FMI 3.0.2
// section 3.2.1: fmi3SetTime and fmi3EnterEventMode only in Continuous-Time
// Mode.
TEST(StateTable, SetTimeAndEnterEventModeInEventModeFollowTheVersion) {
  for (int version : {2, 3}) {
    for (bool inverse : {false, true}) {
      SCOPED_TRACE(std::to_string(version) + (inverse ? " inverse" : " plant"));
      Any a(version, true, true, inverse);
      ASSERT_NE(a.c, nullptr) << a.log.dump();
      ASSERT_EQ(a.enter(0.0, 1.0), fmi2OK) << a.log.dump();
      ASSERT_EQ(a.exit(), fmi2OK);  // Event Mode
      ASSERT_EQ(a.update(), fmi2OK) << a.log.dump();
      const bool pure_discrete = a.def.n_states == 0;
      EXPECT_EQ(pure_discrete, inverse);
      const bool allowed = version == 2 && pure_discrete;
      EXPECT_EQ(a.set_time(0.5), allowed ? fmi2OK : fmi2Error) << a.log.dump();
      if (!allowed) {
        EXPECT_NE(a.log.last().find("not allowed in state EventMode"), std::string::npos) << a.log.dump();
      } else {
        EXPECT_EQ(a.value("time"), 0.5);
        EXPECT_EQ(a.set_time(1.05), fmi2Error);
        EXPECT_NE(a.log.last().find("the event at t = 1.05"), std::string::npos) << a.log.dump();
        EXPECT_EQ(a.value("time"), 0.5);
      }
      EXPECT_EQ(a.event(), version == 2 ? fmi2OK : fmi2Error) << a.log.dump();
    }
  }
}

// FMI 3.0.2 section 2.3.2: fmi3GetNumberOfContinuousStates and
// fmi3GetNumberOfEventIndicators "can only be called in Model Exchange";
// start values can be read with fmi3Get{VariableType} in Instantiated, and a
// variable without one is refused.
TEST(StateTable, Fmi3InstantiatedReadsStartValuesAndCountsAreModelExchangeOnly) {
  Any cs(3, false), me(3, true);
  std::size_t n = 99;
  EXPECT_EQ(fmi3().fmi3GetNumberOfContinuousStates(cs.c, &n), fmi3Error);
  EXPECT_EQ(fmi3().fmi3GetNumberOfEventIndicators(cs.c, &n), fmi3Error);
  EXPECT_EQ(n, 99u);
  EXPECT_EQ(fmi3().fmi3GetNumberOfContinuousStates(me.c, &n), fmi3OK);
  EXPECT_EQ(n, plant().n_states);
  double l = NAN, x = 7.0;
  EXPECT_EQ(cs.get("l", l), fmi3OK) << cs.log.dump();
  EXPECT_EQ(l, plant().find("l")->start);
  EXPECT_EQ(cs.get("x", x), fmi3Error) << "an output has no start value";
  EXPECT_EQ(x, 7.0);
}

// FMI 3.0.2 section 2.3.1 (logMessage): "must only be called for log
// categories that were enabled"; with loggingOn = false nothing is logged, the
// reason of an Error stays in the last-error text. FMI 2.0 keeps its
// documented behaviour: the reason of an Error always reaches the logger.
TEST(StateTable, Fmi3LogsNothingWhileLoggingIsOff) {
  Any quiet(3, false, /*logging_on=*/false), told(2, false, false);
  EXPECT_EQ(quiet.step(0.0, 1e-3), fmi3Error);
  EXPECT_TRUE(quiet.log.messages.empty()) << quiet.log.dump();
  EXPECT_EQ(told.step(0.0, 1e-3), fmi2Error);
  EXPECT_TRUE(told.log.contains("not allowed in state Instantiated")) << told.log.dump();
  // Switched on for the error category: the next refusal is told.
  const fmi3String category = "logStatusError";
  ASSERT_EQ(fmi3().fmi3SetDebugLogging(quiet.c, fmi3True, 1, &category), fmi3OK);
  EXPECT_EQ(quiet.step(0.0, 1e-3), fmi3Error);
  EXPECT_TRUE(quiet.log.contains("not allowed in state Instantiated")) << quiet.log.dump();
}

// The last-error text of an FMI 3.0 instance whose logging is off (in
// process: the Instance behind the handle).
TEST(StateTable, Fmi3KeepsTheReasonOfAnErrorWhileLoggingIsOff) {
  int calls = 0;
  pkm_fmi::Logger log([](void* cb, void*, const char*, pkm_fmi::Status, const char*, const char*) {
    ++*static_cast<int*>(cb);
  }, &calls, nullptr, "quiet", false, /*categories_only=*/true);
  std::unique_ptr<pkm_fmi::Instance> inst(pkm_fmi::Instance::create(plant(), 3, pkm_fmi::Interface::CoSimulation,
                                                                    plant().guid().c_str(), std::move(log)));
  ASSERT_TRUE(inst);
  bool terminate = false;
  double last = 0.0;
  EXPECT_EQ(inst->do_step(0.0, 1e-3, &terminate, &last), pkm_fmi::Status::Error);
  EXPECT_EQ(calls, 0);
  EXPECT_NE(std::string(inst->logger().last_error()).find("fmi3DoStep: not allowed in state Instantiated"),
            std::string::npos)
      << inst->logger().last_error();
}

}  // namespace
