// SPDX-License-Identifier: BSD-2-Clause
// One instance of either FMU through either FMI version and interface, for
// the tests that walk the standards' state tables (state_table.cpp) and the
// tunable parameters (payload.cpp): the FMI 3.0 functions found with dlsym
// beside fmu_loader.hpp's FMI 2.0 ones.
#pragma once

#include <dlfcn.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fmi/instance.hpp"
#include "fmi3FunctionTypes.h"
#include "fmu_fixture.hpp"

namespace pkm_test {

/// The FMI 3.0 functions of a library (dlsym).
struct Fmi3 {
#define PKM_DECLARE3(name) name##TYPE* name = nullptr;
  PKM_FMI3_FUNCTIONS(PKM_DECLARE3)
#undef PKM_DECLARE3
  explicit Fmi3(FmuLibrary& lib) {
#define PKM_LOAD3(name) name = reinterpret_cast<name##TYPE*>(dlsym(lib.handle, #name));
    PKM_FMI3_FUNCTIONS(PKM_LOAD3)
#undef PKM_LOAD3
  }
};

/// The FMI 3.0 functions of the plant's library, or of `lib`'s.
inline Fmi3& fmi3(FmuLibrary& lib = plant_library()) {
  static Fmi3 plant(plant_library()), inverse(inverse_library());
  return &lib == &inverse_library() ? inverse : plant;
}

inline void collect3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
  static_cast<Log*>(env)->messages.push_back(
      {static_cast<fmi2Status>(status), category ? category : "", message ? message : ""});
}

/// One instance of the plant (or, with `inverse`, of the inverse FMU)
/// through either FMI version; statuses as int (fmi2OK = fmi3OK = 0, ...).
struct Any {
  int version;
  bool me;
  const pkm_fmi::ModelDefinition& def;
  FmuLibrary& lib;
  Fmi3& f3;
  void* c = nullptr;
  Log log;
  fmi2CallbackFunctions functions{&collect_log, &std::calloc, &std::free, nullptr, &log};

  Any(int v, bool model_exchange, bool logging_on = true, bool inverse = false)
      : version(v),
        me(model_exchange),
        def(inverse ? pkm_fmi::pkm4puu_inverse_definition() : pkm_fmi::pkm4puu_definition()),
        lib(inverse ? inverse_library() : plant_library()),
        f3(fmi3(lib)) {
    const std::string token = def.guid();  // alive through the calls below
    const char* guid = token.c_str();
    if (v == 2) {
      c = lib.fmi2Instantiate("table", me ? fmi2ModelExchange : fmi2CoSimulation, guid, "", &functions, fmi2False,
                              logging_on ? fmi2True : fmi2False);
    } else if (me) {
      c = f3.fmi3InstantiateModelExchange("table", guid, nullptr, fmi3False, logging_on, &log, &collect3);
    } else {
      c = f3.fmi3InstantiateCoSimulation("table", guid, nullptr, fmi3False, logging_on, fmi3False, fmi3False,
                                         nullptr, 0, &log, &collect3, nullptr);
    }
  }
  ~Any() {
    if (!c) return;
    if (version == 2) {
      lib.fmi2FreeInstance(c);
    } else {
      f3.fmi3FreeInstance(c);
    }
  }
  Any(const Any&) = delete;
  Any& operator=(const Any&) = delete;

