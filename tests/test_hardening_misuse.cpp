// Hardening, FMI misuse: calls out of the FMI 2.0 co-simulation state
// machine's order, unknown value references, NULL pointers, fixed
// parameters set after initialisation, bad communication steps, steps past
// stopTime, foreign handles and FMU states. Each answer is what the
// standard prescribes (fmi2Error, or fmi2Discard for status kinds it does
// not define), nothing crashes, nothing is written outside the instance
// (guard zones around every output buffer), and an instance that was
// stepping goes on bit-identically to an untouched twin.
// Every case prints a row of the hardening table ("| tried | answer | kept |").
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi3FunctionTypes.h"
#include "fmu_loader.hpp"
#include "fnv1a.hpp"
#include "hardening_table.hpp"

namespace {

using namespace pkm_test;

constexpr double kCanary = -7.77e77;

void drive(FmuInstance& p, double t) {
  for (int i = 1; i <= 4; ++i)
    ASSERT_EQ(p.set(force_name(i), kStaticForce + 0.01 * std::sin(2.0 * kPi * (1.0 + 0.5 * i) * t)), fmi2OK);
}

/// Initialised and stepped five times (1 ms), inputs set for the next step.
void prepare(PlantFmu& p, double& t) {
  p.initialize();
  t = 0.0;
  for (int k = 0; k < 5; ++k) {
    drive(p, t);
    ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
    t += 1e-3;
  }
  drive(p, t);
}

/// A misuse on a stepping instance: `misuse` returns the statuses it got;
/// all must equal `expected`; then every variable must be as before and the
/// next step bit-identical to an untouched twin's.
void on_stepping_instance(const std::string& tried, fmi2Status expected, const std::string& answer,
                          const std::function<std::vector<fmi2Status>(PlantFmu&, double)>& misuse,
                          bool expect_message = true) {
  SCOPED_TRACE(tried);
  PlantFmu p("misused"), twin("twin");
  double t = 0.0, t2 = 0.0;
  prepare(p, t);
  prepare(twin, t2);
  const std::vector<double> before = p.all_reals();
  const std::size_t logged = p.log.messages.size();
  for (fmi2Status s : misuse(p, t)) EXPECT_EQ(s, expected) << p.log.dump();
  if (expect_message && expected != fmi2OK) {
    EXPECT_GT(p.log.messages.size(), logged) << "every fmi2Error comes with a logged reason";
    if (p.log.messages.size() > logged) {
      EXPECT_EQ(p.log.messages.back().status, expected) << p.log.dump();
    }
  }
  fmi2Status get_status = fmi2Error;
  EXPECT_TRUE(bit_identical(p.all_reals(&get_status), before)) << "the misuse changed a variable";
  EXPECT_EQ(get_status, fmi2OK);
  EXPECT_EQ(p.last_successful_time(), t);
  ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
  ASSERT_EQ(twin.step(t2, 1e-3), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs())) << "the next step differs from the twin's";
  table_row(tried, answer, "yes: every variable bit-identical, the next step bit-identical to an untouched twin");
}

class HardeningMisuse : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(plant_library().missing.empty()) << plant_library().missing;
    ASSERT_TRUE(inverse_library().missing.empty()) << inverse_library().missing;
  }
  FmuLibrary& lib = plant_library();
};

// ---------------------------------------------------------------- state machine

