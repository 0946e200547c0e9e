// The built FMU binaries (PKM4PUU.so, PKM4PUU_Inverse.so), loaded with
// dlopen and driven through the raw FMI 2.0 functions, as an importer
// would: life cycle, static equilibrium, errors, FMU states, discarded
// steps, input interpolation, independence of instances, logging, the
// exported symbols and the shared libraries they need; and fmpy's view of
// the packaged .fmu files when fmpy is available.
//
// A cross build (cmake/Platforms.cmake: Windows x64 under wine, Linux
// aarch64 under qemu) compiles it with PKM_TEST_ON_TARGET: the tests that
// run host programs (ldd, nm, fmpy) on the build's files are left out there
// (the host build checks the cross-built binaries' imports and exports), and
// so is the stdout/stderr test on Windows (POSIX file descriptors).
#ifndef _WIN32
#include <fcntl.h>
#include <unistd.h>
#endif

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmu_loader.hpp"
#include "models.hpp"

namespace {

using pkm_test::kPi;
using pkm_test::kStaticForce;
using pkm_test::plant_library;
using pkm_test::inverse_library;
using Library = pkm_test::FmuLibrary;

// ---------------------------------------------------------------- an instance

using pkm_test::Log;

/// tests/fmu_loader.hpp's instance, with this file's argument order
/// (logging flag before the instance name).
class Instance : public pkm_test::FmuInstance {
 public:
  Instance(Library& lib, const pkm_fmi::ModelDefinition& def, const char* guid, bool logging_on = false,
           const char* name = "instance")
      : FmuInstance(lib, def, guid, name, logging_on) {}
};

struct Plant : Instance {
  explicit Plant(bool logging_on = false, const char* name = "plant")
      : Instance(plant_library(), pkm_fmi::pkm4puu_definition(), PKM_FMU_PLANT_GUID, logging_on, name) {}
};

struct Inverse : Instance {
  explicit Inverse(bool logging_on = false)
      : Instance(inverse_library(), pkm_fmi::pkm4puu_inverse_definition(), PKM_FMU_INVERSE_GUID, logging_on,
                 "inverse") {}
};

bool bit_identical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

/// Inputs that move the platform around: forces near the static ones plus
/// a slow variation, and their derivatives for interpolation.
void drive(Instance& p, double t) {
  for (int i = 1; i <= 4; ++i) {
    const std::string F = "F[" + std::to_string(i) + "]";
    const double w = 2.0 * kPi * (1.0 + 0.3 * i);
    ASSERT_EQ(p.set(F, kStaticForce + 0.02 * std::sin(w * t)), fmi2OK);
    ASSERT_EQ(p.set_derivative(F, 0.02 * w * std::cos(w * t)), fmi2OK);
  }
  ASSERT_EQ(p.set("Me_z", 1e-3 * std::cos(3.0 * t)), fmi2OK);
}

/// n steps of h from t, driving the inputs; the outputs after each step.
std::vector<double> run(Instance& p, Library& lib, double& t, int n, double h) {
  std::vector<double> trace;
  for (int k = 0; k < n; ++k) {
    drive(p, t);
    EXPECT_EQ(lib.fmi2DoStep(p.c, t, h, fmi2True), fmi2OK) << p.log.dump();
    t += h;
    const std::vector<double> o = p.outputs();
    trace.insert(trace.end(), o.begin(), o.end());
  }
  return trace;
}

class Fmi2 : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(plant_library().missing.empty()) << "PKM4PUU.so: " << plant_library().missing;
    ASSERT_TRUE(inverse_library().missing.empty()) << "PKM4PUU_Inverse.so: " << inverse_library().missing;
  }
  Library& lib = plant_library();
};

// ---------------------------------------------------------------- life cycle

TEST_F(Fmi2, VersionAndPlatform) {
  EXPECT_STREQ(lib.fmi2GetVersion(), "2.0");
  EXPECT_STREQ(lib.fmi2GetTypesPlatform(), "default");
}

