// SPDX-License-Identifier: BSD-2-Clause
// A small co-simulation master for valgrind memcheck (ctest
// hardening_valgrind): the paper's full 2-s auto-test through the built
// FMUs, as python/pkm4puu/autotest.py does it -- PKM4PUU_Inverse.so turns
// the prescribed motion into F1..F4 at each 1-ms step's midpoint,
// PKM4PUU.so is driven by them open loop -- with RK4 and with CVODE; plus
// the paths an importer may take around it: FMU states (get, set,
// serialise, deserialise, and some left for fmi2FreeInstance to free), a
// step discarded at a singularity, an initialisation that fails and
// fmi2Reset, logging. Exits 1 if the plant does not follow the path
// (5e-8 m / 5e-8 rad) or anything else goes wrong; valgrind's
// --error-exitcode makes any invalid access or definite leak fail too.
#include <dlfcn.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fmi2FunctionTypes.h"
#include "models/models.hpp"
#include "apps/trajectory.hpp"

namespace {

struct Fmu {
  void* handle = nullptr;
#define PKM_VG_FUNCTIONS(X)                                                                                      \
  X(fmi2Instantiate) X(fmi2FreeInstance) X(fmi2SetupExperiment) X(fmi2EnterInitializationMode)                   \
  X(fmi2ExitInitializationMode) X(fmi2Terminate) X(fmi2Reset) X(fmi2GetReal) X(fmi2SetReal) X(fmi2SetInteger)    \
  X(fmi2DoStep) X(fmi2GetFMUstate) X(fmi2SetFMUstate) X(fmi2FreeFMUstate) X(fmi2SerializedFMUstateSize)           \
  X(fmi2SerializeFMUstate) X(fmi2DeSerializeFMUstate) X(fmi2GetRealStatus) X(fmi2GetBooleanStatus)              \
  X(fmi2SetDebugLogging)
#define PKM_VG_DECLARE(name) name##TYPE* name = nullptr;
  PKM_VG_FUNCTIONS(PKM_VG_DECLARE)
#undef PKM_VG_DECLARE
  explicit Fmu(const char* path) {
    handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      std::fprintf(stderr, "dlopen %s: %s\n", path, dlerror());
      std::exit(1);
    }
#define PKM_VG_LOAD(name)                                           \
  name = reinterpret_cast<name##TYPE*>(dlsym(handle, #name));       \
  if (!name) {                                                      \
    std::fprintf(stderr, "%s: no %s\n", path, #name);               \
    std::exit(1);                                                   \
  }
    PKM_VG_FUNCTIONS(PKM_VG_LOAD)
#undef PKM_VG_LOAD
  }
  ~Fmu() { dlclose(handle); }
};

int g_messages = 0;
void logger(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String message, ...) {
  char buf[1024];
  va_list args;
  va_start(args, message);
  std::vsnprintf(buf, sizeof buf, message, args);
  va_end(args);
  ++g_messages;
}
const fmi2CallbackFunctions kCallbacks{&logger, &std::calloc, &std::free, nullptr, nullptr};

bool g_failed = false;
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "FAILED: %s\n", what);
    g_failed = true;
  }
}

fmi2ValueReference vr(const pkm_fmi::ModelDefinition& d, const std::string& name) {
  const pkm_fmi::Variable* v = d.find(name.c_str());
  if (!v) {
    std::fprintf(stderr, "no variable %s\n", name.c_str());
    std::exit(1);
  }
  return v->vr;
}

fmi2Component instantiate(Fmu& f, const pkm_fmi::ModelDefinition& d, const char* name) {
  fmi2Component c = f.fmi2Instantiate(name, fmi2CoSimulation, d.guid().c_str(), "file:///tmp", &kCallbacks, fmi2False, fmi2False);
  check(c != nullptr, "fmi2Instantiate");
  if (!c) std::exit(1);
  return c;
}

void initialize(Fmu& f, fmi2Component c) {
  check(f.fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2True, 2.0) == fmi2OK, "setup");
  check(f.fmi2EnterInitializationMode(c) == fmi2OK, "enter");
  check(f.fmi2ExitInitializationMode(c) == fmi2OK, "exit");
}

