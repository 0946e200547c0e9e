// SPDX-License-Identifier: BSD-2-Clause
// The FMU binaries given arguments no call may take, through the raw FMI 2.0
// functions as an importer would (dlopen): fmi2Instantiate's checks of its
// arguments, NULL arguments, NULL and foreign handles, and instances of the
// other model or FMI version. Each answer is what the standard prescribes,
// nothing crashes, nothing is written outside the instance (canaries around
// every output buffer), and an instance that was stepping goes on
// bit-identically to an untouched twin. (The order of calls:
// state_machine.cpp; values out of range: bad_inputs_and_parameters.cpp.)
// Every misuse prints a row of the hardening table ("| tried | answer | kept |").
#include <cstddef>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"

namespace {

using namespace pkm_test;

TEST_F(StateMachine, InstantiateChecksGuidAndType) {
  Log log;
  const fmi2CallbackFunctions f{&pkm_test::collect_log, &std::calloc, &std::free, nullptr, &log};
  EXPECT_EQ(lib.fmi2Instantiate("x", fmi2CoSimulation, "{not-the-guid}", "", &f, fmi2False, fmi2False), nullptr);
  EXPECT_EQ(lib.fmi2Instantiate("x", static_cast<fmi2Type>(7), PKM_FMU_PLANT_GUID, "", &f, fmi2False, fmi2False),
            nullptr);
  EXPECT_EQ(lib.fmi2Instantiate("x", fmi2CoSimulation, PKM_FMU_INVERSE_GUID, "", &f, fmi2False, fmi2False), nullptr);
  ASSERT_EQ(log.messages.size(), 3u);
  for (const auto& m : log.messages) EXPECT_EQ(m.status, fmi2Error);
  EXPECT_TRUE(log.contains("GUID"));
  EXPECT_TRUE(log.contains("fmuType = 7"));
  // Both interfaces of the one binary.
  for (fmi2Type type : {fmi2ModelExchange, fmi2CoSimulation}) {
    fmi2Component c = lib.fmi2Instantiate("x", type, PKM_FMU_PLANT_GUID, "", &f, fmi2False, fmi2False);
    EXPECT_NE(c, nullptr) << log.dump();
    lib.fmi2FreeInstance(c);
  }
}

TEST_F(StateMachine, NullArgumentsAreErrors) {
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

TEST_F(StateMachine, NullAndForeignComponentsAreErrorsWithoutACrash) {
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

#ifndef _WIN32  // the FMI 3.0 functions are looked up with dlsym
// Both libraries are built from the same sources: an instance made by one
// has the right tag for the other, only its model definition differs. Each
// library must serve its own model's instances only, and the
// FMI 3.0 entry points only instances made by fmi3Instantiate*.
TEST_F(StateMachine, InstancesOfTheOtherModelOrFmiVersionAreErrors) {
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
#endif  // _WIN32

TEST_F(StateMachine, InstantiateWithBadArguments) {
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

}  // namespace
