// SPDX-License-Identifier: BSD-2-Clause
// Coverage-guided fuzzing (libFuzzer, under AddressSanitizer and
// UndefinedBehaviorSanitizer) of the FMI 2.0 and 3.0 layers: random sequences
// of FMI calls with random arguments on up to three instances of the two FMUs,
// linked in-process (the same sources as PKM4PUU.so and PKM4PUU_Inverse.so;
// the exported functions are compiled twice, once per model, with the
// prefixes PKM4PUU_ and PKM4PUU_Inverse_).
//
// Each input is decoded (FuzzedDataProvider) into at most kMaxOps operations:
// any FMI function, in any state, with value references from the model's
// table or arbitrary ones, values from a list of awkward numbers (NaN, +-Inf,
// 0, -0, denormals, 1e300, DBL_MAX, ...) or raw bytes, NULL pointers,
// foreign pointers, FMU states (saved, freed, serialised, corrupted, forged
// with the checksum recomputed, taken to another instance), and two macro operations that bring an instance
// into its stepping state and run it, so that deep states are reached fast.
//
// Besides the sanitizers, the harness checks the FMU's promises (a
// violation aborts, i.e. is a finding):
//   - no fmi2GetReal that returns fmi2OK or fmi2Warning hands out NaN or Inf;
//   - nothing is written outside the buffers the FMU was given (guard zones);
//   - after fmi2Discard: fmi2GetBooleanStatus(fmi2Terminated) is fmi2True and
//     fmi2GetRealStatus(fmi2LastSuccessfulTime) lies in [t, t + h];
//   - the logger receives a message that is safe as a printf format.
// An input that starts with the four bytes "FMI3" drives the FMI 3.0 front
// end instead (the rest decoded the same way: Co-Simulation and Model
// Exchange instances, the Model Exchange calls with an importer's explicit
// Euler loop among them, states set by value reference too); any other
// input, the FMI 2.0 one, decoded as before (the seed corpus keeps its
// meaning). FMI 3.0's checks: no fmi3GetFloat64 (nor state, derivative,
// indicator, nominal or directional-derivative array) that answers fmi3OK,
// fmi3Warning or fmi3Discard hands out NaN or Inf where the FMU promises
// finite values, nothing is written outside the given buffers, a failed get
// writes nothing, the logger gets non-NULL strings, fmi3DoStep's
// lastSuccessfulTime is finite.
// At exit it prints how many FMI calls were made (PKM_FUZZ_CALLS=...).
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"
#include "fmi/fmi_functions.h"
#include "fmi/fnv1a.hpp"
#include "models/PKM4PUU/plant_state.hpp"
#include "models/models.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

// The two in-process FMUs' exported FMI 2.0 functions: fmi_functions.h.
#define PKM_FUZZ_FMI2_FUNCTIONS PKM_FMI2_FUNCTIONS

extern "C" {
#define PKM_FUZZ_DECLARE(name) name##TYPE PKM4PUU_##name; name##TYPE PKM4PUU_Inverse_##name;
PKM_FUZZ_FMI2_FUNCTIONS(PKM_FUZZ_DECLARE)
PKM_FMI3_FUNCTIONS(PKM_FUZZ_DECLARE)
#undef PKM_FUZZ_DECLARE
}

namespace {

struct Api {
#define PKM_FUZZ_MEMBER(name) name##TYPE* name;
  PKM_FUZZ_FMI2_FUNCTIONS(PKM_FUZZ_MEMBER)
#undef PKM_FUZZ_MEMBER
  const pkm_fmi::ModelDefinition* def;
};

const Api kApis[2] = {
    {
#define PKM_FUZZ_PLANT(name) &PKM4PUU_##name,
        PKM_FUZZ_FMI2_FUNCTIONS(PKM_FUZZ_PLANT)
#undef PKM_FUZZ_PLANT
            &pkm_fmi::pkm4puu_definition(),
    },
    {
#define PKM_FUZZ_INVERSE(name) &PKM4PUU_Inverse_##name,
        PKM_FUZZ_FMI2_FUNCTIONS(PKM_FUZZ_INVERSE)
#undef PKM_FUZZ_INVERSE
            &pkm_fmi::pkm4puu_inverse_definition(),
    },
};

struct Api3 {
#define PKM_FUZZ_MEMBER(name) name##TYPE* name;
  PKM_FMI3_FUNCTIONS(PKM_FUZZ_MEMBER)
#undef PKM_FUZZ_MEMBER
  const pkm_fmi::ModelDefinition* def;
};

const Api3 kApis3[2] = {
    {
#define PKM_FUZZ_PLANT(name) &PKM4PUU_##name,
        PKM_FMI3_FUNCTIONS(PKM_FUZZ_PLANT)
#undef PKM_FUZZ_PLANT
            &pkm_fmi::pkm4puu_definition(),
    },
    {
#define PKM_FUZZ_INVERSE(name) &PKM4PUU_Inverse_##name,
        PKM_FMI3_FUNCTIONS(PKM_FUZZ_INVERSE)
#undef PKM_FUZZ_INVERSE
            &pkm_fmi::pkm4puu_inverse_definition(),
    },
};

// ---------------------------------------------------------------- checks

unsigned long long g_calls = 0;  // FMI calls made (harness bookkeeping, not FMU state)
unsigned long long g_inputs = 0;

[[noreturn]] void violation(const char* what) {
  std::fprintf(stderr, "PKM_FUZZ VIOLATION: %s\n", what);
  std::abort();
}

void require(bool ok, const char* what) {
  if (!ok) violation(what);
}

void print_calls() {
  std::fprintf(stderr, "PKM_FUZZ_CALLS=%llu PKM_FUZZ_INPUTS=%llu\n", g_calls, g_inputs);
}

// The importer's logger: treats the message as a printf format with no
// arguments (as many masters do): the FMU must have escaped every '%'.
void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category, fmi2String message,
            ...) {
  (void)env;
  (void)status;
  require(message != nullptr && category != nullptr && name != nullptr, "logger called with NULL strings");
  for (const char* p = message; *p; ++p) {
    if (*p == '%') {
      require(p[1] == '%', "log message with an unescaped '%'");
      ++p;
    }
  }
  char buf[256];
  va_list args;
  va_start(args, message);
  std::vsnprintf(buf, sizeof buf, message, args);
  va_end(args);
}

void* fuzz_calloc(size_t n, size_t size) { return std::calloc(n, size); }
void fuzz_free(void* p) { std::free(p); }

const fmi2CallbackFunctions kCallbacks{&logger, &fuzz_calloc, &fuzz_free, nullptr, nullptr};
const fmi2CallbackFunctions kNoLogger{nullptr, &fuzz_calloc, &fuzz_free, nullptr, nullptr};

alignas(64) unsigned char g_foreign[512];  // never an instance nor a state (all zero)

// ---------------------------------------------------------------- values

double awkward(FuzzedDataProvider& in) {
  static const double values[] = {0.0,
                                  -0.0,
                                  1.0,
                                  -1.0,
                                  std::numeric_limits<double>::quiet_NaN(),
                                  std::numeric_limits<double>::infinity(),
                                  -std::numeric_limits<double>::infinity(),
                                  1e300,
                                  -1e300,
                                  1e-300,
                                  std::numeric_limits<double>::denorm_min(),
                                  std::numeric_limits<double>::max(),
                                  -std::numeric_limits<double>::max(),
                                  std::numeric_limits<double>::min(),
                                  2.655616050,
                                  2.7,
                                  0.05,
                                  0.08,
                                  0.075,
                                  1e-3,
                                  1e-4,
                                  0.02,
                                  0.5,
                                  3.0,
                                  1.1344640137963142,
                                  1e3,
                                  1e-2,
                                  0.4999,
                                  2147483648.0,
                                  -2147483649.0};
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
    case 1: return values[in.ConsumeIntegralInRange<std::size_t>(0, std::size(values) - 1)];
    case 2: return in.ConsumeFloatingPoint<double>();
    default: return in.ConsumeFloatingPointInRange<double>(-0.05, 0.05);
  }
}

/// A perturbation of a variable's start value (parameters: mostly valid).
double near_start(FuzzedDataProvider& in, const pkm_fmi::Variable& v) {
  const double s = v.has_start() ? v.start : 0.0;
  const double f = in.ConsumeFloatingPointInRange<double>(-0.3, 0.3);
  return s != 0.0 ? s * (1.0 + f) : f * 0.01;
}