/// The 2-s auto-test through both FMUs; returns the largest position and angle errors.
void autotest(Fmu& plant_so, Fmu& inverse_so, int solver, double& max_pos, double& max_ang) {
  const pkm_fmi::ModelDefinition& pd = pkm_fmi::pkm4puu_definition();
  const pkm_fmi::ModelDefinition& id = pkm_fmi::pkm4puu_inverse_definition();
  fmi2Component plant = instantiate(plant_so, pd, "plant");
  fmi2Component inv = instantiate(inverse_so, id, "inverse");
  const fmi2ValueReference solver_vr = vr(pd, "solver");
  const fmi2Integer solver_value = solver;
  check(plant_so.fmi2SetInteger(plant, &solver_vr, 1, &solver_value) == fmi2OK, "solver");
  initialize(plant_so, plant);
  initialize(inverse_so, inv);
  fmi2ValueReference motion[12], forces_out[4], forces_in[4], pose[4];
  const char* names[12] = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"};
  for (int k = 0; k < 12; ++k) motion[k] = vr(id, names[k]);
  for (int i = 0; i < 4; ++i) {
    forces_out[i] = vr(id, "F[" + std::to_string(i + 1) + "]");
    forces_in[i] = vr(pd, "F[" + std::to_string(i + 1) + "]");
    pose[i] = vr(pd, names[i]);
  }
  const pkm::RestToRest path;
  const double h = 1e-3;
  max_pos = max_ang = 0.0;
  fmi2FMUstate keep = nullptr, left = nullptr;
  std::vector<fmi2Byte> bytes;
  for (int k = 0; k < 2000; ++k) {
    const double t = k * h;
    pkm::Pose p, pd_, pdd;
    path.eval(t + 0.5 * h, p, pd_, pdd);  // forces held at the step's midpoint value
    double m[12], F[4];
    for (int j = 0; j < 4; ++j) {
      m[j] = p[j];
      m[4 + j] = pd_[j];
      m[8 + j] = pdd[j];
    }
    check(inverse_so.fmi2SetReal(inv, motion, 12, m) == fmi2OK, "inverse inputs");
    check(inverse_so.fmi2GetReal(inv, forces_out, 4, F) == fmi2OK, "inverse outputs");
    check(inverse_so.fmi2DoStep(inv, t, h, fmi2True) == fmi2OK, "inverse step");
    check(plant_so.fmi2SetReal(plant, forces_in, 4, F) == fmi2OK, "plant inputs");
    if (k == 1000) {
      // An FMU state in the middle: saved, serialised, deserialised, restored (no change).
      check(plant_so.fmi2GetFMUstate(plant, &keep) == fmi2OK, "get state");
      std::size_t size = 0;
      check(plant_so.fmi2SerializedFMUstateSize(plant, keep, &size) == fmi2OK, "state size");
      bytes.resize(size);
      check(plant_so.fmi2SerializeFMUstate(plant, keep, bytes.data(), size) == fmi2OK, "serialise");
      fmi2FMUstate copy = nullptr;
      check(plant_so.fmi2DeSerializeFMUstate(plant, bytes.data(), size, &copy) == fmi2OK, "deserialise");
      check(plant_so.fmi2SetFMUstate(plant, copy) == fmi2OK, "set state");
      check(plant_so.fmi2FreeFMUstate(plant, &copy) == fmi2OK, "free state");
      check(plant_so.fmi2GetFMUstate(plant, &left) == fmi2OK, "a state left for fmi2FreeInstance");
    }
    check(plant_so.fmi2DoStep(plant, t, h, fmi2True) == fmi2OK, "plant step");
    double y[4];
    check(plant_so.fmi2GetReal(plant, pose, 4, y) == fmi2OK, "plant outputs");
    path.eval(t + h, p, pd_, pdd);
    for (int j = 0; j < 3; ++j) max_pos = std::max(max_pos, std::fabs(y[j] - p[j]));
    max_ang = std::max(max_ang, std::fabs(y[3] - p[3]));
  }
  // Every Real of the plant once more, and the end of the run.
  std::vector<fmi2ValueReference> all;
  for (std::size_t k = 0; k < pd.n_variables; ++k)
    if (pd.variables[k].type == pkm_fmi::VarType::Real) all.push_back(pd.variables[k].vr);
  std::vector<double> values(all.size());
  check(plant_so.fmi2GetReal(plant, all.data(), all.size(), values.data()) == fmi2OK, "all reals");
  for (double v : values) check(std::isfinite(v), "finite outputs");
  check(plant_so.fmi2Terminate(plant) == fmi2OK, "terminate");
  check(inverse_so.fmi2Terminate(inv) == fmi2OK, "terminate inverse");
  check(plant_so.fmi2FreeFMUstate(plant, &keep) == fmi2OK, "free kept state");
  plant_so.fmi2FreeInstance(plant);  // also frees `left`
  inverse_so.fmi2FreeInstance(inv);
}