  std::uint32_t vr(const char* name) const { return vr_of(def, name); }
  int enter(double start = 0.0, double stop = NAN) {
    const bool stop_defined = std::isfinite(stop);
    if (version == 2) {
      const int s = lib.fmi2SetupExperiment(c, fmi2False, 0.0, start, stop_defined, stop_defined ? stop : 0.0);
      return s != fmi2OK ? s : lib.fmi2EnterInitializationMode(c);
    }
    return f3.fmi3EnterInitializationMode(c, fmi3False, 0.0, start, stop_defined, stop_defined ? stop : 0.0);
  }
  int exit() { return version == 2 ? +lib.fmi2ExitInitializationMode(c) : +f3.fmi3ExitInitializationMode(c); }
  int continuous() { return version == 2 ? +lib.fmi2EnterContinuousTimeMode(c) : +f3.fmi3EnterContinuousTimeMode(c); }
  int event() { return version == 2 ? +lib.fmi2EnterEventMode(c) : +f3.fmi3EnterEventMode(c); }
  int terminate() { return version == 2 ? +lib.fmi2Terminate(c) : +f3.fmi3Terminate(c); }
  int set_time(double t) { return version == 2 ? +lib.fmi2SetTime(c, t) : +f3.fmi3SetTime(c, t); }
  int completed() {
    if (version == 2) {
      fmi2Boolean a = fmi2False, b = fmi2False;
      return lib.fmi2CompletedIntegratorStep(c, fmi2True, &a, &b);
    }
    fmi3Boolean a = fmi3False, b = fmi3False;
    return f3.fmi3CompletedIntegratorStep(c, fmi3True, &a, &b);
  }
  int step(double t, double h) {
    if (version == 2) return lib.fmi2DoStep(c, t, h, fmi2True);
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    double last = NAN;
    return f3.fmi3DoStep(c, t, h, fmi3True, &event, &terminate, &early, &last);
  }
  /// fmi2NewDiscreteStates / fmi3UpdateDiscreteStates; *states_changed:
  /// valuesOfContinuousStatesChanged.
  int update(bool* states_changed = nullptr) {
    bool changed = false;
    int s;
    if (version == 2) {
      fmi2EventInfo info{};
      s = lib.fmi2NewDiscreteStates(c, &info);
      changed = info.valuesOfContinuousStatesChanged == fmi2True;
    } else {
      fmi3Boolean b[5] = {};
      double next = 0.0;
      s = f3.fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &next);
      changed = b[3] == fmi3True;  // valuesOfContinuousStatesChanged
    }
    if (states_changed) *states_changed = changed;
    return s;
  }
  int set(const char* name, double x) {
    const std::uint32_t r = vr(name);
    return version == 2 ? +lib.fmi2SetReal(c, &r, 1, &x) : +f3.fmi3SetFloat64(c, &r, 1, &x, 1);
  }
  int get(const char* name, double& x) {
    const std::uint32_t r = vr(name);
    return version == 2 ? +lib.fmi2GetReal(c, &r, 1, &x) : +f3.fmi3GetFloat64(c, &r, 1, &x, 1);
  }
  /// get(name) with its status expected OK.
  double value(const char* name) {
    double x = NAN;
    EXPECT_EQ(get(name, x), fmi2OK) << name << "\n" << log.dump();
    return x;
  }
  std::vector<double> states() {
    std::vector<double> x(def.n_states, NAN);
    EXPECT_EQ(version == 2 ? +lib.fmi2GetContinuousStates(c, x.data(), x.size())
                           : +f3.fmi3GetContinuousStates(c, x.data(), x.size()),
              fmi2OK)
        << log.dump();
    return x;
  }
  std::vector<double> derivatives() {
    std::vector<double> dx(def.n_states, NAN);
    EXPECT_EQ(version == 2 ? +lib.fmi2GetDerivatives(c, dx.data(), dx.size())
                           : +f3.fmi3GetContinuousStateDerivatives(c, dx.data(), dx.size()),
              fmi2OK)
        << log.dump();
    return dx;
  }
  std::vector<double> reals(int* status = nullptr) {
    std::vector<std::uint32_t> vrs;
    for (std::size_t k = 0; k < def.n_variables; ++k)
      if (def.variables[k].type == pkm_fmi::VarType::Real) vrs.push_back(def.variables[k].vr);
    std::vector<double> v(vrs.size(), NAN);
    const int s = version == 2 ? +lib.fmi2GetReal(c, vrs.data(), vrs.size(), v.data())
                               : +f3.fmi3GetFloat64(c, vrs.data(), vrs.size(), v.data(), v.size());
    if (status) *status = s;
    return v;
  }
  /// The last message names a refusal by the state table.
  bool refused(int status) const {
    return status == fmi2Error && !log.messages.empty() && log.last().find("not allowed") != std::string::npos;
  }
};

// The states an instance of a version and interface can be brought to.
struct Reach {
  std::uint32_t state;
  const char* name;
};

inline std::vector<Reach> states_of(int version, bool me) {
  std::vector<Reach> s = {{pkm_fmi::kInstantiated, "Instantiated"}, {pkm_fmi::kInitializationMode, "Initialization"}};
  if (me) {
    s.push_back({pkm_fmi::kEventMode, "EventMode"});
    s.push_back({pkm_fmi::kContinuousTimeMode, "ContinuousTimeMode"});
  } else {
    s.push_back({pkm_fmi::kStepMode, "StepMode"});
    if (version == 2) s.push_back({pkm_fmi::kStepFailed, "StepFailed"});
  }
  s.push_back({pkm_fmi::kTerminated, "Terminated"});
  return s;
}

/// Brings an instance from Instantiated to `state` (StepFailed: the plant only).
inline void bring_to(Any& a, std::uint32_t state) {
  if (state == pkm_fmi::kInstantiated) return;
  ASSERT_EQ(a.enter(), fmi2OK) << a.log.dump();
  if (state == pkm_fmi::kInitializationMode) return;
  ASSERT_EQ(a.exit(), fmi2OK) << a.log.dump();
  if (state == pkm_fmi::kContinuousTimeMode) {
    ASSERT_EQ(a.continuous(), fmi2OK) << a.log.dump();
  }
  if (state == pkm_fmi::kStepFailed) {
    ASSERT_EQ(a.set("F[3]", 1e300), fmi2OK);
    ASSERT_EQ(a.step(0.0, 1e-3), fmi2Discard) << a.log.dump();
  }
  if (state == pkm_fmi::kTerminated) {
    ASSERT_EQ(a.terminate(), fmi2OK) << a.log.dump();
  }
}

}  // namespace pkm_test