fmi2ValueReference pick_vr(FuzzedDataProvider& in, const pkm_fmi::ModelDefinition& d) {
  if (in.ConsumeIntegralInRange<int>(0, 9) < 8)
    return d.variables[in.ConsumeIntegralInRange<std::size_t>(0, d.n_variables - 1)].vr;
  return in.ConsumeIntegral<fmi2ValueReference>();
}

const pkm_fmi::Variable* pick_var(FuzzedDataProvider& in, const pkm_fmi::ModelDefinition& d) {
  return &d.variables[in.ConsumeIntegralInRange<std::size_t>(0, d.n_variables - 1)];
}

double step_size(FuzzedDataProvider& in) {
  static const double common[] = {1e-3, 1e-3, 1e-3, 2e-3, 1e-4, 5e-3, 1e-2, 0.05};
  static const double odd[] = {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(), 1e-12, 0.3, 1.0, 1e-300};
  if (in.ConsumeIntegralInRange<int>(0, 15) != 0)
    return common[in.ConsumeIntegralInRange<std::size_t>(0, std::size(common) - 1)];
  return odd[in.ConsumeIntegralInRange<std::size_t>(0, std::size(odd) - 1)];
}

// ---------------------------------------------------------------- the world of one input

constexpr int kSlots = 3;
constexpr int kMaxOps = 48;

/// A forged serialised state: one bit flipped in a field the loader checks
/// against the instance -- the mode and flags (bytes 32..38,
/// fmu_state.hpp), the plant's contact mode and the integrators' memory at
/// its end (plant_state.hpp) -- or anywhere, and the checksum recomputed (the
/// last 8 bytes, fnv1a.hpp), so that the forgery passes the header's checks
/// and reaches those of the content.
template <class Byte>
void forge_field(std::vector<Byte>& b, FuzzedDataProvider& in) {
  // From the contact mode on: the mode, the memory's size, the memory, the checksum.
  constexpr auto& layout = pkm_fmi::pkm4puu_model::kPlantStateLayout;
  constexpr std::size_t kTail = layout.size - layout.stops + 8;
  if (b.size() < 40 + kTail) return;
  const std::size_t end = b.size() - 8;
  std::size_t at = 0;
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0: at = in.ConsumeIntegralInRange<std::size_t>(32, 38); break;
    case 1: at = in.ConsumeIntegralInRange<std::size_t>(b.size() - kTail, end - 1); break;
    default: at = in.ConsumeIntegralInRange<std::size_t>(0, end - 1); break;
  }
  b[at] = static_cast<Byte>(b[at] ^ (1u << in.ConsumeIntegralInRange<int>(0, 7)));
  const std::uint64_t h = pkm_fmi::fnv1a(reinterpret_cast<const unsigned char*>(b.data()), end);
  for (int k = 0; k < 8; ++k) b[end + k] = static_cast<Byte>((h >> (8 * k)) & 0xff);
}

/// The instances and FMU states of one input, for either FMI version V
/// (Fmi2, Fmi3 below: its Api, instance, state and byte types, and how to
/// free an instance and a state).
template <class V>
struct WorldOf {
  struct State {
    typename V::FmuState s = nullptr;
    int owner = -1;  // slot that created it
  };
  struct Slot {
    int kind = 0;     // 0 plant, 1 inverse
    bool me = false;  // FMI 3.0: a Model Exchange instance (FMI 2.0 tracks none)
    typename V::Instance c = nullptr;
    double time = 0.0;  // what the harness believes the current time is
  };
  Slot slots[kSlots];
  std::vector<State> states;
  std::vector<std::vector<typename V::Byte>> blobs;

  const typename V::Api& api(int i) const { return V::apis[slots[i].kind]; }

  void free_slot(int i) {
    if (!slots[i].c) return;
    ++g_calls;
    V::free_instance(api(i), slots[i].c);  // frees the states it created
    slots[i].c = nullptr;
    for (auto it = states.begin(); it != states.end();)
      it = (it->owner == i) ? states.erase(it) : it + 1;
  }
  ~WorldOf() {
    // Free every other state explicitly, leave the rest to FreeInstance.
    for (std::size_t k = 0; k < states.size(); k += 2) {
      State& st = states[k];
      if (slots[st.owner].c) {
        ++g_calls;
        V::free_state(api(st.owner), slots[st.owner].c, &st.s);
      }
    }
    for (int i = 0; i < kSlots; ++i) free_slot(i);
  }
};

/// A state just serialised (`blob`), forged (forge_field), deserialised and
/// handed to `set` at once, then freed: the loader's checks of the content
/// in one operation.
template <class V, class Set>
void forge_and_set(const typename V::Api& a, typename V::Instance c, std::vector<typename V::Byte> blob,
                   FuzzedDataProvider& in, Set&& set) {
  forge_field(blob, in);
  typename V::FmuState f = nullptr;
  ++g_calls;
  if (!V::deserialize(a, c, blob, &f)) return;
  set(f);
  ++g_calls;
  V::free_state(a, c, &f);
}

struct Fmi2 {
  using Api = ::Api;
  using Instance = fmi2Component;
  using FmuState = fmi2FMUstate;
  using Byte = fmi2Byte;
  static constexpr const Api* apis = kApis;
  static void free_instance(const Api& a, Instance c) { a.fmi2FreeInstance(c); }
  static void free_state(const Api& a, Instance c, FmuState* s) { a.fmi2FreeFMUstate(c, s); }
  static bool deserialize(const Api& a, Instance c, const std::vector<Byte>& b, FmuState* s) {
    return a.fmi2DeSerializeFMUstate(c, b.data(), b.size(), s) == fmi2OK;
  }
};
using World = WorldOf<Fmi2>;
using State = World::State;
using Slot = World::Slot;

fmi2Component component(FuzzedDataProvider& in, World& w, int i) {
  switch (in.ConsumeIntegralInRange<int>(0, 31)) {
    case 0: return nullptr;
    case 1: return g_foreign;
    default: return w.slots[i].c;
  }
}

void check_reals(fmi2Status s, const double* v, std::size_t n) {
  if (s != fmi2OK && s != fmi2Warning && s != fmi2Discard) return;
  for (std::size_t k = 0; k < n; ++k) require(std::isfinite(v[k]), "fmi2GetReal returned values with NaN or Inf");
}

constexpr double kGuard = -8.125e77;

void get_reals(const Api& a, fmi2Component c, const fmi2ValueReference* vr, std::size_t n, bool null_value) {
  std::vector<double> buf(n + 2, kGuard);
  ++g_calls;
  const fmi2Status s = a.fmi2GetReal(c, vr, n, null_value ? nullptr : buf.data() + 1);
  require(buf.front() == kGuard && buf.back() == kGuard, "fmi2GetReal wrote outside its buffer");
  // Discard (the inverse FMU beyond a singularity guard) hands out the last good outputs.
  if (s != fmi2OK && s != fmi2Warning && s != fmi2Discard) {
    for (double x : buf) require(x == kGuard, "fmi2GetReal failed but wrote values");
  } else if (!null_value) {
    check_reals(s, buf.data() + 1, n);
  }
}

/// All Real outputs of a slot (after a step).
void get_all_outputs(World& w, int i) {
  const Api& a = w.api(i);
  std::vector<fmi2ValueReference> vrs;
  for (std::size_t k = 0; k < a.def->n_variables; ++k)
    if (a.def->variables[k].causality == pkm_fmi::Causality::Output) vrs.push_back(a.def->variables[k].vr);
  get_reals(a, w.slots[i].c, vrs.data(), vrs.size(), false);
}