TEST_F(HardeningMisuse, CallsOutOfOrderBeforeInitialisation) {
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

TEST_F(HardeningMisuse, CallsOutOfOrderDuringInitialisation) {
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

TEST_F(HardeningMisuse, CallsAfterTermination) {
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

TEST_F(HardeningMisuse, CallsInTheStepFailedState) {
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

TEST_F(HardeningMisuse, FunctionsThisFmuDoesNotProvide) {
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

// ---------------------------------------------------------------- value references

TEST_F(HardeningMisuse, UnknownAndMistypedValueReferences) {
  on_stepping_instance(
      "unknown value references (0, 9, 99999, 0xFFFFFFFF) in fmi2GetReal / fmi2SetReal, alone and within a vector "
      "call with valid ones; a Real's reference in fmi2GetInteger / GetBoolean / GetString and an Integer's in "
      "fmi2GetReal / SetReal; fmi2SetInteger, SetBoolean, SetString",
      fmi2Error, "fmi2Error each, \"unknown value reference <vr> (no <type> variable has it)\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        for (fmi2ValueReference bad : {9u, 99u, 99999u, 0xFFFFFFFFu}) {  // (0 is time)
          double buf[4] = {kCanary, kCanary, kCanary, kCanary};
          const fmi2ValueReference mixed[2] = {p.vr("x"), bad};
          s.push_back(lib.fmi2GetReal(p.c, &bad, 1, &buf[1]));
          s.push_back(lib.fmi2GetReal(p.c, mixed, 2, &buf[1]));
          for (double v : buf) EXPECT_EQ(v, kCanary) << "nothing written for vr " << bad;
          const fmi2ValueReference set_mixed[2] = {p.vr("F[1]"), bad};
          const double values[2] = {123.0, 456.0};
          s.push_back(lib.fmi2SetReal(p.c, &bad, 1, values));
          s.push_back(lib.fmi2SetReal(p.c, set_mixed, 2, values));
        }
        const fmi2ValueReference real = p.vr("x"), integer = p.vr("solver"), input = p.vr("F[2]");
        fmi2Integer ibuf[3] = {-5, -5, -5};
        fmi2Boolean bbuf[3] = {-5, -5, -5};
        fmi2String sbuf[3] = {"canary", "canary", "canary"};
        double rbuf[3] = {kCanary, kCanary, kCanary};
        s.push_back(lib.fmi2GetInteger(p.c, &real, 1, &ibuf[1]));
        s.push_back(lib.fmi2GetBoolean(p.c, &real, 1, &bbuf[1]));
        s.push_back(lib.fmi2GetString(p.c, &real, 1, &sbuf[1]));
        s.push_back(lib.fmi2GetReal(p.c, &integer, 1, &rbuf[1]));
        const double one = 1.0;
        const fmi2Integer ione = 1;
        const fmi2Boolean btrue = fmi2True;
        const fmi2String str = "x";
        s.push_back(lib.fmi2SetReal(p.c, &integer, 1, &one));
        s.push_back(lib.fmi2SetInteger(p.c, &input, 1, &ione));
        s.push_back(lib.fmi2SetBoolean(p.c, &input, 1, &btrue));
        s.push_back(lib.fmi2SetString(p.c, &input, 1, &str));
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(ibuf[k], -5);
          EXPECT_EQ(bbuf[k], -5);
          EXPECT_STREQ(sbuf[k], "canary");
          EXPECT_EQ(rbuf[k], kCanary);
        }
        EXPECT_TRUE(p.log.contains("unknown value reference 99999")) << p.log.dump();
        EXPECT_TRUE(p.log.contains("unknown value reference 4294967295")) << p.log.dump();
        return s;
      });
}

TEST_F(HardeningMisuse, OutputsAndFixedParametersCannotBeSetAfterInitialisation) {
  on_stepping_instance(
      "fmi2SetReal of an output (x, lambda[3]) or of a fixed parameter after initialisation (l, m_platform, x0, "
      "rk4_step, max_jacobian_condition, min_leg_measure); fmi2SetInteger of solver, formulation",
      fmi2Error,
      "fmi2Error each, \"<name> is a fixed parameter: it can only be set before fmi2ExitInitializationMode\" / "
      "\"<name> ... is a continuous output variable and cannot be set\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        for (const char* name : {"x", "lambda[3]", "l", "m_platform", "x0", "rk4_step", "max_jacobian_condition",
                                 "min_leg_measure"})
          s.push_back(p.set(name, 0.5));
        for (const char* name : {"solver", "formulation"}) s.push_back(p.set_int(name, 1));
        EXPECT_TRUE(p.log.contains("l is a fixed parameter")) << p.log.dump();
        EXPECT_TRUE(p.log.contains("max_jacobian_condition is a fixed parameter")) << p.log.dump();
        return s;
      });
}

// ---------------------------------------------------------------- NULL pointers and foreign handles

TEST_F(HardeningMisuse, NullArgumentsAreErrors) {
  on_stepping_instance(
      "NULL arrays with n > 0 in fmi2Get/Set Real/Integer/Boolean/String and fmi2SetRealInputDerivatives; "
      "NULL FMUstate / size / buffer in the FMU-state functions; NULL value in fmi2GetStatus / GetRealStatus / "
      "GetBooleanStatus; NULL category list or a NULL category in fmi2SetDebugLogging",
      fmi2Error, "fmi2Error each, \"<function>: ... is NULL\"", [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        const fmi2ValueReference x = p.vr("x"), f = p.vr("F[1]");
        double v = kCanary;
        fmi2Integer i = 0;
        fmi2Boolean b = 0;
        fmi2String str = nullptr;
        s.push_back(lib.fmi2GetReal(p.c, nullptr, 1, &v));
        s.push_back(lib.fmi2GetReal(p.c, &x, 1, nullptr));
        s.push_back(lib.fmi2SetReal(p.c, nullptr, 1, &v));
        s.push_back(lib.fmi2SetReal(p.c, &f, 1, nullptr));
        s.push_back(lib.fmi2GetInteger(p.c, nullptr, 1, &i));
        s.push_back(lib.fmi2SetInteger(p.c, &x, 1, nullptr));
        s.push_back(lib.fmi2GetBoolean(p.c, nullptr, 1, &b));
        s.push_back(lib.fmi2SetBoolean(p.c, &x, 1, nullptr));
        s.push_back(lib.fmi2GetString(p.c, nullptr, 1, &str));
        s.push_back(lib.fmi2SetString(p.c, &x, 1, nullptr));
        const fmi2Integer order = 1;
        s.push_back(lib.fmi2SetRealInputDerivatives(p.c, nullptr, 1, &order, &v));
        s.push_back(lib.fmi2SetRealInputDerivatives(p.c, &f, 1, nullptr, &v));
        s.push_back(lib.fmi2SetRealInputDerivatives(p.c, &f, 1, &order, nullptr));
        s.push_back(lib.fmi2GetFMUstate(p.c, nullptr));
        s.push_back(lib.fmi2SetFMUstate(p.c, nullptr));
        fmi2FMUstate state = nullptr;
        EXPECT_EQ(lib.fmi2GetFMUstate(p.c, &state), fmi2OK);
        std::size_t size = 0;
        s.push_back(lib.fmi2SerializedFMUstateSize(p.c, state, nullptr));
        s.push_back(lib.fmi2SerializedFMUstateSize(p.c, nullptr, &size));
        s.push_back(lib.fmi2SerializeFMUstate(p.c, state, nullptr, 1000));
        s.push_back(lib.fmi2SerializeFMUstate(p.c, nullptr, reinterpret_cast<fmi2Byte*>(&v), sizeof v));
        fmi2FMUstate out = nullptr;
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, nullptr, 100, &out));
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, reinterpret_cast<const fmi2Byte*>(&v), sizeof v, nullptr));
        EXPECT_EQ(out, nullptr);
        EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &state), fmi2OK);
        EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, nullptr), fmi2OK) << "freeing nothing is fine";
        s.push_back(lib.fmi2GetStatus(p.c, fmi2DoStepStatus, nullptr));
        s.push_back(lib.fmi2GetRealStatus(p.c, fmi2LastSuccessfulTime, nullptr));
        s.push_back(lib.fmi2GetBooleanStatus(p.c, fmi2Terminated, nullptr));
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 2, nullptr));
        const fmi2String with_null[2] = {"logEvents", nullptr};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 2, with_null));
        EXPECT_EQ(v, kCanary);
        // n = 0 with NULL arrays: nothing to do, fine.
        EXPECT_EQ(lib.fmi2GetReal(p.c, nullptr, 0, nullptr), fmi2OK);
        EXPECT_EQ(lib.fmi2SetReal(p.c, nullptr, 0, nullptr), fmi2OK);
        return s;
      });
}

