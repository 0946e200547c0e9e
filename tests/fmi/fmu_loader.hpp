// SPDX-License-Identifier: BSD-2-Clause
// The built FMU binaries (PKM4PUU.so / .dll, PKM4PUU_Inverse.so / .dll)
// loaded as an importer would (dlopen; LoadLibrary on Windows) and driven
// through the raw FMI 2.0 functions: shared by the tests of tests/fmi/.
// Value references come from the models' variable tables (checked against
// modelDescription.xml by tests/fmi/model_description.cpp). The helpers that run host programs (capture,
// run_python) exist on POSIX only.
#pragma once

#ifdef _WIN32
#ifndef NOMINMAX
#define NOMINMAX
#endif
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#else
#include <dlfcn.h>
#include <unistd.h>
#endif

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmi/fmi_functions.h"
#include "models/models.hpp"

// The instantiation tokens (GUIDs): hashes of the variable tables, as in the
// model descriptions; kept for the program's life, so the pointer never dangles.
inline const char* pkm_test_guid(const pkm_fmi::ModelDefinition& d) {
  static const std::string plant = pkm_fmi::pkm4puu_definition().guid();
  static const std::string inverse = pkm_fmi::pkm4puu_inverse_definition().guid();
  return &d == &pkm_fmi::pkm4puu_definition() ? plant.c_str() : inverse.c_str();
}
#define PKM_FMU_PLANT_GUID (pkm_test_guid(pkm_fmi::pkm4puu_definition()))
#define PKM_FMU_INVERSE_GUID (pkm_test_guid(pkm_fmi::pkm4puu_inverse_definition()))

namespace pkm_test {

constexpr double kStaticForce = 2.655616050;  // docs/model.md "Bodies"
constexpr double kPi = 3.14159265358979323846;

/// `path` as the platform's C library takes it. The build's paths are Linux
/// ones ("/work/..."): under wine, a Windows program reaches them through the
/// Z: drive (wine's view of the Linux root). A native Windows build has
/// drive-letter paths and passes them as they are.
inline std::string native_path(const std::string& path) {
#ifdef _WIN32
  if (!path.empty() && path[0] == '/') return "Z:" + path;
#endif
  return path;
}

/// A shared library opened by path, and its exported symbols.
class SharedLibrary {
 public:
  explicit SharedLibrary(const char* path) {
#ifdef _WIN32
    const std::string p = native_path(path);
    handle_ = LoadLibraryA(p.c_str());
    if (!handle_) error_ = "LoadLibrary(" + p + ") failed: error " + std::to_string(GetLastError());
#else
    handle_ = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle_) error_ = dlerror();
#endif
  }
  ~SharedLibrary() {
#ifdef _WIN32
    if (handle_) FreeLibrary(handle_);
#else
    if (handle_) dlclose(handle_);
#endif
  }
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  bool loaded() const { return handle_ != nullptr; }
#ifndef _WIN32
  void* native() const { return handle_; }
#endif
  const std::string& error() const { return error_; }
  /// The exported function `name` as a pointer of type T*, or null.
  template <class T>
  T* function(const char* name) const {
#ifdef _WIN32
    return reinterpret_cast<T*>(reinterpret_cast<void*>(GetProcAddress(handle_, name)));
#else
    return reinterpret_cast<T*>(dlsym(handle_, name));
#endif
  }

 private:
#ifdef _WIN32
  HMODULE handle_ = nullptr;
#else
  void* handle_ = nullptr;
#endif
  std::string error_;
};

struct FmuLibrary {
  SharedLibrary library;
#ifndef _WIN32
  void* handle = nullptr;  // dlopen's handle, for dlsym of functions not in the list below
#endif
#define PKM_TEST_DECLARE(name) name##TYPE* name = nullptr;
  PKM_FMI2_FUNCTIONS(PKM_TEST_DECLARE)
#undef PKM_TEST_DECLARE
  std::string missing;

  explicit FmuLibrary(const char* path) : library(path) {
    if (!library.loaded()) {
      missing = library.error();
      return;
    }
#ifndef _WIN32
    handle = library.native();
#endif
#define PKM_TEST_LOAD(name)                          \
  name = library.function<name##TYPE>(#name);        \
  if (!name) missing += #name " ";
    PKM_FMI2_FUNCTIONS(PKM_TEST_LOAD)
#undef PKM_TEST_LOAD
  }
  FmuLibrary(const FmuLibrary&) = delete;
  FmuLibrary& operator=(const FmuLibrary&) = delete;
};

/// The FMU binary the tests drive: the build's (`built`), or the file of
/// the same name in the directory PKM_FMU_BINARIES when that is set (the
/// sanitized build's, scripts/check_sanitized_fmi_tests.sh). The tests of
/// the binaries as files (tests/fmi/binary.cpp) keep the build's.
inline std::string fmu_binary(const char* built) {
  const char* dir = std::getenv("PKM_FMU_BINARIES");
  if (dir == nullptr || *dir == '\0') return built;
  const std::string path = built;
  return std::string(dir) + "/" + path.substr(path.find_last_of("/\\") + 1);
}