void do_step(FuzzedDataProvider& in, World& w, int i, double h) {
  Slot& sl = w.slots[i];
  if (!sl.c) return;
  const Api& a = w.api(i);
  // Keep RK4 runs short: a step of more than 2e4 RK4 steps (but fewer than
  // the 1e7 the FMU refuses outright) costs seconds under the sanitizers.
  if (sl.kind == 0) {
    const fmi2ValueReference solver_vr = 140, rk4_vr = 141;
    fmi2Integer solver = 0;
    double rk4 = 1e-3;
    g_calls += 2;
    if (a.fmi2GetInteger(sl.c, &solver_vr, 1, &solver) == fmi2OK && solver == 1 &&
        a.fmi2GetReal(sl.c, &rk4_vr, 1, &rk4) == fmi2OK && h / rk4 > 2e4 && h / rk4 <= 1.1e7)
      h = 2e4 * rk4;
  }
  double t = sl.time;
  if (in.ConsumeIntegralInRange<int>(0, 31) == 0) t = awkward(in);
  ++g_calls;
  static const bool trace = std::getenv("PKM_FUZZ_TRACE") != nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  const fmi2Status s = a.fmi2DoStep(component(in, w, i), t, h, in.ConsumeBool() ? fmi2True : fmi2False);
  if (trace) {
    std::fprintf(stderr, "  fmi2DoStep(slot %d, kind %d, t %.17g, h %g) = %d in %.3f s\n", i, sl.kind, t, h,
                 static_cast<int>(s), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    for (std::size_t k = 0; k < a.def->n_variables; ++k) {  // the parameters that differ from their start values
      const pkm_fmi::Variable& v = a.def->variables[k];
      if ((v.causality != pkm_fmi::Causality::Parameter && v.causality != pkm_fmi::Causality::Input) || v.type != pkm_fmi::VarType::Real) continue;
      double x = 0.0;
      if (a.fmi2GetReal(sl.c, &v.vr, 1, &x) == fmi2OK && x != v.start)
        std::fprintf(stderr, "    %s = %.17g (start %g)\n", v.name, x, v.start);
    }
  }
  if (s == fmi2OK || s == fmi2Warning) {
    sl.time = t + h;
    if (in.ConsumeBool()) get_all_outputs(w, i);
  } else if (s == fmi2Discard) {
    fmi2Boolean terminated = fmi2False;
    double last = std::numeric_limits<double>::quiet_NaN();
    g_calls += 2;
    require(a.fmi2GetBooleanStatus(sl.c, fmi2Terminated, &terminated) == fmi2OK && terminated == fmi2True,
            "fmi2Discard without fmi2Terminated");
    require(a.fmi2GetRealStatus(sl.c, fmi2LastSuccessfulTime, &last) == fmi2OK, "no fmi2LastSuccessfulTime");
    require(last >= t - 1e-9 * std::fmax(1.0, std::fabs(t)) && last <= t + h, "fmi2LastSuccessfulTime out of range");
    sl.time = last;
    get_all_outputs(w, i);
  }
}

void set_some(FuzzedDataProvider& in, World& w, int i, bool plausible) {
  const Api& a = w.api(i);
  const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 5);
  std::vector<fmi2ValueReference> vr(n);
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    const pkm_fmi::Variable* var = pick_var(in, *a.def);
    vr[k] = plausible ? var->vr : pick_vr(in, *a.def);
    v[k] = plausible && in.ConsumeBool() ? near_start(in, *var) : awkward(in);
  }
  ++g_calls;
  a.fmi2SetReal(component(in, w, i), n ? vr.data() : nullptr, n, (n || in.ConsumeBool()) ? v.data() : nullptr);
}

void boot(FuzzedDataProvider& in, World& w, int i) {
  w.free_slot(i);
  Slot& sl = w.slots[i];
  sl.kind = in.ConsumeIntegralInRange<int>(0, 3) == 0 ? 1 : 0;
  const Api& a = w.api(i);
  ++g_calls;
  sl.c = a.fmi2Instantiate("fuzz", fmi2CoSimulation, a.def->guid().c_str(), "", &kCallbacks, fmi2False,
                           in.ConsumeBool() ? fmi2True : fmi2False);
  if (!sl.c) violation("fmi2Instantiate failed with valid arguments");
  sl.time = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  g_calls += 4;
  a.fmi2SetupExperiment(sl.c, fmi2False, 0.0, sl.time, fmi2False, 0.0);
  const int n = in.ConsumeIntegralInRange<int>(0, 3);
  for (int k = 0; k < n; ++k) set_some(in, w, i, true);
  if (sl.kind == 0 && in.ConsumeBool()) {
    const fmi2ValueReference solver = 140;
    const fmi2Integer one = 1;
    ++g_calls;
    a.fmi2SetInteger(sl.c, &solver, 1, &one);
  }
  a.fmi2EnterInitializationMode(sl.c);
  a.fmi2ExitInitializationMode(sl.c);
}

void run(FuzzedDataProvider& in, World& w, int i) {
  const Slot& sl = w.slots[i];
  if (!sl.c) return;
  const Api& a = w.api(i);
  const int n = in.ConsumeIntegralInRange<int>(1, 12);
  const double h = step_size(in);
  for (int k = 0; k < n; ++k) {
    if (sl.kind == 0 && in.ConsumeBool()) {
      const fmi2ValueReference f[4] = {1, 2, 3, 4};
      double v[4];
      const double amp = in.ConsumeBool() ? 0.01 : in.ConsumeFloatingPointInRange<double>(-5.0, 5.0);
      for (int j = 0; j < 4; ++j) v[j] = 2.655616050 + amp * std::sin(3.0 * sl.time + j);
      ++g_calls;
      a.fmi2SetReal(sl.c, f, 4, v);
    }
    do_step(in, w, i, h);
  }
}

/// fmi2SetFMUstate on a slot; on success the harness takes the time the
/// instance now has. Whether it succeeded.
bool set_state(const Api& a, Slot& sl, fmi2FMUstate s) {
  ++g_calls;
  if (a.fmi2SetFMUstate(sl.c, s) != fmi2OK) return false;
  double t = 0.0;
  ++g_calls;
  if (a.fmi2GetRealStatus(sl.c, fmi2LastSuccessfulTime, &t) == fmi2OK) sl.time = t;
  else sl.time = 0.0;  // instantiated or initialisation mode: the experiment's start, not tracked
  // (the harness re-reads the time when it can; a wrong guess only makes fmi2DoStep refuse)
  return true;
}