TEST_F(HardeningMisuse, NullAndForeignComponentsAreErrorsWithoutACrash) {
  // Not an instance: NULL, and a pointer to memory that is not one (the tag check).
  alignas(16) unsigned char not_an_instance[256] = {};
  for (void* c : {static_cast<void*>(nullptr), static_cast<void*>(not_an_instance)}) {
    const fmi2ValueReference vr = 10;
    double v = kCanary;
    fmi2Integer i = 0;
    fmi2Boolean b = 0;
    fmi2String s = nullptr;
    fmi2FMUstate state = nullptr;
    std::size_t size = 0;
    fmi2Status st = fmi2Pending;
    const fmi2Integer order = 1;
    EXPECT_EQ(lib.fmi2SetDebugLogging(c, fmi2True, 0, nullptr), fmi2Error);
    EXPECT_EQ(lib.fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0), fmi2Error);
    EXPECT_EQ(lib.fmi2EnterInitializationMode(c), fmi2Error);
    EXPECT_EQ(lib.fmi2ExitInitializationMode(c), fmi2Error);
    EXPECT_EQ(lib.fmi2Terminate(c), fmi2Error);
    EXPECT_EQ(lib.fmi2Reset(c), fmi2Error);
    EXPECT_EQ(lib.fmi2GetReal(c, &vr, 1, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2GetInteger(c, &vr, 1, &i), fmi2Error);
    EXPECT_EQ(lib.fmi2GetBoolean(c, &vr, 1, &b), fmi2Error);
    EXPECT_EQ(lib.fmi2GetString(c, &vr, 1, &s), fmi2Error);
    EXPECT_EQ(lib.fmi2SetReal(c, &vr, 1, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2SetInteger(c, &vr, 1, &i), fmi2Error);
    EXPECT_EQ(lib.fmi2SetBoolean(c, &vr, 1, &b), fmi2Error);
    EXPECT_EQ(lib.fmi2SetString(c, &vr, 1, &s), fmi2Error);
    EXPECT_EQ(lib.fmi2GetFMUstate(c, &state), fmi2Error);
    EXPECT_EQ(lib.fmi2SetFMUstate(c, state), fmi2Error);
    EXPECT_EQ(lib.fmi2FreeFMUstate(c, &state), fmi2Error);
    EXPECT_EQ(lib.fmi2SerializedFMUstateSize(c, state, &size), fmi2Error);
    EXPECT_EQ(lib.fmi2SerializeFMUstate(c, state, nullptr, 0), fmi2Error);
    EXPECT_EQ(lib.fmi2DeSerializeFMUstate(c, nullptr, 0, &state), fmi2Error);
    EXPECT_EQ(lib.fmi2GetDirectionalDerivative(c, &vr, 1, &vr, 1, &v, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2SetRealInputDerivatives(c, &vr, 1, &order, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2GetRealOutputDerivatives(c, &vr, 1, &order, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2Error);
    EXPECT_EQ(lib.fmi2CancelStep(c), fmi2Error);
    EXPECT_EQ(lib.fmi2GetStatus(c, fmi2DoStepStatus, &st), fmi2Error);
    EXPECT_EQ(lib.fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &v), fmi2Error);
    EXPECT_EQ(lib.fmi2GetIntegerStatus(c, fmi2DoStepStatus, &i), fmi2Error);
    EXPECT_EQ(lib.fmi2GetBooleanStatus(c, fmi2Terminated, &b), fmi2Error);
    EXPECT_EQ(lib.fmi2GetStringStatus(c, fmi2PendingStatus, &s), fmi2Error);
    lib.fmi2FreeInstance(c);
    EXPECT_EQ(v, kCanary);
    EXPECT_EQ(st, fmi2Pending);
    EXPECT_EQ(state, nullptr);
  }
  for (unsigned char byte : not_an_instance) EXPECT_EQ(byte, 0) << "the foreign memory was written";
  table_row("a NULL fmi2Component, or a pointer to memory that is not an instance, passed to every one of the "
            "32 functions that take one (and fmi2FreeInstance)",
            "fmi2Error each (nobody to log to); fmi2FreeInstance ignores it",
            "yes: no crash, the foreign memory untouched");
}

// Both libraries are built from the same sources: an instance made by one
// has the right tag for the other, only its model definition differs. Each
// library must serve its own model's instances only (issue 17.5), and the
// FMI 3.0 entry points only instances made by fmi3Instantiate*.
TEST_F(HardeningMisuse, InstancesOfTheOtherModelOrFmiVersionAreErrors) {
  FmuLibrary& inverse = inverse_library();
  InverseFmu inv;
  PlantFmu plant;
  ASSERT_NE(inv.c, nullptr);
  ASSERT_NE(plant.c, nullptr);
  const fmi2ValueReference vr = 1;
  for (auto [library, foreign] : {std::pair<FmuLibrary*, fmi2Component>{&lib, inv.c}, {&inverse, plant.c}}) {
    double v = kCanary;
    fmi2FMUstate state = nullptr;
    EXPECT_EQ(library->fmi2SetReal(foreign, &vr, 1, &v), fmi2Error);
    EXPECT_EQ(library->fmi2GetReal(foreign, &vr, 1, &v), fmi2Error);
    EXPECT_EQ(v, kCanary);
    EXPECT_EQ(library->fmi2SetupExperiment(foreign, fmi2False, 0, 0, fmi2False, 0), fmi2Error);
    EXPECT_EQ(library->fmi2EnterInitializationMode(foreign), fmi2Error);
    EXPECT_EQ(library->fmi2DoStep(foreign, 0.0, 1e-3, fmi2True), fmi2Error);
    EXPECT_EQ(library->fmi2GetFMUstate(foreign, &state), fmi2Error);
    EXPECT_EQ(state, nullptr);
    EXPECT_EQ(library->fmi2Reset(foreign), fmi2Error);
    library->fmi2FreeInstance(foreign);  // ignored: not this library's
  }
  // An FMI 2.0 instance handed to the same library's FMI 3.0 functions.
  auto* fmi3_do_step = reinterpret_cast<fmi3DoStepTYPE*>(dlsym(lib.handle, "fmi3DoStep"));
  auto* fmi3_get = reinterpret_cast<fmi3GetFloat64TYPE*>(dlsym(lib.handle, "fmi3GetFloat64"));
  auto* fmi3_free = reinterpret_cast<fmi3FreeInstanceTYPE*>(dlsym(lib.handle, "fmi3FreeInstance"));
  ASSERT_TRUE(fmi3_do_step && fmi3_get && fmi3_free);
  fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
  fmi3Float64 last = kCanary, v = kCanary;
  const fmi3ValueReference vr3 = 1;
  EXPECT_EQ(fmi3_do_step(plant.c, 0.0, 1e-3, fmi3True, &event, &terminate, &early, &last), fmi3Error);
  EXPECT_EQ(fmi3_get(plant.c, &vr3, 1, &v, 1), fmi3Error);
  EXPECT_EQ(v, kCanary);
  fmi3_free(plant.c);  // ignored: an FMI 2.0 instance

  // Both instances survived every call above and still work with their own library.
  inv.initialize();
  EXPECT_NEAR(inv.get("F[1]"), kStaticForce, 1e-9) << inv.log.dump();
  plant.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(plant.set(force_name(i), kStaticForce), fmi2OK);
  ASSERT_EQ(plant.step(0.0, 1e-3), fmi2OK) << plant.log.dump();
  EXPECT_NEAR(plant.get("z"), 0.05, 1e-12) << "held at rest by the static forces";
  table_row("an instance of the inverse FMU passed to the plant library (and the reverse), and an FMI 2.0 instance "
            "to the FMI 3.0 functions: SetReal, GetReal, SetupExperiment, EnterInitializationMode, DoStep, "
            "GetFMUstate, Reset, FreeInstance",
            "fmi2Error / fmi3Error each; FreeInstance ignores it; the instance keeps working with its own library",
            "yes");
}

TEST_F(HardeningMisuse, InstantiateWithBadArguments) {
  Log log;
  const fmi2CallbackFunctions f{&collect_log, &std::calloc, &std::free, nullptr, &log};
  EXPECT_EQ(lib.fmi2Instantiate(nullptr, fmi2CoSimulation, PKM_FMU_PLANT_GUID, "", &f, fmi2False, fmi2False), nullptr);
  EXPECT_EQ(lib.fmi2Instantiate("x", fmi2CoSimulation, nullptr, "", &f, fmi2False, fmi2False), nullptr);
  EXPECT_EQ(lib.fmi2Instantiate("x", fmi2CoSimulation, "{00000000-0000-0000-0000-000000000000}", "", &f, fmi2False,
                                fmi2False),
            nullptr);
  EXPECT_EQ(lib.fmi2Instantiate("x", static_cast<fmi2Type>(7), PKM_FMU_PLANT_GUID, "", &f, fmi2False, fmi2False),
            nullptr);
  EXPECT_EQ(log.messages.size(), 4u) << log.dump();
  // No callbacks at all, no resource location: a working, silent instance.
  fmi2Component c = lib.fmi2Instantiate("x", fmi2CoSimulation, PKM_FMU_PLANT_GUID, nullptr, nullptr, fmi2False,
                                        fmi2True);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(lib.fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0), fmi2OK);
  EXPECT_EQ(lib.fmi2EnterInitializationMode(c), fmi2OK);
  EXPECT_EQ(lib.fmi2ExitInitializationMode(c), fmi2OK);
  EXPECT_EQ(lib.fmi2DoStep(c, 0.0, -1.0, fmi2True), fmi2Error);  // an error with nobody to tell
  EXPECT_EQ(lib.fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2OK);
  lib.fmi2FreeInstance(c);
  table_row("fmi2Instantiate with instanceName NULL, GUID NULL or of another model, fmuType 7; "
            "with no callback functions at all",
            "NULL, with the reason logged when there is a logger; without callbacks: a working instance that logs "
            "nothing",
            "nothing to lose yet");
}

// ---------------------------------------------------------------- communication steps

TEST_F(HardeningMisuse, BadCommunicationSteps) {
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

TEST_F(HardeningMisuse, AStepWhoseEndOverflowsIsAnError) {
  PlantFmu p;
  ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 1e308, fmi2False, 0.0), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  ASSERT_EQ(p.exit(), fmi2OK);
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

// Issue 17.7: at t = 1e15 a 1 ms step rounds away (the spacing of doubles
// there is 0.125 s): answering OK would advance nothing.
TEST_F(HardeningMisuse, AStepThatVanishesInTPlusHIsAnError) {
  PlantFmu p;
  ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 1e15, fmi2False, 0.0), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  ASSERT_EQ(p.exit(), fmi2OK);
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

// Issue 17.7: at startTime 1e9 s, t + 1 ms rounds to a multiple of 0.12 us;
// the model used to integrate (t + h) - t, 7e-5 s lost over 1 s. It
// integrates the time since start: the motion is that of a start at 0.
TEST_F(HardeningMisuse, TheMotionDoesNotDependOnTheStartTime) {
  for (int solver : {0, 1}) {
    SCOPED_TRACE(solver == 0 ? "CVODE" : "RK4");
    PlantFmu late("late"), early("early");
    for (PlantFmu* p : {&late, &early}) {
      ASSERT_EQ(p->set_int("solver", solver), fmi2OK);
      const double start = p == &late ? 1e9 : 0.0;
      ASSERT_EQ(lib.fmi2SetupExperiment(p->c, fmi2False, 0.0, start, fmi2False, 0.0), fmi2OK);
      ASSERT_EQ(p->enter(), fmi2OK);
      ASSERT_EQ(p->exit(), fmi2OK);
      double t = start;
      for (int k = 0; k < 1000; ++k) {
        drive(*p, k * 1e-3);  // the same forces at the same time since start
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

TEST_F(HardeningMisuse, AStepTooLongForCvodeIsDiscarded) {
  PlantFmu p;
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), kStaticForce + 0.01 * i), fmi2OK);
  ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(1e-3, 1e6), fmi2Discard);
  EXPECT_TRUE(p.log.contains("mxstep")) << p.log.dump();
  EXPECT_TRUE(p.terminated());
  EXPECT_EQ(p.last_successful_time(), 1e-3);
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  table_row("CVODE, fmi2DoStep(h = 1e6 s): more than CVODE's 100000 internal steps",
            "fmi2Discard, fmi2Terminated = true (\"CVODE ... mxstep steps taken before reaching tout\")",
            "yes: every variable bit-identical at fmi2LastSuccessfulTime = the step start");
}

TEST_F(HardeningMisuse, AStepPastTheStopTimeIsAnError) {
  PlantFmu p;
  ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 0.0, fmi2True, 0.01), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  ASSERT_EQ(p.exit(), fmi2OK);
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), kStaticForce), fmi2OK);
  for (int k = 0; k < 9; ++k) ASSERT_EQ(p.step(k * 1e-3, 1e-3), fmi2OK);
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(0.009, 2e-3), fmi2Error);
  EXPECT_TRUE(p.log.contains("would pass stopTime")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  EXPECT_EQ(p.step(0.009, 1e-3 + 1e-15), fmi2OK) << "rounding of the last step is tolerated\n" << p.log.dump();
  EXPECT_EQ(p.step(0.01, 1e-3), fmi2Error);
  table_row("fmi2SetupExperiment(stopTimeDefined, stopTime = 0.01 s), then fmi2DoStep(0.009, 0.002) past it",
            "fmi2Error (FMI 2.0: computing past a defined stopTime), \"the step to t = 0.011 would pass stopTime "
            "= 0.01 ...; the call has no effect\"",
            "yes: every variable bit-identical; the step to exactly stopTime (within 1e-9 relative) succeeds");
}