inline FmuLibrary& plant_library() {
  static FmuLibrary lib(fmu_binary(PKM_FMU_PLANT_SO).c_str());
  return lib;
}
inline FmuLibrary& inverse_library() {
  static FmuLibrary lib(fmu_binary(PKM_FMU_INVERSE_SO).c_str());
  return lib;
}

struct LogMessage {
  fmi2Status status;
  std::string category, text;
};

/// Collects the FMU's log messages (thread-safe: one Log per instance).
struct Log {
  std::vector<LogMessage> messages;
  /// Called with each message once collected, in the thread that logged it
  /// (a test can wait there: the FMU is inside the call that logs).
  std::function<void(const LogMessage&)> on_message;
  bool contains(const std::string& s) const {
    for (const auto& m : messages)
      if (m.text.find(s) != std::string::npos) return true;
    return false;
  }
  std::string last() const { return messages.empty() ? std::string() : messages.back().text; }
  std::string dump() const {
    std::string out;
    for (const auto& m : messages) out += "  [" + m.category + "] " + m.text + "\n";
    return out;
  }
};

/// The importer's logger: formats the message as printf would (the FMU
/// escapes '%'), as fmpy and most masters do.
inline void collect_log(fmi2ComponentEnvironment env, fmi2String, fmi2Status status, fmi2String category,
                        fmi2String message, ...) {
  char text[4096];
  va_list args;
  va_start(args, message);
  std::vsnprintf(text, sizeof text, message ? message : "", args);
  va_end(args);
  Log& log = *static_cast<Log*>(env);
  log.messages.push_back({status, category ? category : "", text});
  if (log.on_message) log.on_message(log.messages.back());
}

inline fmi2ValueReference vr_of(const pkm_fmi::ModelDefinition& d, const std::string& name) {
  const pkm_fmi::Variable* v = d.find(name.c_str());
  if (!v) ADD_FAILURE() << "no variable " << name;
  return v ? v->vr : 0;
}

/// One instance of a dlopen'd FMU.
class FmuInstance {
 public:
  FmuInstance(FmuLibrary& lib, const pkm_fmi::ModelDefinition& def, const char* guid, const char* name = "instance",
              bool logging_on = false, fmi2Type type = fmi2CoSimulation)
      : lib(lib), def(def) {
    functions_ = fmi2CallbackFunctions{&collect_log, &std::calloc, &std::free, nullptr, &log};
    c = lib.fmi2Instantiate(name, type, guid, "file:///nonexistent", &functions_, fmi2False,
                            logging_on ? fmi2True : fmi2False);
  }
  ~FmuInstance() {
    if (c) lib.fmi2FreeInstance(c);
  }
  FmuInstance(const FmuInstance&) = delete;
  FmuInstance& operator=(const FmuInstance&) = delete;

  fmi2ValueReference vr(const std::string& name) const { return vr_of(def, name); }