void one_op(FuzzedDataProvider& in, World& w) {
  const int i = in.ConsumeIntegralInRange<int>(0, kSlots - 1);
  Slot& sl = w.slots[i];
  const Api& a = w.api(i);
  const pkm_fmi::ModelDefinition& d = *a.def;
  switch (in.ConsumeIntegralInRange<int>(0, 29)) {
    case 0:
    case 1: boot(in, w, i); break;
    case 2:
    case 3:
    case 4: run(in, w, i); break;
    case 5: {  // fmi2Instantiate with arbitrary arguments
      w.free_slot(i);
      sl.kind = in.ConsumeBool() ? 1 : 0;
      const Api& b = w.api(i);
      const std::string name = in.ConsumeRandomLengthString(16);
      const int guid_kind = in.ConsumeIntegralInRange<int>(0, 3);
      const std::string junk_guid = in.ConsumeRandomLengthString(40);
      const std::string token = b.def->guid();
      const char* guid = guid_kind == 0 ? nullptr : guid_kind == 1 ? junk_guid.c_str() : token.c_str();
      int type_bits = in.ConsumeBool() ? 1 : in.ConsumeIntegral<int>();
      fmi2Type type;
      std::memcpy(&type, &type_bits, sizeof type);  // a C importer may pass any int
      const int cb = in.ConsumeIntegralInRange<int>(0, 2);
      ++g_calls;
      sl.c = b.fmi2Instantiate(in.ConsumeBool() ? name.c_str() : nullptr, type, guid,
                               in.ConsumeBool() ? "file:///tmp" : nullptr,
                               cb == 0 ? nullptr : cb == 1 ? &kNoLogger : &kCallbacks, fmi2False,
                               in.ConsumeBool() ? fmi2True : fmi2False);
      sl.time = 0.0;
      break;
    }
    case 6:
      w.free_slot(i);
      break;
    case 7: {
      const double start = in.ConsumeBool() ? 0.0 : awkward(in);
      const double stop = in.ConsumeBool() ? start + 0.05 : awkward(in);
      ++g_calls;
      if (a.fmi2SetupExperiment(component(in, w, i), in.ConsumeBool(), awkward(in), start, in.ConsumeBool(), stop) ==
          fmi2OK)
        sl.time = start;
      break;
    }
    case 8: ++g_calls; a.fmi2EnterInitializationMode(component(in, w, i)); break;
    case 9: ++g_calls; a.fmi2ExitInitializationMode(component(in, w, i)); break;
    case 10: ++g_calls; a.fmi2Terminate(component(in, w, i)); break;
    case 11:
      ++g_calls;
      if (a.fmi2Reset(component(in, w, i)) == fmi2OK) sl.time = 0.0;
      break;
    case 12:
    case 13: set_some(in, w, i, in.ConsumeBool()); break;
    case 14: {
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 6);
      std::vector<fmi2ValueReference> vr(n);
      for (auto& r : vr) r = pick_vr(in, d);
      get_reals(a, component(in, w, i), n ? vr.data() : nullptr, n, in.ConsumeIntegralInRange<int>(0, 15) == 0);
      break;
    }
    case 15: {  // Integer
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 3);
      std::vector<fmi2ValueReference> vr(n);
      std::vector<fmi2Integer> v(n + 2, -123456);
      for (auto& r : vr) r = in.ConsumeBool() ? static_cast<fmi2ValueReference>(in.ConsumeIntegralInRange(140, 145))
                                              : pick_vr(in, d);
      if (in.ConsumeBool()) {
        for (std::size_t k = 0; k < n; ++k) v[k + 1] = in.ConsumeIntegralInRange<int>(-2, 3);
        if (in.ConsumeIntegralInRange<int>(0, 7) == 0 && n) v[1] = in.ConsumeIntegral<int>();
        ++g_calls;
        a.fmi2SetInteger(component(in, w, i), n ? vr.data() : nullptr, n, v.data() + 1);
      } else {
        ++g_calls;
        a.fmi2GetInteger(component(in, w, i), n ? vr.data() : nullptr, n, v.data() + 1);
        require(v.front() == -123456 && v.back() == -123456, "fmi2GetInteger wrote outside its buffer");
      }
      break;
    }
    case 16: {  // Boolean and String: this FMU has none
      const fmi2ValueReference vr = pick_vr(in, d);
      fmi2Boolean b[3] = {7, 7, 7};
      fmi2String s[3] = {"g", "g", "g"};
      g_calls += 4;
      a.fmi2GetBoolean(component(in, w, i), &vr, 1, &b[1]);
      a.fmi2SetBoolean(component(in, w, i), &vr, 1, &b[1]);
      a.fmi2GetString(component(in, w, i), &vr, 1, &s[1]);
      a.fmi2SetString(component(in, w, i), &vr, 1, &s[1]);
      require(b[0] == 7 && b[2] == 7 && s[0][0] == 'g' && s[2][0] == 'g', "Boolean/String wrote outside");
      break;
    }
    case 17: {  // input derivatives
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 4);
      std::vector<fmi2ValueReference> vr(n);
      std::vector<fmi2Integer> order(n);
      std::vector<double> v(n);
      for (std::size_t k = 0; k < n; ++k) {
        vr[k] = in.ConsumeBool() ? static_cast<fmi2ValueReference>(in.ConsumeIntegralInRange(1, 8)) : pick_vr(in, d);
        order[k] = in.ConsumeIntegralInRange<int>(-1, 3);
        v[k] = in.ConsumeBool() ? in.ConsumeFloatingPointInRange<double>(-10.0, 10.0) : awkward(in);
      }
      ++g_calls;
      a.fmi2SetRealInputDerivatives(component(in, w, i), n ? vr.data() : nullptr, n,
                                    in.ConsumeIntegralInRange<int>(0, 15) ? order.data() : nullptr, v.data());
      break;
    }
    case 18: {  // not provided
      const fmi2ValueReference vr = pick_vr(in, d);
      const fmi2Integer order = 1;
      double v[3] = {kGuard, kGuard, kGuard};
      const double dv = 1.0;
      g_calls += 3;
      a.fmi2GetRealOutputDerivatives(component(in, w, i), &vr, 1, &order, &v[1]);
      a.fmi2GetDirectionalDerivative(component(in, w, i), &vr, 1, &vr, 1, &dv, &v[1]);
      a.fmi2CancelStep(component(in, w, i));
      for (double x : v) require(x == kGuard, "a function that is not provided wrote a value");
      break;
    }
    case 19:
    case 20: do_step(in, w, i, step_size(in)); break;
    case 21: {  // status functions, any kind
      int kind_bits = in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(0, 4) : in.ConsumeIntegral<int>();
      fmi2StatusKind kind;
      std::memcpy(&kind, &kind_bits, sizeof kind);  // a C importer may pass any int
      fmi2Status st = fmi2Pending;
      double r = kGuard;
      fmi2Integer iv = 5;
      fmi2Boolean bv = 5;
      fmi2String sv = "g";
      const bool null_value = in.ConsumeIntegralInRange<int>(0, 15) == 0;
      g_calls += 5;
      a.fmi2GetStatus(component(in, w, i), kind, null_value ? nullptr : &st);
      a.fmi2GetRealStatus(component(in, w, i), kind, null_value ? nullptr : &r);
      a.fmi2GetIntegerStatus(component(in, w, i), kind, null_value ? nullptr : &iv);
      a.fmi2GetBooleanStatus(component(in, w, i), kind, null_value ? nullptr : &bv);
      a.fmi2GetStringStatus(component(in, w, i), kind, null_value ? nullptr : &sv);
      require(r == kGuard || std::isfinite(r), "fmi2GetRealStatus returned a non-finite time");
      break;
    }
    case 22: {  // fmi2GetFMUstate: new, overwrite, or into junk
      if (!sl.c) break;
      const int how = in.ConsumeIntegralInRange<int>(0, 7);
      if (how == 0) {
        fmi2FMUstate junk = g_foreign;
        ++g_calls;
        a.fmi2GetFMUstate(sl.c, &junk);
      } else if (how == 1 && !w.states.empty()) {
        State& st = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)];
        ++g_calls;
        if (w.slots[st.owner].kind == sl.kind) a.fmi2GetFMUstate(sl.c, &st.s);
      } else if (w.states.size() < 12) {
        State st;
        st.owner = i;
        ++g_calls;
        if (a.fmi2GetFMUstate(sl.c, &st.s) == fmi2OK) w.states.push_back(st);
      }
      break;
    }
    case 23: {  // fmi2SetFMUstate: own, another instance's (same or other FMU), NULL, junk
      if (!sl.c) break;
      fmi2FMUstate s = nullptr;
      const int how = in.ConsumeIntegralInRange<int>(0, 7);
      if (how == 0) s = g_foreign;
      else if (how > 1 && !w.states.empty())
        s = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)].s;
      set_state(a, sl, s);
      break;
    }
    case 24: {  // fmi2FreeFMUstate, through any live instance of the same FMU
      if (w.states.empty()) {
        fmi2FMUstate junk = in.ConsumeBool() ? g_foreign : nullptr;
        ++g_calls;
        if (sl.c) a.fmi2FreeFMUstate(sl.c, &junk);
        break;
      }
      const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1);
      State st = w.states[k];
      for (int j = 0; j < kSlots; ++j) {
        if (w.slots[j].c && w.slots[j].kind == w.slots[st.owner].kind && (j == i || j == st.owner)) {
          ++g_calls;
          if (w.api(j).fmi2FreeFMUstate(w.slots[j].c, &st.s) == fmi2OK) {
            require(st.s == nullptr, "fmi2FreeFMUstate did not clear the pointer");
            w.states.erase(w.states.begin() + static_cast<long>(k));
          }
          break;
        }
      }
      break;
    }
    case 25: {  // serialise a state (size query, exact or short buffer)
      if (!sl.c || w.states.empty()) break;
      const State& st = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)];
      std::size_t size = 0;
      ++g_calls;
      if (a.fmi2SerializedFMUstateSize(sl.c, st.s, &size) != fmi2OK) break;
      require(size > 0 && size < (1u << 20), "implausible serialised size");
      const std::size_t given = in.ConsumeBool() ? size : in.ConsumeIntegralInRange<std::size_t>(0, size);
      std::vector<fmi2Byte> blob(given + 2, 0x5a);
      ++g_calls;
      const fmi2Status s = a.fmi2SerializeFMUstate(sl.c, st.s, blob.data() + 1, given);
      require(blob.front() == 0x5a && blob.back() == 0x5a, "fmi2SerializeFMUstate wrote outside its buffer");
      if (s == fmi2OK && w.blobs.size() < 8) w.blobs.emplace_back(blob.begin() + 1, blob.end() - 1);
      if (s == fmi2OK && given == size && in.ConsumeBool())
        forge_and_set<Fmi2>(a, sl.c, {blob.begin() + 1, blob.end() - 1}, in,
                            [&](fmi2FMUstate f) { set_state(a, sl, f); });
      break;
    }
    case 26: {  // deserialise: a stored blob, mutated or truncated, or raw fuzz bytes
      if (!sl.c) break;
      std::vector<fmi2Byte> bytes;
      if (!w.blobs.empty() && in.ConsumeIntegralInRange<int>(0, 3) != 0) {
        bytes = w.blobs[in.ConsumeIntegralInRange<std::size_t>(0, w.blobs.size() - 1)];
        const int flips = in.ConsumeIntegralInRange<int>(0, 2);
        for (int f = 0; f < flips && !bytes.empty(); ++f)
          bytes[in.ConsumeIntegralInRange<std::size_t>(0, bytes.size() - 1)] ^= static_cast<fmi2Byte>(
              1u << in.ConsumeIntegralInRange<int>(0, 7));
        if (in.ConsumeBool()) forge_field(bytes, in);
        if (in.ConsumeIntegralInRange<int>(0, 7) == 0) bytes.resize(in.ConsumeIntegralInRange<std::size_t>(0, bytes.size()));
      } else {
        const std::string raw = in.ConsumeRandomLengthString(200);
        bytes.assign(raw.begin(), raw.end());
      }
      State st;
      st.owner = i;
      ++g_calls;
      if (a.fmi2DeSerializeFMUstate(sl.c, bytes.empty() ? nullptr : bytes.data(), bytes.size(), &st.s) == fmi2OK) {
        require(st.s != nullptr, "fmi2DeSerializeFMUstate returned fmi2OK without a state");
        if (w.states.size() < 12) {
          w.states.push_back(st);
        } else {
          ++g_calls;
          a.fmi2FreeFMUstate(sl.c, &st.s);
        }
      }
      break;
    }
    case 27: {  // logging
      static const char* const cats[] = {"logEvents",  "logStatusWarning", "logStatusDiscard", "logStatusError",
                                         "logStatusFatal", "logAll", "logNothing", "%s%n%x%%", ""};
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 4);
      std::vector<fmi2String> c(n);
      for (auto& s : c) {
        const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, std::size(cats));
        s = k == std::size(cats) ? nullptr : cats[k];
      }
      ++g_calls;
      a.fmi2SetDebugLogging(component(in, w, i), in.ConsumeBool(), n, n || in.ConsumeBool() ? c.data() : nullptr);
      break;
    }
    case 28:
      g_calls += 2;
      require(std::strcmp(a.fmi2GetVersion(), "2.0") == 0, "version");
      require(std::strcmp(a.fmi2GetTypesPlatform(), "default") == 0, "types platform");
      break;
    default: {  // read everything readable
      if (!sl.c) break;
      std::vector<fmi2ValueReference> vrs;
      for (std::size_t k = 0; k < d.n_variables; ++k)
        if (d.variables[k].type == pkm_fmi::VarType::Real) vrs.push_back(d.variables[k].vr);
      get_reals(a, sl.c, vrs.data(), vrs.size(), false);
      break;
    }
  }
}