TEST_F(HardeningMisuse, TooManyRk4StepsAreRefusedBeforeAnyWork) {
  // The smallest rk4_step its range allows (1e-6 s): a 20 s step needs 2e7
  // RK4 steps, twice the work budget (1e7, about 25 s of computing).
  PlantFmu p("refused"), twin("twin");
  for (PlantFmu* q : {&p, &twin}) {
    ASSERT_EQ(q->set_int("solver", 1), fmi2OK);
    ASSERT_EQ(q->set("rk4_step", 1e-6), fmi2OK);
    q->initialize();
    drive(*q, 0.0);
  }
  const std::vector<double> before = p.all_reals();
  EXPECT_EQ(p.step(0.0, 20.0), fmi2Error);
  EXPECT_TRUE(p.log.contains("more than the work budget of 1e+07")) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.all_reals(), before));
  // Usable as it was (no Reset, no SetFMUstate): the next step is the twin's.
  ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
  ASSERT_EQ(twin.step(0.0, 1e-3), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs()));
  table_row("RK4 with rk4_step = 1e-6 s (the smallest its range allows), then fmi2DoStep(h = 20 s): 2e7 RK4 steps",
            "fmi2Error at once, \"a communication step of 20 s needs 2e+07 RK4 steps of rk4_step = 1e-06 s, more "
            "than the work budget of 1e+07 per step ...; the call has no effect\"",
            "yes: every variable bit-identical; the next step bit-identical to an untouched twin's");
}