TEST_F(Fmi2, InstantiateChecksGuidAndType) {
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

TEST_F(Fmi2, HoldsTheHomePoseWithTheStaticForces) {
  Plant p;
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
  EXPECT_NEAR(p.get("rho[1]"), 0.0443193423, 1e-10);  // MODEL_SPEC golden pose
  EXPECT_NEAR(p.get("theta2[2]"), -0.8606121019, 1e-10);
  EXPECT_TRUE(std::isfinite(p.get("jacobian_condition")));
  EXPECT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  EXPECT_TRUE(p.log.messages.empty()) << p.log.dump();
}

TEST_F(Fmi2, Rk4HoldsTheHomePoseToo) {
  Plant p;
  ASSERT_EQ(p.set_int("solver", 1), fmi2OK);
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set("F[" + std::to_string(i) + "]", kStaticForce), fmi2OK);
  for (int k = 0; k < 200; ++k) ASSERT_EQ(lib.fmi2DoStep(p.c, k * 1e-2, 1e-2, fmi2True), fmi2OK);
  EXPECT_NEAR(p.get("z"), 0.05, 1e-9);
  EXPECT_NEAR(p.get("x"), 0.0, 1e-9);
}

TEST_F(Fmi2, OutOfOrderCallsAreErrorsWithoutEffect) {
  Plant p;
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

TEST_F(Fmi2, NonFiniteInputsAreRejected) {
  Plant p;
  p.initialize();
  ASSERT_EQ(p.set("F[1]", 1.5), fmi2OK);
  EXPECT_EQ(p.set("F[1]", std::nan("")), fmi2Error);
  EXPECT_TRUE(p.log.contains("F[1]")) << p.log.dump();
  EXPECT_EQ(p.set("Fe[2]", INFINITY), fmi2Error);
  EXPECT_EQ(p.set_derivative("F[2]", -INFINITY), fmi2Error);
  // Rejected values change nothing, also within a vector call.
  const fmi2ValueReference vrs[2] = {p.vr("F[3]"), p.vr("F[4]")};
  const double values[2] = {7.0, std::nan("")};
  EXPECT_EQ(lib.fmi2SetReal(p.c, vrs, 2, values), fmi2Error);
  EXPECT_EQ(p.get("F[1]"), 1.5);
  EXPECT_EQ(p.get("F[3]"), kStaticForce);  // its start value (MODEL_SPEC)
  EXPECT_EQ(p.get("Fe[2]"), 0.0);
  // Nor parameters before initialisation.
  Plant q;
  EXPECT_EQ(q.set("rtol", std::nan("")), fmi2Error);
  // And an inverse input.
  Inverse inv;
  EXPECT_EQ(inv.set("ddz", std::nan("")), fmi2Error);
}

TEST_F(Fmi2, UnknownValueReferencesAreErrors) {
  Plant p;
  p.initialize();
  double v = 0.0;
  fmi2Integer i = 0;
  fmi2Boolean b = fmi2False;
  const fmi2ValueReference unknown = 99999, real = p.vr("x"), integer = p.vr("solver");
  EXPECT_EQ(lib.fmi2GetReal(p.c, &unknown, 1, &v), fmi2Error);
  EXPECT_EQ(lib.fmi2SetReal(p.c, &unknown, 1, &v), fmi2Error);
  EXPECT_EQ(lib.fmi2GetInteger(p.c, &real, 1, &i), fmi2Error);  // a Real's reference
  EXPECT_EQ(lib.fmi2GetReal(p.c, &integer, 1, &v), fmi2Error);  // an Integer's reference
  EXPECT_EQ(lib.fmi2GetBoolean(p.c, &real, 1, &b), fmi2Error);
  fmi2String s = nullptr;
  EXPECT_EQ(lib.fmi2GetString(p.c, &real, 1, &s), fmi2Error);
  EXPECT_TRUE(p.log.contains("unknown value reference 99999")) << p.log.dump();
  EXPECT_EQ(lib.fmi2GetInteger(p.c, &integer, 1, &i), fmi2OK);
  EXPECT_EQ(i, 0);
  // A mixed call with one bad reference writes nothing.
  const fmi2ValueReference vrs[2] = {p.vr("F[1]"), unknown};
  const double values[2] = {3.0, 4.0};
  EXPECT_EQ(lib.fmi2SetReal(p.c, vrs, 2, values), fmi2Error);
  EXPECT_EQ(p.get("F[1]"), kStaticForce);  // its start value (MODEL_SPEC)
}

TEST_F(Fmi2, InvalidParametersAndUnreachablePosesFailInitialisation) {
  {
    Plant p;
    // Outside the modelDescription's range: refused when set, the start value kept.
    EXPECT_EQ(p.set("r_b", -1.0), fmi2Error);
    EXPECT_TRUE(p.log.contains("r_b = -1 lies outside its range [0, 10] m")) << p.log.dump();
    // Within the range but not usable (r_b must be positive): refused at initialisation.
    ASSERT_EQ(p.set("r_b", 0.0), fmi2OK);
    ASSERT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2OK);
    EXPECT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2Error);
    EXPECT_TRUE(p.log.contains("r_b")) << p.log.dump();
    EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
    EXPECT_EQ(lib.fmi2Reset(p.c), fmi2OK);  // still in initialization mode: allowed
    p.initialize();                          // start values again: r_b valid
  }
  {
    Plant p;
    ASSERT_EQ(p.set("x0", 0.2), fmi2OK);
    ASSERT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2OK);
    EXPECT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2Error);
    EXPECT_TRUE(p.log.contains("unreachable")) << p.log.dump();
  }
  {
    Plant p;
    EXPECT_EQ(p.set_int("formulation", 7), fmi2Error);  // outside [0, 2]: refused when set
    EXPECT_TRUE(p.log.contains("formulation = 7 lies outside its range [0, 2]")) << p.log.dump();
  }
  {
    Plant p;
    ASSERT_EQ(p.set("atol", 0.0), fmi2OK);  // within [0, 1], but CVODE needs it positive
    ASSERT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2OK);
    EXPECT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2Error);
    EXPECT_TRUE(p.log.contains("atol = 0 must be positive")) << p.log.dump();
  }
}

