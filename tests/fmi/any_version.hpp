// SPDX-License-Identifier: BSD-2-Clause
// One instance of the plant FMU (or of the inverse FMU) through either FMI
// version and interface (FMI 2.0 through fmu_loader.hpp's functions, FMI 3.0
// looked up by name in the same library), with the calls the state-table,
// FMU-state and payload tests make of both versions alike.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <vector>

#include "fmi3FunctionTypes.h"
#include "fmu_fixture.hpp"

namespace pkm_test {

/// The FMI 3.0 functions of a library.
struct Fmi3 {
#define PKM_DECLARE3(name) name##TYPE* name = nullptr;
  PKM_FMI3_FUNCTIONS(PKM_DECLARE3)
#undef PKM_DECLARE3
  explicit Fmi3(FmuLibrary& lib) {
#define PKM_LOAD3(name) name = lib.library.function<name##TYPE>(#name);
    PKM_FMI3_FUNCTIONS(PKM_LOAD3)
#undef PKM_LOAD3
  }
};

/// The FMI 3.0 functions of the plant's library, or of the inverse FMU's.
inline Fmi3& fmi3(FmuLibrary& lib = plant_library()) {
  if (&lib == &plant_library()) {
    static Fmi3 plant(lib);
    return plant;
  }
  static Fmi3 inverse(inverse_library());
  return inverse;
}

inline void collect3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
  static_cast<Log*>(env)->messages.push_back(
      {static_cast<fmi2Status>(status), category ? category : "", message ? message : ""});
}

inline const pkm_fmi::ModelDefinition& plant() { return pkm_fmi::pkm4puu_definition(); }
inline std::uint32_t vr(const char* name) { return vr_of(plant(), name); }

/// One instance of the plant (`inverse`: of the inverse FMU) through either
/// FMI version. The statuses of both versions share their values (fmi2OK ==
/// fmi3OK, ..., Error = 3).
struct Any {
  int version;
  bool me;
  void* c = nullptr;
  Log log;
  fmi2CallbackFunctions functions{&collect_log, &std::calloc, &std::free, nullptr, &log};
  const pkm_fmi::ModelDefinition& def;
  FmuLibrary& lib;

  Any(int v, bool model_exchange, bool logging_on = true, bool inverse = false)
      : version(v),
        me(model_exchange),
        def(inverse ? pkm_fmi::pkm4puu_inverse_definition() : plant()),
        lib(inverse ? inverse_library() : plant_library()) {
    const std::string token = def.guid();  // alive through the calls below
    const char* guid = token.c_str();
    if (v == 2) {
      c = lib.fmi2Instantiate("table", me ? fmi2ModelExchange : fmi2CoSimulation, guid, "", &functions, fmi2False,
                              logging_on ? fmi2True : fmi2False);
    } else if (me) {
      c = fmi3(lib).fmi3InstantiateModelExchange("table", guid, nullptr, fmi3False, logging_on, &log, &collect3);
    } else {
      c = fmi3(lib).fmi3InstantiateCoSimulation("table", guid, nullptr, fmi3False, logging_on, fmi3False, fmi3False,
                                             nullptr, 0, &log, &collect3, nullptr);
    }
  }
  ~Any() {
    if (!c) return;
    if (version == 2) {
      lib.fmi2FreeInstance(c);
    } else {
      fmi3(lib).fmi3FreeInstance(c);
    }
  }
  Any(const Any&) = delete;
  Any& operator=(const Any&) = delete;