  fmi2Status set(const std::string& name, double value) {
    const fmi2ValueReference r = vr(name);
    return lib.fmi2SetReal(c, &r, 1, &value);
  }
  fmi2Status set_int(const std::string& name, int value) {
    const fmi2ValueReference r = vr(name);
    const fmi2Integer v = value;
    return lib.fmi2SetInteger(c, &r, 1, &v);
  }
  fmi2Status set_derivative(const std::string& name, double value) {
    const fmi2ValueReference r = vr(name);
    const fmi2Integer order = 1;
    return lib.fmi2SetRealInputDerivatives(c, &r, 1, &order, &value);
  }
  double get(const std::string& name) {
    const fmi2ValueReference r = vr(name);
    double v = std::nan("");
    EXPECT_EQ(lib.fmi2GetReal(c, &r, 1, &v), fmi2OK) << name << "\n" << log.dump();
    return v;
  }
  /// fmi2SetupExperiment from `start`, with a stopTime when `stop` is finite.
  fmi2Status setup(double start = 0.0, double stop = std::numeric_limits<double>::infinity()) {
    const fmi2Boolean stop_defined = std::isfinite(stop) ? fmi2True : fmi2False;
    return lib.fmi2SetupExperiment(c, fmi2False, 0.0, start, stop_defined, stop_defined ? stop : 0.0);
  }
  fmi2Status enter() { return lib.fmi2EnterInitializationMode(c); }
  fmi2Status exit() { return lib.fmi2ExitInitializationMode(c); }
  /// Setup (as setup(start, stop)), initialisation mode, exit.
  void initialize(double start = 0.0, double stop = std::numeric_limits<double>::infinity()) {
    ASSERT_EQ(setup(start, stop), fmi2OK) << log.dump();
    ASSERT_EQ(enter(), fmi2OK) << log.dump();
    ASSERT_EQ(exit(), fmi2OK) << log.dump();
  }
  fmi2Status step(double t, double h) { return lib.fmi2DoStep(c, t, h, fmi2True); }
  /// Value references of every Real variable of a causality.
  std::vector<fmi2ValueReference> reals(pkm_fmi::Causality causality) const {
    std::vector<fmi2ValueReference> v;
    for (std::size_t k = 0; k < def.n_variables; ++k)
      if (def.variables[k].causality == causality && def.variables[k].type == pkm_fmi::VarType::Real)
        v.push_back(def.variables[k].vr);
    return v;
  }
  /// Every Real output, in table order.
  std::vector<double> outputs() {
    const std::vector<fmi2ValueReference> vrs = reals(pkm_fmi::Causality::Output);
    std::vector<double> v(vrs.size(), std::nan(""));
    EXPECT_EQ(lib.fmi2GetReal(c, vrs.data(), vrs.size(), v.data()), fmi2OK) << log.dump();
    return v;
  }
  /// Every Real variable (parameters, inputs, outputs), in table order;
  /// `status` receives the call's status.
  std::vector<double> all_reals(fmi2Status* status = nullptr) {
    std::vector<fmi2ValueReference> vrs;
    for (std::size_t k = 0; k < def.n_variables; ++k)
      if (def.variables[k].type == pkm_fmi::VarType::Real) vrs.push_back(def.variables[k].vr);
    std::vector<double> v(vrs.size(), std::nan(""));
    const fmi2Status s = lib.fmi2GetReal(c, vrs.data(), vrs.size(), v.data());
    if (status) *status = s;
    return v;
  }
  double last_successful_time() {
    double t = std::nan("");
    EXPECT_EQ(lib.fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &t), fmi2OK) << log.dump();
    return t;
  }
  bool terminated() {
    fmi2Boolean b = fmi2False;
    EXPECT_EQ(lib.fmi2GetBooleanStatus(c, fmi2Terminated, &b), fmi2OK) << log.dump();
    return b == fmi2True;
  }

  FmuLibrary& lib;
  const pkm_fmi::ModelDefinition& def;
  fmi2Component c = nullptr;
  Log log;

 private:
  fmi2CallbackFunctions functions_;
};

struct PlantFmu : FmuInstance {
  explicit PlantFmu(const char* name = "plant", bool logging_on = false, fmi2Type type = fmi2CoSimulation)
      : FmuInstance(plant_library(), pkm_fmi::pkm4puu_definition(), PKM_FMU_PLANT_GUID, name, logging_on, type) {}
};

struct InverseFmu : FmuInstance {
  explicit InverseFmu(const char* name = "inverse", bool logging_on = false)
      : FmuInstance(inverse_library(), pkm_fmi::pkm4puu_inverse_definition(), PKM_FMU_INVERSE_GUID, name,
                    logging_on) {}
};

inline bool bit_identical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

inline bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

inline std::string force_name(int i) { return "F[" + std::to_string(i) + "]"; }

#ifndef _WIN32
/// Runs a command, returns its output (stdout and stderr).
inline std::string capture(const std::string& command, int* status = nullptr) {
  std::string out;
  FILE* f = popen(command.c_str(), "r");
  if (!f) return out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, f)) out += buf;
  const int st = pclose(f);
  if (status) *status = st;
  return out;
}

/// The lines `tool` prints about the shared library `so` (`tool 'so' 2>&1`);
/// false, with the tool's whole output in *out, when it did not run.
inline bool tool_lines(const std::string& tool, const char* so, std::vector<std::string>& lines, std::string* out) {
  int status = 0;
  *out = capture(tool + " '" + so + "' 2>&1", &status);
  std::istringstream text(*out);
  lines.clear();
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  return status == 0;
}

inline bool have_fmpy() {
  const std::string python = PKM_FMU_PYTHON;
  if (python.empty()) return false;
  int status = 0;
  capture("'" + python + "' -c 'import fmpy' 2>&1", &status);
  return status == 0;
}

/// Runs a Python script with PKM_FMU_PYTHON (through a temporary file) and
/// returns its output (stdout and stderr); *status is the exit status.
inline std::string run_python(const std::string& script, int* status) {
  char path[] = "/tmp/pkm_test_python_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) {
    *status = -1;
    return "mkstemp failed";
  }
  const bool written = write(fd, script.data(), script.size()) == static_cast<ssize_t>(script.size());
  close(fd);
  std::string out = written ? capture(std::string("'") + PKM_FMU_PYTHON + "' " + path + " 2>&1", status)
                            : "cannot write the script";
  if (!written) *status = -1;
  unlink(path);
  return out;
}
#endif  // _WIN32

}  // namespace pkm_test