TEST_F(Fmi2, OutputsAreAvailableInInitializationMode) {
  Plant p;
  ASSERT_EQ(p.set("z0", 0.07), fmi2OK);
  ASSERT_EQ(lib.fmi2SetupExperiment(p.c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
  ASSERT_EQ(lib.fmi2EnterInitializationMode(p.c), fmi2OK);
  EXPECT_EQ(p.get("z"), 0.07);
  EXPECT_EQ(p.get("l"), 0.08);
  ASSERT_EQ(p.set("z0", 0.05), fmi2OK);
  EXPECT_EQ(p.get("z"), 0.05);
  EXPECT_NEAR(p.get("rho[3]"), 0.0443193423, 1e-10);
  ASSERT_EQ(lib.fmi2ExitInitializationMode(p.c), fmi2OK);
  EXPECT_EQ(p.get("z"), 0.05);
}

// ---------------------------------------------------------------- FMU states

class FmuStates : public Fmi2, public ::testing::WithParamInterface<int> {};

TEST_P(FmuStates, GetSetGivesABitIdenticalContinuation) {
  Plant p;
  ASSERT_EQ(p.set_int("solver", GetParam()), fmi2OK);
  ASSERT_EQ(p.set("dx0", 0.01), fmi2OK);
  p.initialize();
  double t = 0.0;
  run(p, lib, t, 30, 1e-3);
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  ASSERT_NE(s, nullptr);
  const double t_saved = t;
  const std::vector<double> a = run(p, lib, t, 150, 1e-3);
  ASSERT_EQ(lib.fmi2SetFMUstate(p.c, s), fmi2OK) << p.log.dump();
  t = t_saved;
  const std::vector<double> b = run(p, lib, t, 150, 1e-3);
  EXPECT_TRUE(bit_identical(a, b)) << "restored run differs";
  // The state can be overwritten in place and freed.
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  ASSERT_EQ(lib.fmi2FreeFMUstate(p.c, &s), fmi2OK);
  EXPECT_EQ(s, nullptr);
}

TEST_P(FmuStates, SerializedStateContinuesInAFreshInstance) {
  Plant p;
  ASSERT_EQ(p.set_int("solver", GetParam()), fmi2OK);
  ASSERT_EQ(p.set("m_platform", 0.5), fmi2OK);  // a non-default parameter travels with the state
  ASSERT_EQ(p.set("dphi0", -0.3), fmi2OK);
  p.initialize();
  double t = 0.0;
  run(p, lib, t, 20, 1e-3);
  // Leave derivatives set: they are part of the state too.
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  std::size_t size = 0;
  ASSERT_EQ(lib.fmi2SerializedFMUstateSize(p.c, s, &size), fmi2OK);
  std::vector<fmi2Byte> bytes(size);
  ASSERT_EQ(lib.fmi2SerializeFMUstate(p.c, s, bytes.data(), bytes.size()), fmi2OK);
  ASSERT_EQ(lib.fmi2FreeFMUstate(p.c, &s), fmi2OK);
  const double t_saved = t;
  const std::vector<double> a = run(p, lib, t, 120, 1e-3);

  Plant fresh(false, "fresh");  // only instantiated: no setup, no initialisation
  fmi2FMUstate s2 = nullptr;
  ASSERT_EQ(lib.fmi2DeSerializeFMUstate(fresh.c, bytes.data(), bytes.size(), &s2), fmi2OK) << fresh.log.dump();
  ASSERT_EQ(lib.fmi2SetFMUstate(fresh.c, s2), fmi2OK) << fresh.log.dump();
  ASSERT_EQ(lib.fmi2FreeFMUstate(fresh.c, &s2), fmi2OK);
  EXPECT_EQ(fresh.get("m_platform"), 0.5);
  t = t_saved;
  const std::vector<double> b = run(fresh, lib, t, 120, 1e-3);
  EXPECT_TRUE(bit_identical(a, b)) << "deserialised run differs";
}

INSTANTIATE_TEST_SUITE_P(CvodeAndRk4, FmuStates, ::testing::Values(0, 1),
                         [](const ::testing::TestParamInfo<int>& i) { return i.param == 0 ? "CVODE" : "RK4"; });

TEST_F(Fmi2, ForeignStateDataIsRejected) {
  Plant p;
  p.initialize();
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  std::size_t size = 0;
  ASSERT_EQ(lib.fmi2SerializedFMUstateSize(p.c, s, &size), fmi2OK);
  std::vector<fmi2Byte> good(size);
  ASSERT_EQ(lib.fmi2SerializeFMUstate(p.c, s, good.data(), good.size()), fmi2OK);
  EXPECT_EQ(lib.fmi2SerializeFMUstate(p.c, s, good.data(), good.size() - 1), fmi2Error);  // buffer too small
  lib.fmi2FreeFMUstate(p.c, &s);

  fmi2FMUstate out = nullptr;
  std::vector<fmi2Byte> junk(size, 0x5a);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, junk.data(), junk.size(), &out), fmi2Error);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), good.size() - 8, &out), fmi2Error);  // truncated
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), 3, &out), fmi2Error);
  std::vector<fmi2Byte> flipped = good;
  flipped[size / 2] = static_cast<fmi2Byte>(flipped[size / 2] ^ 0x01);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, flipped.data(), flipped.size(), &out), fmi2Error);  // checksum
  EXPECT_EQ(out, nullptr);
  // A state of the other FMU.
  Inverse inv;
  inv.initialize();
  fmi2FMUstate si = nullptr;
  Library& ilib = inverse_library();
  ASSERT_EQ(ilib.fmi2GetFMUstate(inv.c, &si), fmi2OK);
  std::size_t isize = 0;
  ASSERT_EQ(ilib.fmi2SerializedFMUstateSize(inv.c, si, &isize), fmi2OK);
  std::vector<fmi2Byte> other(isize);
  ASSERT_EQ(ilib.fmi2SerializeFMUstate(inv.c, si, other.data(), other.size()), fmi2OK);
  ilib.fmi2FreeFMUstate(inv.c, &si);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, other.data(), other.size(), &out), fmi2Error);
  EXPECT_TRUE(p.log.contains("another FMU")) << p.log.dump();
  // Not a state pointer at all.
  double not_a_state[8] = {};
  EXPECT_EQ(lib.fmi2SetFMUstate(p.c, not_a_state), fmi2Error);
  // The good bytes still work, and the instance still steps.
  ASSERT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), good.size(), &out), fmi2OK);
  ASSERT_EQ(lib.fmi2SetFMUstate(p.c, out), fmi2OK);
  lib.fmi2FreeFMUstate(p.c, &out);
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2OK);
}