TEST_F(HardeningMisuse, HugeFiniteInputsEndTheStepWithADiscard) {
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

// ---------------------------------------------------------------- FMU states and logging

TEST_F(HardeningMisuse, ForeignOrBrokenFmuStates) {
  on_stepping_instance(
      "fmi2SetFMUstate / FreeFMUstate / SerializedFMUstateSize / SerializeFMUstate with a pointer that is not an "
      "FMU state; fmi2GetFMUstate into a *FMUstate that is not one; fmi2DeSerializeFMUstate of zeros, of a "
      "truncated, a bit-flipped or an inverse-FMU state; fmi2SerializeFMUstate into a buffer one byte short",
      fmi2Error,
      "fmi2Error each, \"not an FMU state of this FMU\" / \"checksum mismatch\" / \"belongs to another FMU\" / "
      "\"buffer of n bytes, n+1 needed\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        alignas(16) unsigned char junk[256] = {};
        void* foreign = junk;
        std::size_t size = 0;
        s.push_back(lib.fmi2SetFMUstate(p.c, foreign));
        fmi2FMUstate f = foreign;
        s.push_back(lib.fmi2FreeFMUstate(p.c, &f));
        s.push_back(lib.fmi2SerializedFMUstateSize(p.c, foreign, &size));
        s.push_back(lib.fmi2SerializeFMUstate(p.c, foreign, reinterpret_cast<fmi2Byte*>(junk), sizeof junk));
        s.push_back(lib.fmi2GetFMUstate(p.c, &f));
        fmi2FMUstate good = nullptr;
        EXPECT_EQ(lib.fmi2GetFMUstate(p.c, &good), fmi2OK);
        EXPECT_EQ(lib.fmi2SerializedFMUstateSize(p.c, good, &size), fmi2OK);
        std::vector<fmi2Byte> bytes(size + 2, 0x11);
        s.push_back(lib.fmi2SerializeFMUstate(p.c, good, bytes.data() + 1, size - 1));
        for (fmi2Byte byte : bytes) EXPECT_EQ(byte, 0x11) << "nothing written into a short buffer";
        EXPECT_EQ(lib.fmi2SerializeFMUstate(p.c, good, bytes.data() + 1, size), fmi2OK);
        EXPECT_EQ(bytes[0], 0x11);
        EXPECT_EQ(bytes[size + 1], 0x11);
        fmi2FMUstate out = nullptr;
        std::vector<fmi2Byte> zeros(size, 0);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, zeros.data(), zeros.size(), &out));
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, bytes.data() + 1, size - 1, &out));
        std::vector<fmi2Byte> flipped(bytes.begin() + 1, bytes.begin() + 1 + static_cast<long>(size));
        flipped[size / 3] = static_cast<fmi2Byte>(flipped[size / 3] ^ 0x40);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, flipped.data(), flipped.size(), &out));
        InverseFmu inv;
        inv.initialize();
        fmi2FMUstate is = nullptr;
        EXPECT_EQ(inv.lib.fmi2GetFMUstate(inv.c, &is), fmi2OK);
        std::size_t isize = 0;
        EXPECT_EQ(inv.lib.fmi2SerializedFMUstateSize(inv.c, is, &isize), fmi2OK);
        std::vector<fmi2Byte> other(isize);
        EXPECT_EQ(inv.lib.fmi2SerializeFMUstate(inv.c, is, other.data(), other.size()), fmi2OK);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, other.data(), other.size(), &out));
        EXPECT_EQ(out, nullptr);
        // The inverse FMU's in-memory state handed to the plant: a state object, of the other model.
        s.push_back(lib.fmi2SetFMUstate(p.c, is));
        inv.lib.fmi2FreeFMUstate(inv.c, &is);
        EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &good), fmi2OK);
        for (unsigned char byte : junk) EXPECT_EQ(byte, 0);
        return s;
      });
}