// ---------------------------------------------------------------- FMI 3.0

void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
  (void)env;
  (void)status;
  require(message != nullptr && category != nullptr, "fmi3 logger called with NULL strings");
  volatile std::size_t n = std::strlen(message) + std::strlen(category);  // readable to their ends
  (void)n;
}

struct Fmi3 {
  using Api = Api3;
  using Instance = fmi3Instance;
  using FmuState = fmi3FMUState;
  using Byte = fmi3Byte;
  static constexpr const Api* apis = kApis3;
  static void free_instance(const Api& a, Instance c) { a.fmi3FreeInstance(c); }
  static void free_state(const Api& a, Instance c, FmuState* s) { a.fmi3FreeFMUState(c, s); }
  static bool deserialize(const Api& a, Instance c, const std::vector<Byte>& b, FmuState* s) {
    return a.fmi3DeserializeFMUState(c, b.data(), b.size(), s) == fmi3OK;
  }
};
using World3 = WorldOf<Fmi3>;
using Slot3 = World3::Slot;
using State3 = World3::State;

fmi3Instance instance3(FuzzedDataProvider& in, World3& w, int i) {
  switch (in.ConsumeIntegralInRange<int>(0, 31)) {
    case 0: return nullptr;
    case 1: return g_foreign;
    default: return w.slots[i].c;
  }
}

/// A call that fills `n` doubles through `call(buffer)`: guard zones, no
/// write on failure, finite values where it succeeds.
template <class Call>
fmi3Status checked_doubles(std::size_t n, bool null_buffer, const char* what, Call&& call) {
  std::vector<double> buf(n + 2, kGuard);
  ++g_calls;
  const fmi3Status s = call(null_buffer ? nullptr : buf.data() + 1);
  require(buf.front() == kGuard && buf.back() == kGuard, what);
  if (s != fmi3OK && s != fmi3Warning && s != fmi3Discard) {
    for (double x : buf) require(x == kGuard, what);
  } else if (!null_buffer) {
    for (std::size_t k = 0; k < n; ++k) require(std::isfinite(buf[k + 1]), what);
  }
  return s;
}

void get_float64(const Api3& a, fmi3Instance c, const fmi3ValueReference* vr, std::size_t n, bool null_value) {
  checked_doubles(n, null_value, "fmi3GetFloat64: NaN, Inf or a write outside its buffer or after failing",
                  [&](double* v) { return a.fmi3GetFloat64(c, vr, n, v, n); });
}

void get_all_float64(World3& w, int i) {
  const Api3& a = w.api(i);
  std::vector<fmi3ValueReference> vrs;
  for (std::size_t k = 0; k < a.def->n_variables; ++k)
    if (a.def->variables[k].type == pkm_fmi::VarType::Real) vrs.push_back(a.def->variables[k].vr);
  get_float64(a, w.slots[i].c, vrs.data(), vrs.size(), false);
}

void set_some3(FuzzedDataProvider& in, World3& w, int i, bool plausible) {
  const Api3& a = w.api(i);
  const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 5);
  std::vector<fmi3ValueReference> vr(n);
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    const pkm_fmi::Variable* var = pick_var(in, *a.def);
    vr[k] = plausible ? var->vr : pick_vr(in, *a.def);
    v[k] = plausible && in.ConsumeBool() ? near_start(in, *var) : awkward(in);
  }
  const std::size_t n_values = in.ConsumeIntegralInRange<int>(0, 15) == 0 ? n + 1 : n;
  if (n_values > n) v.push_back(0.0);
  ++g_calls;
  a.fmi3SetFloat64(instance3(in, w, i), n ? vr.data() : nullptr, n, (n || in.ConsumeBool()) ? v.data() : nullptr,
                   n_values);
}

/// The event iteration and back to continuous time (Model Exchange).
void event_iteration3(World3& w, int i) {
  const Api3& a = w.api(i);
  fmi3Boolean b[5] = {};
  double next = 0.0;
  g_calls += 3;
  a.fmi3EnterEventMode(w.slots[i].c);
  for (int k = 0; k < 4; ++k) {
    if (a.fmi3UpdateDiscreteStates(w.slots[i].c, &b[0], &b[1], &b[2], &b[3], &b[4], &next) != fmi3OK || !b[0]) break;
    ++g_calls;
  }
  a.fmi3EnterContinuousTimeMode(w.slots[i].c);
}