  int enter(double start = 0.0, double stop = NAN) {
    const bool stop_defined = std::isfinite(stop);
    if (version == 2) {
      const int s = lib.fmi2SetupExperiment(c, fmi2False, 0.0, start, stop_defined, stop_defined ? stop : 0.0);
      return s != fmi2OK ? s : lib.fmi2EnterInitializationMode(c);
    }
    return fmi3(lib).fmi3EnterInitializationMode(c, fmi3False, 0.0, start, stop_defined, stop_defined ? stop : 0.0);
  }
  int exit() { return version == 2 ? +lib.fmi2ExitInitializationMode(c) : +fmi3(lib).fmi3ExitInitializationMode(c); }
  int continuous() {
    return version == 2 ? +lib.fmi2EnterContinuousTimeMode(c) : +fmi3(lib).fmi3EnterContinuousTimeMode(c);
  }
  int event() { return version == 2 ? +lib.fmi2EnterEventMode(c) : +fmi3(lib).fmi3EnterEventMode(c); }
  int terminate() { return version == 2 ? +lib.fmi2Terminate(c) : +fmi3(lib).fmi3Terminate(c); }
  int set_time(double t) { return version == 2 ? +lib.fmi2SetTime(c, t) : +fmi3(lib).fmi3SetTime(c, t); }
  int completed() {
    if (version == 2) {
      fmi2Boolean a = fmi2False, b = fmi2False;
      return lib.fmi2CompletedIntegratorStep(c, fmi2True, &a, &b);
    }
    fmi3Boolean a = fmi3False, b = fmi3False;
    return fmi3(lib).fmi3CompletedIntegratorStep(c, fmi3True, &a, &b);
  }
  int step(double t, double h) {
    if (version == 2) return lib.fmi2DoStep(c, t, h, fmi2True);
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    double last = NAN;
    return fmi3(lib).fmi3DoStep(c, t, h, fmi3True, &event, &terminate, &early, &last);
  }
  std::uint32_t vr(const char* name) const { return vr_of(def, name); }
  int set(const char* name, double x) {
    const std::uint32_t r = vr(name);
    return version == 2 ? +lib.fmi2SetReal(c, &r, 1, &x) : +fmi3(lib).fmi3SetFloat64(c, &r, 1, &x, 1);
  }
  int set_int(const char* name, int x) {
    const std::uint32_t r = vr(name);
    const std::int32_t v = x;
    return version == 2 ? +lib.fmi2SetInteger(c, &r, 1, &v) : +fmi3(lib).fmi3SetInt32(c, &r, 1, &v, 1);
  }
  int get(const char* name, double& x) {
    const std::uint32_t r = vr(name);
    return version == 2 ? +lib.fmi2GetReal(c, &r, 1, &x) : +fmi3(lib).fmi3GetFloat64(c, &r, 1, &x, 1);
  }
  std::vector<double> reals(int* status = nullptr) {
    std::vector<std::uint32_t> vrs;
    for (std::size_t k = 0; k < def.n_variables; ++k)
      if (def.variables[k].type == pkm_fmi::VarType::Real) vrs.push_back(def.variables[k].vr);
    std::vector<double> v(vrs.size(), NAN);
    const int s = version == 2 ? +lib.fmi2GetReal(c, vrs.data(), vrs.size(), v.data())
                               : +fmi3(lib).fmi3GetFloat64(c, vrs.data(), vrs.size(), v.data(), v.size());
    if (status) *status = s;
    return v;
  }
  /// get(name), expected OK.
  double value(const char* name) {
    double x = NAN;
    EXPECT_EQ(get(name, x), fmi2OK) << name << "\n" << log.dump();
    return x;
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
      s = fmi3(lib).fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &next);
      changed = b[3] == fmi3True;  // valuesOfContinuousStatesChanged
    }
    if (states_changed) *states_changed = changed;
    return s;
  }
  /// The continuous states, or (`derivatives`) their derivatives (Model
  /// Exchange), expected OK.
  std::vector<double> states(bool derivatives = false) {
    std::vector<double> x(def.n_states, NAN);
    Fmi3& f = fmi3(lib);
    const int s = version == 2 ? (derivatives ? +lib.fmi2GetDerivatives(c, x.data(), x.size())
                                              : +lib.fmi2GetContinuousStates(c, x.data(), x.size()))
                               : (derivatives ? +f.fmi3GetContinuousStateDerivatives(c, x.data(), x.size())
                                              : +f.fmi3GetContinuousStates(c, x.data(), x.size()));
    EXPECT_EQ(s, fmi2OK) << log.dump();
    return x;
  }
  std::vector<double> derivatives() { return states(true); }
  /// The last message names a refusal by the state table.
  bool refused(int status) const {
    return status == fmi2Error && !log.messages.empty() && log.last().find("not allowed") != std::string::npos;
  }

  // ---- FMU states
  int get_state(void** s) { return version == 2 ? +lib.fmi2GetFMUstate(c, s) : +fmi3(lib).fmi3GetFMUState(c, s); }
  int set_state(void* s) { return version == 2 ? +lib.fmi2SetFMUstate(c, s) : +fmi3(lib).fmi3SetFMUState(c, s); }
  int free_state(void** s) { return version == 2 ? +lib.fmi2FreeFMUstate(c, s) : +fmi3(lib).fmi3FreeFMUState(c, s); }
  /// The state `s` serialised (empty on failure).
  std::vector<unsigned char> serialize(void* s) {
    std::size_t size = 0;
    const int got = version == 2 ? +lib.fmi2SerializedFMUstateSize(c, s, &size)
                                 : +fmi3(lib).fmi3SerializedFMUStateSize(c, s, &size);
    if (got != fmi2OK) return {};
    std::vector<unsigned char> bytes(size);
    const int put = version == 2 ? +lib.fmi2SerializeFMUstate(c, s, reinterpret_cast<fmi2Byte*>(bytes.data()), size)
                                 : +fmi3(lib).fmi3SerializeFMUState(c, s, bytes.data(), size);
    return put == fmi2OK ? bytes : std::vector<unsigned char>{};
  }
  /// The current state, serialised.
  std::vector<unsigned char> serialized_state() {
    void* s = nullptr;
    if (get_state(&s) != fmi2OK) return {};
    std::vector<unsigned char> bytes = serialize(s);
    free_state(&s);
    return bytes;
  }
  int deserialize(const std::vector<unsigned char>& bytes, void** s) {
    return version == 2 ? +lib.fmi2DeSerializeFMUstate(c, reinterpret_cast<const fmi2Byte*>(bytes.data()),
                                                        bytes.size(), s)
                        : +fmi3(lib).fmi3DeserializeFMUState(c, bytes.data(), bytes.size(), s);
  }
  /// DeserializeFMUState, then SetFMUState, then FreeFMUState: the status
  /// of the first that failed (or of SetFMUState).
  int restore(const std::vector<unsigned char>& bytes) {
    void* s = nullptr;
    const int d = deserialize(bytes, &s);
    if (d != fmi2OK) return d;
    const int r = set_state(s);
    free_state(&s);
    return r;
  }
};

/// Takes each instance through initialisation mode at its defaults (call
/// it in ASSERT_NO_FATAL_FAILURE).
inline void initialise(std::initializer_list<Any*> instances) {
  for (Any* x : instances) {
    ASSERT_EQ(x->enter(), fmi2OK);
    ASSERT_EQ(x->exit(), fmi2OK);
  }
}

}  // namespace pkm_test