/// The instance's current state, serialized.
std::vector<fmi2Byte> serialized_state(FmuInstance& p) {
  fmi2FMUstate st = nullptr;
  std::size_t size = 0;
  EXPECT_EQ(p.lib.fmi2GetFMUstate(p.c, &st), fmi2OK);
  EXPECT_EQ(p.lib.fmi2SerializedFMUstateSize(p.c, st, &size), fmi2OK);
  std::vector<fmi2Byte> bytes(size);
  EXPECT_EQ(p.lib.fmi2SerializeFMUstate(p.c, st, bytes.data(), size), fmi2OK);
  EXPECT_EQ(p.lib.fmi2FreeFMUstate(p.c, &st), fmi2OK);
  return bytes;
}

/// A serialized state with the bytes at `at` replaced by `value` (a double,
/// or the low 4 bytes of an integer when `u32`) and the checksum recomputed
/// (fnv1a.hpp): a forgery that passes the header checks.
std::vector<fmi2Byte> forge(std::vector<fmi2Byte> b, std::size_t at, double value, bool u32 = false) {
  std::uint64_t bits = static_cast<std::uint64_t>(value);
  if (!u32) std::memcpy(&bits, &value, 8);
  for (int k = 0; k < (u32 ? 4 : 8); ++k) b[at + k] = static_cast<fmi2Byte>((bits >> (8 * k)) & 0xff);  // little-endian
  const std::uint64_t h = pkm_fmi::fnv1a(reinterpret_cast<const unsigned char*>(b.data()), b.size() - 8);
  for (int k = 0; k < 8; ++k) b[b.size() - 8 + k] = static_cast<fmi2Byte>((h >> (8 * k)) & 0xff);
  return b;
}