void boot3(FuzzedDataProvider& in, World3& w, int i) {
  w.free_slot(i);
  Slot3& sl = w.slots[i];
  sl.kind = in.ConsumeIntegralInRange<int>(0, 3) == 0 ? 1 : 0;
  sl.me = sl.kind == 0 && in.ConsumeBool();
  const Api3& a = w.api(i);
  const std::string token = a.def->guid();
  ++g_calls;
  const fmi3Boolean logging = in.ConsumeBool();
  sl.c = sl.me ? a.fmi3InstantiateModelExchange("fuzz3", token.c_str(), nullptr, false, logging, nullptr, &logger3)
               : a.fmi3InstantiateCoSimulation("fuzz3", token.c_str(), nullptr, false, logging, false, false, nullptr,
                                               0, nullptr, &logger3, nullptr);
  if (!sl.c) violation("fmi3Instantiate* failed with valid arguments");
  sl.time = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  const int n = in.ConsumeIntegralInRange<int>(0, 3);
  for (int k = 0; k < n; ++k) set_some3(in, w, i, true);
  if (sl.kind == 0 && in.ConsumeBool()) {
    const fmi3ValueReference solver = 140;
    const fmi3Int32 one = 1;
    ++g_calls;
    a.fmi3SetInt32(sl.c, &solver, 1, &one, 1);
  }
  g_calls += 2;
  a.fmi3EnterInitializationMode(sl.c, false, 0.0, sl.time, false, 0.0);
  a.fmi3ExitInitializationMode(sl.c);
  if (sl.me) event_iteration3(w, i);
}

void do_step3(FuzzedDataProvider& in, World3& w, int i, double h) {
  Slot3& sl = w.slots[i];
  if (!sl.c) return;
  const Api3& a = w.api(i);
  if (sl.kind == 0) {  // RK4 runs short, as in FMI 2.0's do_step
    const fmi3ValueReference solver_vr = 140, rk4_vr = 141;
    fmi3Int32 solver = 0;
    double rk4 = 1e-3;
    g_calls += 2;
    if (a.fmi3GetInt32(sl.c, &solver_vr, 1, &solver, 1) == fmi3OK && solver == 1 &&
        a.fmi3GetFloat64(sl.c, &rk4_vr, 1, &rk4, 1) == fmi3OK && h / rk4 > 2e4 && h / rk4 <= 1.1e7)
      h = 2e4 * rk4;
  }
  double t = sl.time;
  if (in.ConsumeIntegralInRange<int>(0, 31) == 0) t = awkward(in);
  fmi3Boolean event = false, terminate = false, early = false;
  double last = kGuard;
  ++g_calls;
  const fmi3Status s = a.fmi3DoStep(instance3(in, w, i), t, h, in.ConsumeBool(), &event, &terminate, &early, &last);
  if (s == fmi3OK || s == fmi3Warning || s == fmi3Discard) {
    require(std::isfinite(last), "fmi3DoStep: lastSuccessfulTime not finite");
    sl.time = last;
    if (s != fmi3OK || in.ConsumeBool()) get_all_float64(w, i);
  }
}

/// A few explicit Euler steps of an importer (Model Exchange), the states
/// set by vector or by value reference, events entered where an indicator
/// changes sign.
void integrate3(FuzzedDataProvider& in, World3& w, int i, double h) {
  Slot3& sl = w.slots[i];
  if (!sl.c || !sl.me) return;
  const Api3& a = w.api(i);
  const std::size_t nx = a.def->n_states, nz = a.def->n_event_indicators;
  std::vector<double> x(nx), dx(nx), z(nz), z_new(nz);
  const int n = in.ConsumeIntegralInRange<int>(1, 8);
  g_calls += 2;
  if (a.fmi3GetContinuousStates(sl.c, x.data(), nx) != fmi3OK) return;
  if (a.fmi3GetEventIndicators(sl.c, z.data(), nz) != fmi3OK) return;
  for (int k = 0; k < n; ++k) {
    g_calls += 5;
    if (a.fmi3GetContinuousStateDerivatives(sl.c, dx.data(), nx) != fmi3OK) return;
    for (std::size_t j = 0; j < nx; ++j) x[j] += h * dx[j];
    if (a.fmi3SetTime(sl.c, sl.time + h) != fmi3OK) return;
    sl.time += h;
    if (in.ConsumeBool()) {
      if (a.fmi3SetContinuousStates(sl.c, x.data(), nx) != fmi3OK) return;
    } else {  // by value reference: the states are the variables with a state index
      std::vector<fmi3ValueReference> vrs;
      std::vector<double> values;
      for (std::size_t v = 0; v < a.def->n_variables; ++v) {
        const pkm_fmi::Variable& var = a.def->variables[v];
        if (var.state >= 0) {
          vrs.push_back(var.vr);
          values.push_back(x[static_cast<std::size_t>(var.state)]);
        }
      }
      if (a.fmi3SetFloat64(sl.c, vrs.data(), vrs.size(), values.data(), values.size()) != fmi3OK) return;
    }
    fmi3Boolean enter = false, terminate = false;
    if (a.fmi3CompletedIntegratorStep(sl.c, true, &enter, &terminate) != fmi3OK) return;
    if (a.fmi3GetEventIndicators(sl.c, z_new.data(), nz) != fmi3OK) return;
    bool crossed = enter;
    for (std::size_t j = 0; j < nz; ++j) crossed = crossed || ((z[j] > 0) != (z_new[j] > 0));
    if (crossed) {
      event_iteration3(w, i);
      ++g_calls;
      if (a.fmi3GetEventIndicators(sl.c, z_new.data(), nz) != fmi3OK) return;
      // The end stops' indicators (after the guards', which end the simulation instead) are never 0 there.
      for (std::size_t j = pkm::kGuardIndicators; j < nz && sl.kind == 0; ++j)
        require(z_new[j] != 0.0, "an end stop's event indicator is 0 after the event iteration");
    }
    z.swap(z_new);
  }
}

void run3(FuzzedDataProvider& in, World3& w, int i) {
  const Slot3& sl = w.slots[i];
  if (!sl.c) return;
  const Api3& a = w.api(i);
  const double h = step_size(in);
  if (sl.me) {
    if (sl.kind == 0 && in.ConsumeBool()) {  // forces that drive the platform down onto its stops
      const fmi3ValueReference f[4] = {1, 2, 3, 4};
      const double v[4] = {-5.0, -5.0, -5.0, -5.0};
      ++g_calls;
      a.fmi3SetFloat64(sl.c, f, 4, v, 4);
    }
    integrate3(in, w, i, std::fmin(h, 1e-3));
    return;
  }
  const int n = in.ConsumeIntegralInRange<int>(1, 12);
  for (int k = 0; k < n; ++k) {
    if (sl.kind == 0 && in.ConsumeBool()) {
      const fmi3ValueReference f[4] = {1, 2, 3, 4};
      double v[4];
      const double amp = in.ConsumeBool() ? 0.01 : in.ConsumeFloatingPointInRange<double>(-5.0, 5.0);
      for (int j = 0; j < 4; ++j) v[j] = 2.655616050 + amp * std::sin(3.0 * sl.time + j);
      ++g_calls;
      a.fmi3SetFloat64(sl.c, f, 4, v, 4);
    }
    do_step3(in, w, i, h);
  }
}

/// fmi3SetFMUState on a slot; on success the harness takes the time the
/// instance now has. Whether it succeeded.
bool set_state3(const Api3& a, Slot3& sl, fmi3FMUState s) {
  ++g_calls;
  if (a.fmi3SetFMUState(sl.c, s) != fmi3OK) return false;
  double t = kGuard;  // the time a get of the independent variable reads
  const fmi3ValueReference time_vr = 0;
  ++g_calls;
  sl.time = a.fmi3GetFloat64(sl.c, &time_vr, 1, &t, 1) == fmi3OK ? t : 0.0;
  return true;
}