TEST_F(Fmi2, ResetReturnsToTheStartValues) {
  Plant a;
  ASSERT_EQ(a.set("z0", 0.06), fmi2OK);
  a.initialize();
  ASSERT_EQ(a.set("F[2]", 3.0), fmi2OK);
  ASSERT_EQ(lib.fmi2DoStep(a.c, 0.0, 1e-2, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Reset(a.c), fmi2OK);
  a.initialize();
  EXPECT_EQ(a.get("z0"), 0.05);
  EXPECT_EQ(a.get("F[2]"), kStaticForce);  // its start value (MODEL_SPEC)
  EXPECT_EQ(a.get("z"), 0.05);
  Plant b;
  b.initialize();
  ASSERT_EQ(lib.fmi2DoStep(a.c, 0.0, 1e-2, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2DoStep(b.c, 0.0, 1e-2, fmi2True), fmi2OK);
  EXPECT_TRUE(bit_identical(a.outputs(), b.outputs()));
}

// ---------------------------------------------------------------- discarded steps

TEST_F(Fmi2, AFailedStepIsDiscardedWithTheLastGoodStateKept) {
  for (int solver : {0, 1}) {
    SCOPED_TRACE(solver == 0 ? "CVODE" : "RK4");
    Plant p;
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

// ---------------------------------------------------------------- input interpolation

TEST_F(Fmi2, InputDerivativesInterpolateWithinAStep) {
  // One step of 20 ms with F = F0 + dF (t - t0) against 200 steps of 0.1 ms
  // with the inputs held at their midpoint values: the same ramp, sampled.
  // RK4 with 0.1 ms steps in both, so that the only difference is the
  // sampling, O(1/n^2) relative (CVODE's rtol would hide it).
  Plant ramp, steps;
  for (Plant* p : {&ramp, &steps}) {
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
  Plant held;
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
  Inverse inv;
  EXPECT_EQ(inv.set_derivative("x", 1.0), fmi2Error);
}

// ---------------------------------------------------------------- instances are independent

TEST_F(Fmi2, SeveralInstancesDoNotInterfere) {
  auto solo = [&](double force, std::vector<double>& trace) {
    Plant p;
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
  Plant a(false, "a"), b(false, "b");
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

// ---------------------------------------------------------------- logging

/// How many messages of each category the log holds.
std::map<std::string, int> per_category(const Log& log, std::size_t from = 0) {
  std::map<std::string, int> n;
  for (std::size_t k = from; k < log.messages.size(); ++k) ++n[log.messages[k].category];
  return n;
}

// FMI 2.0.4 section 2.1.5: "If loggingOn = fmi2True and nCategories > 0, then
// only debug messages according to the categories argument shall be output";
// the reason of an Error or a Fatal reaches the logger whatever the setting.
TEST_F(Fmi2, DebugLoggingIsFilteredByCategory) {
  Plant p(/*logging_on=*/false);
  p.initialize();
  ASSERT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2OK);
  EXPECT_TRUE(p.log.messages.empty()) << p.log.dump();
  const fmi2String events[] = {"logEvents"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, events), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  ASSERT_EQ(p.log.messages.size(), 1u) << p.log.dump();
  EXPECT_EQ(p.log.messages[0].category, "logEvents");
  const fmi2String bogus[] = {"logNothing"};
  EXPECT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, bogus), fmi2Error);
  EXPECT_EQ(p.log.messages.back().category, "logStatusError");
  // Logging off, no category named: as loggingOn = false at instantiation,
  // the reasons of a status other than OK still come, events do not.
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2False, 0, nullptr), fmi2OK);
  std::size_t n = p.log.messages.size();
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(per_category(p.log, n), (std::map<std::string, int>{{"logStatusError", 1}})) << p.log.dump();
  // logStatusError switched off by name: the reason of an Error still comes.
  const fmi2String errors[] = {"logStatusError"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2False, 1, errors), fmi2OK);
  n = p.log.messages.size();
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(per_category(p.log, n), (std::map<std::string, int>{{"logStatusError", 1}})) << p.log.dump();
  // Logging on, no category named: events (mode changes), but no call trace.
  Plant q(/*logging_on=*/true);
  q.initialize();
  EXPECT_TRUE(q.log.contains("fmi2ExitInitializationMode")) << q.log.dump();
  for (const auto& m : q.log.messages) EXPECT_NE(m.category, "logCalls") << q.log.dump();
  // logCalls, named with loggingOn = true: exactly that category, the events
  // it replaces are off: 20 steps give 20 calls, the Terminate no event.
  const fmi2String calls[] = {"logCalls"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(q.c, fmi2True, 1, calls), fmi2OK);
  n = q.log.messages.size();
  for (int k = 0; k < 20; ++k) ASSERT_EQ(lib.fmi2DoStep(q.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(q.c), fmi2OK);
  EXPECT_EQ(per_category(q.log, n), (std::map<std::string, int>{{"logCalls", 20}})) << q.log.dump();
  // logEvents named after logCalls: the selection replaces, it does not add.
  ASSERT_EQ(lib.fmi2Reset(q.c), fmi2OK);
  ASSERT_EQ(lib.fmi2SetDebugLogging(q.c, fmi2True, 1, events), fmi2OK);
  n = q.log.messages.size();
  q.initialize();
  for (int k = 0; k < 20; ++k) ASSERT_EQ(lib.fmi2DoStep(q.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(q.c), fmi2OK);
  // Events: entering and leaving initialisation mode, Terminate.
  EXPECT_EQ(per_category(q.log, n), (std::map<std::string, int>{{"logEvents", 3}})) << q.log.dump();
}

#ifndef _WIN32
TEST_F(Fmi2, NothingIsWrittenToStdoutOrStderr) {
  std::fflush(stdout);
  std::fflush(stderr);
  char path[] = "/tmp/pkm_fmi_stdout_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  const int saved_out = dup(1), saved_err = dup(2);
  dup2(fd, 1);
  dup2(fd, 2);
  {
    // With a logger and all categories, and without any logger.
    Plant p(/*logging_on=*/true);
    p.initialize();
    p.set("F[1]", std::nan(""));
    lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True);
    lib.fmi2DoStep(p.c, 5.0, 1e-3, fmi2True);
    const fmi2CallbackFunctions none{nullptr, nullptr, nullptr, nullptr, nullptr};
    fmi2Component c = lib.fmi2Instantiate("silent", fmi2CoSimulation, PKM_FMU_PLANT_GUID, "", &none, fmi2False,
                                          fmi2True);
    EXPECT_NE(c, nullptr);
    lib.fmi2DoStep(c, 0.0, 1e-3, fmi2True);  // an error with nobody to tell
    lib.fmi2FreeInstance(c);
    EXPECT_EQ(lib.fmi2Instantiate("silent", fmi2CoSimulation, "{wrong}", "", &none, fmi2False, fmi2True), nullptr);
    EXPECT_EQ(lib.fmi2Instantiate("silent", fmi2CoSimulation, "{wrong}", "", nullptr, fmi2False, fmi2True), nullptr);
  }
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(saved_out, 1);
  dup2(saved_err, 2);
  close(saved_out);
  close(saved_err);
  const off_t size = lseek(fd, 0, SEEK_END);
  close(fd);
  unlink(path);
  EXPECT_EQ(size, 0) << "the FMU wrote to stdout or stderr";
}
#endif  // _WIN32

// ---------------------------------------------------------------- the inverse FMU

TEST_F(Fmi2, InverseAtRestAtHomeGivesTheStaticForces) {
  Inverse inv;
  ASSERT_NE(inv.c, nullptr);
  inv.initialize();
  Library& ilib = inverse_library();
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
  EXPECT_NEAR(inv.get("rho[1]"), 0.0676488698, 1e-10);  // MODEL_SPEC golden pose
  EXPECT_NEAR(inv.get("rho[4]"), 0.0792527515, 1e-10);
  // Gravity off, at rest: no force.
  Inverse zero_g;
  ASSERT_EQ(zero_g.set("g", 0.0), fmi2OK);
  zero_g.initialize();
  for (int i = 1; i <= 4; ++i) EXPECT_NEAR(zero_g.get("F[" + std::to_string(i) + "]"), 0.0, 1e-15);
}

TEST_F(Fmi2, InverseRejectsAnUnreachablePoseWithoutNaN) {
  Inverse inv;
  inv.initialize();
  Library& ilib = inverse_library();
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

TEST_F(Fmi2, InverseStateRoundTrip) {
  Inverse inv;
  inv.initialize();
  Library& ilib = inverse_library();
  ASSERT_EQ(inv.set("ddz", 0.4), fmi2OK);
  const std::vector<double> before = inv.outputs();
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(ilib.fmi2GetFMUstate(inv.c, &s), fmi2OK);
  ASSERT_EQ(inv.set("ddz", -3.0), fmi2OK);
  ASSERT_EQ(ilib.fmi2DoStep(inv.c, 0.0, 0.1, fmi2True), fmi2OK);
  ASSERT_EQ(ilib.fmi2SetFMUstate(inv.c, s), fmi2OK);
  EXPECT_TRUE(bit_identical(inv.outputs(), before));
  ilib.fmi2FreeFMUstate(inv.c, &s);
  EXPECT_EQ(ilib.fmi2DoStep(inv.c, 0.0, 0.1, fmi2True), fmi2OK) << "time restored to 0";
}

// ---------------------------------------------------------------- the binaries


#ifndef PKM_TEST_ON_TARGET
using pkm_test::capture;
using pkm_test::have_fmpy;

TEST(FmuBinaries, NeedOnlyTheSystemRuntime) {
  // SUNDIALS and the C++ runtime are linked statically (-static-libstdc++
  // -static-libgcc): only libc, libm and the loader remain.
  const std::set<std::string> allowed = {"linux-vdso.so.1", "libc.so.6", "libm.so.6", "libstdc++.so.6",
                                         "libgcc_s.so.1", "ld-linux-x86-64.so.2"};
  for (const char* so : {PKM_FMU_PLANT_SO, PKM_FMU_INVERSE_SO}) {
    int status = 0;
    const std::string out = capture(std::string("ldd '") + so + "' 2>&1", &status);
    ASSERT_EQ(status, 0) << out;
    std::istringstream lines(out);
    std::string line;
    int n = 0;
    while (std::getline(lines, line)) {
      std::istringstream words(line);
      std::string lib;
      words >> lib;
      if (lib.empty()) continue;
      const std::string base = lib.substr(lib.rfind('/') + 1);
      EXPECT_TRUE(allowed.count(base)) << so << " needs " << line;
      EXPECT_EQ(line.find("not found"), std::string::npos) << line;
      ++n;
    }
    EXPECT_GT(n, 0) << out;
  }
}

TEST(FmuBinaries, ExportExactlyTheListedFmiFunctions) {
  std::set<std::string> listed;
#define PKM_TEST_NAME(name) listed.insert(#name);
  PKM_FMI2_FUNCTIONS(PKM_TEST_NAME)
  PKM_FMI3_FUNCTIONS(PKM_TEST_NAME)
#undef PKM_TEST_NAME
  for (const char* so : {PKM_FMU_PLANT_SO, PKM_FMU_INVERSE_SO}) {
    int status = 0;
    const std::string out = capture(std::string("nm -D --defined-only '") + so + "' 2>&1", &status);
    if (status != 0) GTEST_SKIP() << "nm not available: " << out;
    std::istringstream lines(out);
    std::string line;
    std::set<std::string> exported;
    while (std::getline(lines, line)) exported.insert(line.substr(line.rfind(' ') + 1));
    EXPECT_EQ(exported, listed) << so;  // fmu_src/fmi/fmi_functions.h: 44 of FMI 2.0, 75 of FMI 3.0
    EXPECT_EQ(exported.size(), 119u);
  }
}


TEST(FmuArchives, FmpyValidatesThem) {
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  for (const char* fmu : {PKM_FMU_PLANT_FMU, PKM_FMU_INVERSE_FMU}) {
    int status = 0;
    const std::string out = capture(std::string("'") + PKM_FMU_PYTHON + "' -m fmpy.cli validate '" + fmu + "' 2>&1",
                                    &status);
    EXPECT_EQ(status, 0) << fmu << "\n" << out;
    EXPECT_NE(out.find("No problems found"), std::string::npos) << fmu << "\n" << out;
  }
}

TEST(FmuArchives, FmpySimulatesTheHomePose) {
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  const std::string script =
      "import fmpy\n"
      "F = 2.655616050\n"
      "r = fmpy.simulate_fmu('" PKM_FMU_PLANT_FMU "', stop_time=0.1, step_size=1e-3,\n"
      "    start_values={'F[1]': F, 'F[2]': F, 'F[3]': F, 'F[4]': F})\n"
      "dev = max(abs(r['x']).max(), abs(r['y']).max(), abs(r['z'] - 0.05).max(), abs(r['phi']).max())\n"
      "i = fmpy.simulate_fmu('" PKM_FMU_INVERSE_FMU "', stop_time=0.01, step_size=1e-3)\n"
      "ferr = max(abs(i['F[%d]' % k] - F).max() for k in range(1, 5))\n"
      "print('RESULT', r['time'][-1], dev, ferr)\n";
  int status = 0;
  const std::string out = pkm_test::run_python(script, &status);
  ASSERT_EQ(status, 0) << out;
  const std::size_t at = out.find("RESULT");
  ASSERT_NE(at, std::string::npos) << out;
  double t_end = 0, dev = 1, ferr = 1;
  ASSERT_EQ(std::sscanf(out.c_str() + at, "RESULT %lf %lf %lf", &t_end, &dev, &ferr), 3) << out;
  EXPECT_NEAR(t_end, 0.1, 1e-12);
  EXPECT_LE(dev, 1e-9);
  EXPECT_LE(ferr, 1e-9);
}
#endif  // PKM_TEST_ON_TARGET

}  // namespace