// Issue 17.6: states with a valid checksum and absurd content. The layout
// (fmu_state.cpp): a 32-byte header; mode (4), three flags (3), startTime,
// stopTime, time, last successful time, time since start (8 each) from byte
// 39; the count (4) and the stored variables (8 each) from byte 83; then the input
// derivatives and the plant's part, which ends (before the 8-byte checksum)
// with time (8), [pose; velocity] (64), the theta1 references (32), the
// energy integrals (16) and the end-stop record (4).
TEST_F(HardeningMisuse, ForgedFmuStatesWithAValidChecksumAreRefused) {
  on_stepping_instance(
      "fmi2DeSerializeFMUstate + fmi2SetFMUstate of states forged with a recomputed checksum: time = NaN, startTime "
      "after the time, m_platform = -1, the plant's time = NaN, dx = 1e200 m/s, theta1 reference of leg 2 = 1e16 "
      "rad or off by 1 rad, an end-stop record naming no stop",
      fmi2Error,
      "fmi2SetFMUstate: fmi2Error \"malformed FMU state (a time is not finite ...)\" / \"... outside its range\" / "
      "\"beyond the physical bound 1000 m/s\" / \"theta1 reference ... is not the pose's theta1\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        const std::vector<fmi2Byte> bytes = serialized_state(p);
        const std::size_t size = bytes.size(), end = size - 8;
        std::size_t m_platform = 83;
        for (std::size_t i = 0; i < p.def.n_variables; ++i) {
          const pkm_fmi::Variable& v = p.def.variables[i];
          if (std::string(v.name) == "m_platform") break;
          if (v.stored_in_state()) m_platform += 8;
        }
        double theta1_2 = 0.0;
        std::memcpy(&theta1_2, &bytes[end - 52 + 8], 8);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const struct {
          std::size_t at;
          double value;
          const char* reason;
          bool u32 = false;
        } forgeries[] = {
            {55, nan, "a time is not finite"},
            {39, 1.0, "the time lies before startTime"},
            {71, 5.0, "the time since startTime does not match the time"},
            {m_platform, -1.0, "m_platform = -1, outside its range"},
            {end - 124, nan, "not finite"},
            {end - 84, 1e200, "beyond the physical bound"},
            {end - 52 + 8, 1e16, "theta1 reference 10000000000000000 rad of leg 2"},
            {end - 52 + 8, theta1_2 + 1.0, "of leg 2 is not the pose's theta1"},
            {end - 4, 0xffff, "end-stop record", true},
        };
        // The control: the same bytes with the checksum recomputed restore.
        {
          double time = 0.0;
          std::memcpy(&time, &bytes[55], 8);
          fmi2FMUstate same = nullptr;
          EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, forge(bytes, 55, time).data(), size, &same), fmi2OK);
          EXPECT_EQ(lib.fmi2SetFMUstate(p.c, same), fmi2OK) << p.log.dump();
          EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &same), fmi2OK);
        }
        for (const auto& f : forgeries) {
          SCOPED_TRACE(f.reason);
          const std::vector<fmi2Byte> forged = forge(bytes, f.at, f.value, f.u32);
          fmi2FMUstate st = nullptr;
          EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, forged.data(), forged.size(), &st), fmi2OK);
          const std::size_t logged = p.log.messages.size();
          s.push_back(lib.fmi2SetFMUstate(p.c, st));
          bool named = false;
          for (std::size_t k = logged; k < p.log.messages.size(); ++k)
            named = named || p.log.messages[k].text.find(f.reason) != std::string::npos;
          EXPECT_TRUE(named) << p.log.dump();
          EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &st), fmi2OK);
        }
        return s;
      });
}