void one_op3(FuzzedDataProvider& in, World3& w) {
  const int i = in.ConsumeIntegralInRange<int>(0, kSlots - 1);
  Slot3& sl = w.slots[i];
  const Api3& a = w.api(i);
  const pkm_fmi::ModelDefinition& d = *a.def;
  switch (in.ConsumeIntegralInRange<int>(0, 27)) {
    case 0:
    case 1: boot3(in, w, i); break;
    case 2:
    case 3:
    case 4: run3(in, w, i); break;
    case 5: {  // instantiate with arbitrary arguments
      w.free_slot(i);
      sl.kind = in.ConsumeBool() ? 1 : 0;
      const Api3& b = w.api(i);
      const std::string name = in.ConsumeRandomLengthString(16);
      const std::string junk = in.ConsumeRandomLengthString(40);
      const std::string token = b.def->guid();
      const int token_kind = in.ConsumeIntegralInRange<int>(0, 3);
      const char* tok = token_kind == 0 ? nullptr : token_kind == 1 ? junk.c_str() : token.c_str();
      const char* nm = in.ConsumeBool() ? name.c_str() : nullptr;
      const fmi3LogMessageCallback log = in.ConsumeBool() ? &logger3 : nullptr;
      const int how = in.ConsumeIntegralInRange<int>(0, 2);
      const fmi3ValueReference required[2] = {pick_vr(in, *b.def), pick_vr(in, *b.def)};
      ++g_calls;
      if (how == 0) {
        sl.c = b.fmi3InstantiateModelExchange(nm, tok, in.ConsumeBool() ? "file:///tmp" : nullptr, in.ConsumeBool(),
                                              in.ConsumeBool(), nullptr, log);
        sl.me = true;
      } else if (how == 1) {
        sl.c = b.fmi3InstantiateCoSimulation(nm, tok, nullptr, in.ConsumeBool(), in.ConsumeBool(), in.ConsumeBool(),
                                             in.ConsumeBool(), in.ConsumeBool() ? required : nullptr,
                                             in.ConsumeIntegralInRange<std::size_t>(0, 2), nullptr, log, nullptr);
        sl.me = false;
      } else {
        sl.c = b.fmi3InstantiateScheduledExecution(nm, tok, nullptr, false, false, nullptr, log, nullptr, nullptr,
                                                   nullptr);
        sl.me = false;
      }
      sl.time = 0.0;
      break;
    }
    case 6: w.free_slot(i); break;
    case 7: {
      const double start = in.ConsumeBool() ? 0.0 : awkward(in);
      const double stop = in.ConsumeBool() ? start + 0.05 : awkward(in);
      ++g_calls;
      if (a.fmi3EnterInitializationMode(instance3(in, w, i), in.ConsumeBool(), awkward(in), start, in.ConsumeBool(),
                                        stop) == fmi3OK)
        sl.time = start;
      break;
    }
    case 8: ++g_calls; a.fmi3ExitInitializationMode(instance3(in, w, i)); break;
    case 9: ++g_calls; a.fmi3Terminate(instance3(in, w, i)); break;
    case 10:
      ++g_calls;
      if (a.fmi3Reset(instance3(in, w, i)) == fmi3OK) sl.time = 0.0;
      break;
    case 11:
    case 12: set_some3(in, w, i, in.ConsumeBool()); break;
    case 13: {
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 6);
      std::vector<fmi3ValueReference> vr(n);
      for (auto& r : vr) r = pick_vr(in, d);
      get_float64(a, instance3(in, w, i), n ? vr.data() : nullptr, n, in.ConsumeIntegralInRange<int>(0, 15) == 0);
      break;
    }
    case 14: {  // Int32
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 3);
      std::vector<fmi3ValueReference> vr(n);
      std::vector<fmi3Int32> v(n + 2, -123456);
      for (auto& r : vr) r = in.ConsumeBool() ? static_cast<fmi3ValueReference>(in.ConsumeIntegralInRange(140, 145))
                                              : pick_vr(in, d);
      ++g_calls;
      if (in.ConsumeBool()) {
        for (std::size_t k = 0; k < n; ++k) v[k + 1] = in.ConsumeIntegralInRange<int>(-2, 3);
        a.fmi3SetInt32(instance3(in, w, i), n ? vr.data() : nullptr, n, v.data() + 1, n);
      } else {
        a.fmi3GetInt32(instance3(in, w, i), n ? vr.data() : nullptr, n, v.data() + 1, n);
        require(v.front() == -123456 && v.back() == -123456, "fmi3GetInt32 wrote outside its buffer");
      }
      break;
    }
    case 15: {  // the types this FMU has none of
      const fmi3ValueReference vr = pick_vr(in, d);
      fmi3Boolean b[3] = {true, true, true};
      fmi3String str[3] = {"g", "g", "g"};
      float f32[3] = {7.f, 7.f, 7.f};
      std::int8_t i8[3] = {7, 7, 7};
      std::uint64_t u64[3] = {7, 7, 7};
      std::size_t sizes[3] = {7, 7, 7};
      fmi3Binary bins[3] = {nullptr, nullptr, nullptr};
      g_calls += 10;
      a.fmi3GetBoolean(instance3(in, w, i), &vr, 1, &b[1], 1);
      a.fmi3SetBoolean(instance3(in, w, i), &vr, 1, &b[1], 1);
      a.fmi3GetString(instance3(in, w, i), &vr, 1, &str[1], 1);
      a.fmi3SetString(instance3(in, w, i), &vr, 1, &str[1], 1);
      a.fmi3GetFloat32(instance3(in, w, i), &vr, 1, &f32[1], 1);
      a.fmi3SetFloat32(instance3(in, w, i), &vr, 1, &f32[1], 1);
      a.fmi3GetInt8(instance3(in, w, i), &vr, 1, &i8[1], 1);
      a.fmi3GetUInt64(instance3(in, w, i), &vr, 1, &u64[1], 1);
      a.fmi3GetBinary(instance3(in, w, i), &vr, 1, &sizes[1], &bins[1], 1);
      fmi3Clock clk[3] = {true, true, true};
      a.fmi3GetClock(instance3(in, w, i), &vr, 1, &clk[1]);
      require(b[0] && b[2] && str[0][0] == 'g' && str[2][0] == 'g' && f32[0] == 7.f && f32[2] == 7.f && i8[0] == 7 &&
                  i8[2] == 7 && u64[0] == 7 && u64[2] == 7 && sizes[0] == 7 && sizes[2] == 7 && clk[0] && clk[2],
              "a get of a type with no variables wrote outside its buffer");
      break;
    }
    case 16: {  // Model Exchange's mode changes and time, any state
      double next = kGuard;
      fmi3Boolean b[5] = {};
      g_calls += 1;
      switch (in.ConsumeIntegralInRange<int>(0, 4)) {
        case 0: a.fmi3EnterEventMode(instance3(in, w, i)); break;
        case 1:
          a.fmi3UpdateDiscreteStates(instance3(in, w, i), &b[0], &b[1], &b[2], &b[3], &b[4], &next);
          require(!b[4] || std::isfinite(next), "fmi3UpdateDiscreteStates: next event time not finite");
          break;
        case 2: a.fmi3EnterContinuousTimeMode(instance3(in, w, i)); break;
        case 3: {
          const double t = in.ConsumeBool() ? sl.time + 1e-3 : awkward(in);
          if (a.fmi3SetTime(instance3(in, w, i), t) == fmi3OK) sl.time = t;
          break;
        }
        default: a.fmi3CompletedIntegratorStep(instance3(in, w, i), in.ConsumeBool(), &b[0], &b[1]); break;
      }
      break;
    }
    case 17: {  // Model Exchange's arrays, right or wrong sizes
      const std::size_t right[4] = {d.n_states, d.n_states, d.n_event_indicators, d.n_states};
      const int which = in.ConsumeIntegralInRange<int>(0, 4);
      const std::size_t n = in.ConsumeBool() ? right[which % 4] : in.ConsumeIntegralInRange<std::size_t>(0, 20);
      const bool null_buffer = in.ConsumeIntegralInRange<int>(0, 15) == 0;
      const fmi3Instance c = instance3(in, w, i);
      const char* what = "a Model Exchange array: NaN, Inf or a write outside its buffer or after failing";
      switch (which) {
        case 0: checked_doubles(n, null_buffer, what, [&](double* v) { return a.fmi3GetContinuousStates(c, v, n); }); break;
        case 1: checked_doubles(n, null_buffer, what, [&](double* v) { return a.fmi3GetContinuousStateDerivatives(c, v, n); }); break;
        case 2: checked_doubles(n, null_buffer, what, [&](double* v) { return a.fmi3GetEventIndicators(c, v, n); }); break;
        case 3: checked_doubles(n, null_buffer, what, [&](double* v) { return a.fmi3GetNominalsOfContinuousStates(c, v, n); }); break;
        default: {
          std::vector<double> x(n + 1);
          for (auto& v : x) v = in.ConsumeBool() ? near_start(in, *pick_var(in, d)) : awkward(in);
          ++g_calls;
          a.fmi3SetContinuousStates(c, null_buffer ? nullptr : x.data(), n);
        }
      }
      break;
    }
    case 18: {  // directional and adjoint derivatives
      const std::size_t nu = in.ConsumeIntegralInRange<std::size_t>(0, 3), nk = in.ConsumeIntegralInRange<std::size_t>(0, 3);
      std::vector<fmi3ValueReference> u(nu), k(nk);
      for (auto& r : u) r = pick_vr(in, d);
      for (auto& r : k) r = pick_vr(in, d);
      const std::size_t n_seed = in.ConsumeBool() ? nk : in.ConsumeIntegralInRange<std::size_t>(0, 4);
      std::vector<double> seed(n_seed + 1, 1.0);
      const fmi3Instance c = instance3(in, w, i);
      const char* what = "directional derivative: NaN, Inf or a write outside its buffer or after failing";
      if (in.ConsumeBool()) {
        checked_doubles(nu, false, what, [&](double* v) {
          return a.fmi3GetDirectionalDerivative(c, u.data(), nu, k.data(), nk, seed.data(), n_seed, v, nu);
        });
      } else {
        checked_doubles(nk, false, what, [&](double* v) {
          return a.fmi3GetAdjointDerivative(c, u.data(), nu, k.data(), nk, seed.data(), n_seed, v, nk);
        });
      }
      break;
    }
    case 19: do_step3(in, w, i, step_size(in)); break;
    case 20: {  // get an FMU state: new or overwrite
      if (!sl.c) break;
      if (in.ConsumeBool() && !w.states.empty()) {
        State3& st = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)];
        ++g_calls;
        if (w.slots[st.owner].kind == sl.kind) a.fmi3GetFMUState(sl.c, &st.s);
      } else if (w.states.size() < 12) {
        State3 st;
        st.owner = i;
        ++g_calls;
        if (a.fmi3GetFMUState(sl.c, &st.s) == fmi3OK) w.states.push_back(st);
      }
      break;
    }
    case 21: {  // set an FMU state: own, another's, NULL, junk
      if (!sl.c) break;
      fmi3FMUState s = nullptr;
      const int how = in.ConsumeIntegralInRange<int>(0, 7);
      if (how == 0) s = g_foreign;
      else if (how > 1 && !w.states.empty())
        s = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)].s;
      set_state3(a, sl, s);
      break;
    }
    case 22: {  // free an FMU state through a live instance of the same FMU
      if (w.states.empty()) break;
      const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1);
      State3 st = w.states[k];
      for (int j = 0; j < kSlots; ++j) {
        if (w.slots[j].c && w.slots[j].kind == w.slots[st.owner].kind && (j == i || j == st.owner)) {
          ++g_calls;
          if (w.api(j).fmi3FreeFMUState(w.slots[j].c, &st.s) == fmi3OK) {
            require(st.s == nullptr, "fmi3FreeFMUState did not clear the pointer");
            w.states.erase(w.states.begin() + static_cast<long>(k));
          }
          break;
        }
      }
      break;
    }
    case 23: {  // serialise, then deserialise a stored blob (mutated) or raw bytes
      if (!sl.c) break;
      if (!w.states.empty() && in.ConsumeBool()) {
        const State3& st = w.states[in.ConsumeIntegralInRange<std::size_t>(0, w.states.size() - 1)];
        std::size_t size = 0;
        ++g_calls;
        if (a.fmi3SerializedFMUStateSize(sl.c, st.s, &size) != fmi3OK) break;
        require(size > 0 && size < (1u << 20), "implausible serialised size");
        const std::size_t given = in.ConsumeBool() ? size : in.ConsumeIntegralInRange<std::size_t>(0, size);
        std::vector<fmi3Byte> blob(given + 2, 0x5a);
        ++g_calls;
        const fmi3Status s = a.fmi3SerializeFMUState(sl.c, st.s, blob.data() + 1, given);
        require(blob.front() == 0x5a && blob.back() == 0x5a, "fmi3SerializeFMUState wrote outside its buffer");
        if (s == fmi3OK && w.blobs.size() < 8) w.blobs.emplace_back(blob.begin() + 1, blob.end() - 1);
        if (s == fmi3OK && given == size && in.ConsumeBool())
          forge_and_set<Fmi3>(a, sl.c, {blob.begin() + 1, blob.end() - 1}, in,
                              [&](fmi3FMUState f) { set_state3(a, sl, f); });
        break;
      }
      std::vector<fmi3Byte> bytes;
      if (!w.blobs.empty() && in.ConsumeBool()) {
        bytes = w.blobs[in.ConsumeIntegralInRange<std::size_t>(0, w.blobs.size() - 1)];
        if (!bytes.empty() && in.ConsumeBool())
          bytes[in.ConsumeIntegralInRange<std::size_t>(0, bytes.size() - 1)] ^=
              static_cast<fmi3Byte>(1u << in.ConsumeIntegralInRange<int>(0, 7));
        if (in.ConsumeBool()) forge_field(bytes, in);
      } else {
        const std::string raw = in.ConsumeRandomLengthString(200);
        bytes.assign(raw.begin(), raw.end());
      }
      State3 st;
      st.owner = i;
      ++g_calls;
      if (a.fmi3DeserializeFMUState(sl.c, bytes.empty() ? nullptr : bytes.data(), bytes.size(), &st.s) == fmi3OK) {
        require(st.s != nullptr, "fmi3DeserializeFMUState returned fmi3OK without a state");
        if (w.states.size() < 12) {
          w.states.push_back(st);
        } else {
          ++g_calls;
          a.fmi3FreeFMUState(sl.c, &st.s);
        }
      }
      break;
    }
    case 24: {  // logging
      static const char* const cats[] = {"logEvents", "logStatusWarning", "logStatusError", "logAll", "%s%n", ""};
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 4);
      std::vector<fmi3String> c(n);
      for (auto& s : c) {
        const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, std::size(cats));
        s = k == std::size(cats) ? nullptr : cats[k];
      }
      ++g_calls;
      a.fmi3SetDebugLogging(instance3(in, w, i), in.ConsumeBool(), n, n || in.ConsumeBool() ? c.data() : nullptr);
      break;
    }
    case 25: {  // counts, version, dependencies and what is not provided
      std::size_t count = 7;
      const fmi3ValueReference vr = pick_vr(in, d);
      const fmi3Instance c = instance3(in, w, i);
      g_calls += 8;
      require(std::strcmp(a.fmi3GetVersion(), "3.0") == 0, "fmi3GetVersion");
      a.fmi3GetNumberOfContinuousStates(c, in.ConsumeBool() ? &count : nullptr);
      a.fmi3GetNumberOfEventIndicators(c, in.ConsumeBool() ? &count : nullptr);
      a.fmi3GetNumberOfVariableDependencies(c, vr, &count);
      a.fmi3EnterStepMode(c);
      a.fmi3EnterConfigurationMode(c);
      a.fmi3ExitConfigurationMode(c);
      const fmi3Int32 order = 1;
      double v[3] = {kGuard, kGuard, kGuard};
      a.fmi3GetOutputDerivatives(c, &vr, 1, &order, &v[1], 1);
      require(v[0] == kGuard && v[2] == kGuard, "fmi3GetOutputDerivatives wrote outside its buffer");
      break;
    }
    default: {  // read everything readable
      if (!sl.c) break;
      get_all_float64(w, i);
      break;
    }
  }
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::atexit(&print_calls);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ++g_inputs;
  static const bool trace = std::getenv("PKM_FUZZ_TRACE") != nullptr;  // harness debugging: time per operation
  auto ops = [&](FuzzedDataProvider& in, auto& w, auto&& one) {
    for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
      const unsigned long long calls = g_calls;
      const auto t0 = std::chrono::steady_clock::now();
      one(in, w);
      if (trace)
        std::fprintf(stderr, "op %d: %llu calls, %.3f s\n", op, g_calls - calls,
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  };
  if (size >= 4 && std::memcmp(data, "FMI3", 4) == 0) {  // the FMI 3.0 front end
    FuzzedDataProvider in(data + 4, size - 4);
    World3 w;
    ops(in, w, one_op3);
  } else {
    FuzzedDataProvider in(data, size);
    World w;
    ops(in, w, one_op);
  }
  return 0;
}