/// A step discarded at a leg singularity, then a failed initialisation and a reset.
void failure_paths(Fmu& plant_so) {
  const pkm_fmi::ModelDefinition& pd = pkm_fmi::pkm4puu_definition();
  fmi2Component c = instantiate(plant_so, pd, "failing");
  const fmi2String all[1] = {"logCalls"};
  check(plant_so.fmi2SetDebugLogging(c, fmi2True, 1, all) == fmi2OK, "logging");
  initialize(plant_so, c);
  fmi2ValueReference F[4];
  for (int i = 0; i < 4; ++i) F[i] = vr(pd, "F[" + std::to_string(i + 1) + "]");
  const double push[4] = {2.655616050 + 1.0, 2.655616050, 2.655616050 - 1.0, 2.655616050};
  check(plant_so.fmi2SetReal(c, F, 4, push) == fmi2OK, "push");
  fmi2Status s = fmi2OK;
  double t = 0.0;
  for (int k = 0; k < 1000 && s == fmi2OK; ++k) {
    s = plant_so.fmi2DoStep(c, t, 1e-3, fmi2True);
    if (s == fmi2OK) t += 1e-3;
  }
  check(s == fmi2Discard, "discard at the singularity");
  fmi2Boolean terminated = fmi2False;
  double last = -1.0;
  check(plant_so.fmi2GetBooleanStatus(c, fmi2Terminated, &terminated) == fmi2OK && terminated == fmi2True,
        "terminated");
  check(plant_so.fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &last) == fmi2OK && last == t, "last time");
  check(plant_so.fmi2Reset(c) == fmi2OK, "reset");
  const fmi2ValueReference l = vr(pd, "l");
  const double bad = 1e-3;  // within the model description's range, refused at initialisation (no leg reaches the home pose)
  check(plant_so.fmi2SetReal(c, &l, 1, &bad) == fmi2OK, "bad l");
  check(plant_so.fmi2SetupExperiment(c, fmi2False, 0, 0, fmi2False, 0) == fmi2OK, "setup");
  check(plant_so.fmi2EnterInitializationMode(c) == fmi2OK, "enter");
  check(plant_so.fmi2ExitInitializationMode(c) == fmi2Error, "bad l refused");
  check(plant_so.fmi2Reset(c) == fmi2OK, "reset after error");
  initialize(plant_so, c);
  check(plant_so.fmi2DoStep(c, 0.0, 1e-3, fmi2True) == fmi2OK, "step after reset");
  fmi2FMUstate s1 = nullptr;
  check(plant_so.fmi2GetFMUstate(c, &s1) == fmi2OK, "a state left behind");
  plant_so.fmi2FreeInstance(c);
}

}  // namespace

int main() {
  Fmu plant(PKM_FMU_PLANT_SO), inverse(PKM_FMU_INVERSE_SO);
  for (int solver : {1, 0}) {
    double pos = 1, ang = 1;
    autotest(plant, inverse, solver, pos, ang);
    std::printf("auto-test through the FMUs, %s: max position error %.2e m, max angle error %.2e rad\n",
                solver == 1 ? "RK4  " : "CVODE", pos, ang);
    check(pos <= 5e-8 && ang <= 5e-8, "the plant follows the prescribed path");
  }
  failure_paths(plant);
  std::printf("%d log messages; %s\n", g_messages, g_failed ? "FAILED" : "ok");
  return g_failed ? 1 : 0;
}