// ---------------------------------------------------------------- the error policy

// The error policy (README "Error policy", instance.hpp) as a table: each
// refusal, its status, and what the instance can still do without Reset.
// Errors found before anything changed leave the instance as it was,
// wherever they come from (FMI 2.0.4 allows an importer to give up after
// any fmi2Error; this FMU guarantees more). Discard leaves a valid
// instance: StepFailed (Co-Simulation) until a saved state is restored or
// the importer terminates, the inputs' domain for a get.
TEST_F(HardeningMisuse, TheErrorPolicyAsATable) {
  struct Row {
    const char* refusal;
    fmi2Status expected;
    std::function<fmi2Status(PlantFmu&, double)> refuse;
    const char* after;
    std::function<void(PlantFmu&, double)> usable;
  };
  auto steps_on = [](PlantFmu& p, double t) {
    drive(p, t);
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
         drive(p, 0.0);
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
  ASSERT_EQ(p.set("l", 0.0), fmi2OK);
  ASSERT_EQ(p.setup(), fmi2OK);
  ASSERT_EQ(p.enter(), fmi2OK);
  EXPECT_EQ(p.exit(), fmi2Error);
  EXPECT_TRUE(p.log.contains("l = 0 must be positive")) << p.log.dump();
  ASSERT_EQ(p.set("l", 0.08), fmi2OK) << p.log.dump();
  ASSERT_EQ(p.exit(), fmi2OK) << p.log.dump();
  steps_on(p, 0.0);
  table_row("error policy: fmi2ExitInitializationMode with l = 0", "fmi2Error, reason logged",
            "InitializationMode: the parameter corrected, fmi2ExitInitializationMode succeeds (no fmi2Reset)");
  // The inverse FMU: a get beyond a singularity guard.
  InverseFmu inv;
  inv.initialize();
  const std::vector<double> good = inv.outputs();
  ASSERT_EQ(inv.set("x", 0.0231306807897694 * (1.0 - 1e-9)), fmi2OK);  // leg 2's rod within 3e-5 rad of horizontal
  const fmi2ValueReference F1 = inv.vr("F[1]");
  double f = 0.0;
  EXPECT_EQ(inv.lib.fmi2GetReal(inv.c, &F1, 1, &f), fmi2Discard) << inv.log.dump();
  EXPECT_EQ(f, good[0]);
  ASSERT_EQ(inv.set("x", 0.0), fmi2OK);
  EXPECT_TRUE(bit_identical(inv.outputs(), good));
  table_row("error policy: inverse fmi2GetReal at a pose beyond a singularity guard", "fmi2Discard, reason logged",
            "the last good outputs handed out; inputs within the guards: fmi2OK again");
}

TEST_F(HardeningMisuse, StatesLeftBehindAreFreedWithTheInstance) {
  // FMI 2.0: fmi2FreeInstance frees everything the instance allocated. The
  // valgrind test (hardening_valgrind) checks that nothing leaks; here: a
  // state freed through another instance of the FMU is forgotten by its creator.
  PlantFmu a("a"), b("b");
  a.initialize();
  b.initialize();
  fmi2FMUstate s1 = nullptr, s2 = nullptr, s3 = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s1), fmi2OK);
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s2), fmi2OK);
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s3), fmi2OK);
  ASSERT_EQ(lib.fmi2FreeFMUstate(b.c, &s2), fmi2OK);  // freed through b
  ASSERT_EQ(lib.fmi2SetFMUstate(b.c, s3), fmi2OK);    // used by b
  EXPECT_EQ(lib.fmi2FreeFMUstate(a.c, &s1), fmi2OK);
  // s3 stays with a, which frees it.
  table_row("FMU states never freed by the importer (fmi2GetFMUstate / fmi2DeSerializeFMUstate, then "
            "fmi2FreeInstance); a state freed or used through another instance of the FMU",
            "fmi2FreeInstance frees them (FMI 2.0: all memory of the instance); fmi2OK for the others",
            "no leak (valgrind: 0 bytes definitely lost)");
}

TEST_F(HardeningMisuse, LogMessagesWithFormatCharactersAreSafe) {
  on_stepping_instance(
      "fmi2SetDebugLogging with the category \"%s%s%n%x\", an unknown category, a NULL category",
      fmi2Error,
      "fmi2Error, \"unknown log category \\\"%s%s%n%x\\\"\" delivered with '%' escaped (the importer's printf "
      "prints it literally)",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        const fmi2String evil[1] = {"%s%s%n%x"};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, evil));
        EXPECT_TRUE(p.log.contains("\"%s%s%n%x\"")) << p.log.dump();
        const fmi2String unknown[1] = {"logNothing"};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, unknown));
        const fmi2String null_name[1] = {nullptr};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, null_name));
        // A long list of known names is no misuse: accepted.
        std::vector<fmi2String> many(1000, "logEvents");
        EXPECT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, many.size(), many.data()), fmi2OK);
        return s;
      });
}

TEST_F(HardeningMisuse, StatusKindsTheStandardDoesNotDefine) {
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
