// A model-independent FMI 2.0 Co-Simulation layer, in the spirit of the
// Modelica Association's Reference-FMUs: the instance, the FMI state
// machine, logging through the importer's callback, get/set of all
// variables driven by one table per model, FMU states and their
// serialisation. A model supplies only
//   - a ModelDefinition (immutable, shared by every instance: identity,
//     capability flags, the variable table, a factory), and
//   - a ModelData subclass (per instance, mutable: the storage the table
//     points into plus a few hooks: reset, exit initialisation, do step,
//     compute outputs, save/load its state beyond the table's values).
// There is no global or static mutable state: instances are independent.
// Nothing here writes to stdout or stderr; every message goes to the
// fmi2CallbackLogger given to fmi2Instantiate.
#pragma once

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "fmi2Functions.h"

namespace pkm_fmi {

// ---------------------------------------------------------------- variables

enum class VarType : std::uint8_t { Real, Integer, Boolean };
enum class Causality : std::uint8_t { Parameter, CalculatedParameter, Input, Output, Local, Independent };
enum class Variability : std::uint8_t { Constant, Fixed, Tunable, Discrete, Continuous };
enum class Initial : std::uint8_t { None, Exact, Approx, Calculated };

/// The modelDescription.xml spelling ("Real", "parameter", "fixed", "exact"; "" for Initial::None).
const char* xml_name(VarType t);
const char* xml_name(Causality c);
const char* xml_name(Variability v);
const char* xml_name(Initial i);

class ModelData;
class Instance;
struct SavedState;  // an FMU state (fmi2_cs.cpp)

/// Where a variable lives in an instance's data: returns a pointer to a
/// double (Real), fmi2Integer (Integer) or fmi2Boolean (Boolean). `index`
/// is the variable's element index (arrays), 0 for scalars.
using Ref = void* (*)(ModelData& data, int index);

/// One row of a model's variable table: everything modelDescription.xml
/// says about a ScalarVariable, plus how to reach its value.
struct Variable {
  fmi2ValueReference vr;
  const char* name;
  VarType type;
  Causality causality;
  Variability variability;
  Initial initial;      // Initial::None: attribute absent (inputs, independent)
  double start;         // meaningful iff has_start()
  const char* unit;     // "" = no unit attribute
  const char* description;
  Ref value;
  int index;
  Ref derivative;       // first derivative of a continuous Real input
                        // (fmi2SetRealInputDerivatives), nullptr if none

  constexpr bool has_start() const {
    return causality == Causality::Input || initial == Initial::Exact || initial == Initial::Approx;
  }
  /// Values the model computes (read through ModelData::update_outputs).
  constexpr bool computed() const {
    return causality == Causality::Output || causality == Causality::Local ||
           causality == Causality::CalculatedParameter;
  }
  /// Values an FMU state carries (the rest is recomputed).
  constexpr bool stored_in_state() const {
    return causality == Causality::Parameter || causality == Causality::Input;
  }
};

/// Table rows of the usual kinds.
/// A continuous Real input (start value required, no initial attribute).
constexpr Variable real_input(fmi2ValueReference vr, const char* name, double start, const char* unit,
                              const char* description, Ref value, int index, Ref derivative) {
  return {vr,    name, VarType::Real, Causality::Input, Variability::Continuous, Initial::None, start, unit,
          description, value, index, derivative};
}
/// A continuous Real output computed by the model (initial calculated, no start).
constexpr Variable real_output(fmi2ValueReference vr, const char* name, const char* unit,
                               const char* description, Ref value, int index) {
  return {vr,    name, VarType::Real, Causality::Output, Variability::Continuous, Initial::Calculated, 0.0, unit,
          description, value, index, nullptr};
}
/// A fixed Real parameter (initial exact): settable before initialisation ends.
constexpr Variable real_parameter(fmi2ValueReference vr, const char* name, double start, const char* unit,
                                  const char* description, Ref value, int index) {
  return {vr,    name, VarType::Real, Causality::Parameter, Variability::Fixed, Initial::Exact, start, unit,
          description, value, index, nullptr};
}
/// A fixed Integer parameter (initial exact).
constexpr Variable integer_parameter(fmi2ValueReference vr, const char* name, int start, const char* description,
                                     Ref value) {
  return {vr,    name, VarType::Integer, Causality::Parameter, Variability::Fixed, Initial::Exact,
          static_cast<double>(start), "", description, value, 0, nullptr};
}

// ---------------------------------------------------------------- logging

/// The log categories of modelDescription.xml, in this order.
enum class LogCategory : unsigned { Events, StatusWarning, StatusDiscard, StatusError, StatusFatal, All };
constexpr int kLogCategoryCount = 6;
inline constexpr const char* kLogCategoryNames[kLogCategoryCount] = {
    "logEvents", "logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logAll"};
inline constexpr const char* kLogCategoryDescriptions[kLogCategoryCount] = {
    "Mode changes: initialisation, termination, reset, FMU state get/set",
    "Messages returned with status fmi2Warning",
    "Messages returned with status fmi2Discard (a communication step that could not be completed)",
    "Messages returned with status fmi2Error",
    "Messages returned with status fmi2Fatal",
    "Every call of an FMI function, with its arguments (verbose)"};

#if defined(__GNUC__)
#define PKM_FMI_PRINTF(fmt, args) __attribute__((format(printf, fmt, args)))
#else
#define PKM_FMI_PRINTF(fmt, args)
#endif

/// Sends messages to the importer's fmi2CallbackLogger, filtered by the
/// categories enabled through fmi2Instantiate(loggingOn) and
/// fmi2SetDebugLogging. With loggingOn = fmi2False the logStatus* categories
/// (warning, discard, error, fatal) are enabled, so that every status other
/// than fmi2OK comes with its reason, and logEvents and logAll are not;
/// with fmi2True all are. fmi2SetDebugLogging can switch any of them.
/// Enabling logAll enables every category.
class Logger {
 public:
  Logger(fmi2CallbackLogger logger, fmi2ComponentEnvironment env, std::string instance_name,
         bool logging_on);

  bool enabled(LogCategory c) const;
  void enable(LogCategory c, bool on) { on_[static_cast<unsigned>(c)] = on; }
  void enable_all(bool on);

  void log(fmi2Status status, LogCategory c, const char* fmt, ...) PKM_FMI_PRINTF(4, 5);
  void error(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void warning(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void discard(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void event(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);
  void trace(const char* fmt, ...) PKM_FMI_PRINTF(2, 3);  // logAll

  const std::string& instance_name() const { return name_; }

 private:
  void vlog(fmi2Status status, LogCategory c, const char* fmt, va_list args);

  fmi2CallbackLogger logger_;
  fmi2ComponentEnvironment env_;
  std::string name_;
  bool on_[kLogCategoryCount];
};

// ---------------------------------------------------------------- FMU states

/// Appends little-endian fixed-size fields to a byte vector.
class StateWriter {
 public:
  explicit StateWriter(std::vector<unsigned char>& out) : out_(out) {}
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v);
  template <class It>
  void f64s(It first, It last) {
    for (; first != last; ++first) f64(*first);
  }

 private:
  std::vector<unsigned char>& out_;
};

/// Reads what StateWriter wrote; never reads past the end (ok() turns false).
class StateReader {
 public:
  StateReader(const unsigned char* data, std::size_t size) : p_(data), end_(data + size) {}
  std::uint8_t u8();
  std::uint32_t u32();
  std::uint64_t u64();
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64();
  template <class It>
  void f64s(It first, It last) {
    for (; first != last; ++first) *first = f64();
  }
  bool ok() const { return ok_; }
  bool at_end() const { return p_ == end_; }

 private:
  bool take(std::size_t n);
  const unsigned char* p_;
  const unsigned char* end_;
  bool ok_ = true;
};

// ---------------------------------------------------------------- the model

/// FMI 2.0 co-simulation states (bit masks; the spec's state machine).
enum Mode : std::uint32_t {
  kInstantiated = 1u << 0,
  kInitializationMode = 1u << 1,
  kStepComplete = 1u << 2,
  kStepInProgress = 1u << 3,  // never entered: fmi2DoStep is synchronous
  kStepFailed = 1u << 4,      // after fmi2DoStep returned fmi2Discard
  kStepCanceled = 1u << 5,    // never entered
  kTerminated = 1u << 6,
  kError = 1u << 7,
  kFatal = 1u << 8,
};
const char* mode_name(std::uint32_t mode);

/// What a hook may see of its instance.
struct Context {
  Logger& log;
  std::uint32_t mode;
  double start_time;  // fmi2SetupExperiment's startTime (0 if not called)
};

/// Per-instance data of a model: the storage the variable table points
/// into, and the model's hooks. Start values are written through the table
/// by the generic layer; parameters, inputs and input derivatives are saved
/// in FMU states by the generic layer too.
class ModelData {
 public:
  virtual ~ModelData() = default;
  /// After fmi2Instantiate and fmi2Reset, once the table's start values are
  /// written: forget everything derived (solvers, caches, warm starts).
  virtual void reset() = 0;
  /// fmi2ExitInitializationMode: build the model from the parameters and
  /// set the initial state at ctx.start_time. fmi2Error with a logged
  /// message if that is impossible.
  virtual fmi2Status exit_initialization(Context& ctx) = 0;
  /// fmi2DoStep from t to t + h (t is the current time). On return
  /// t_reached is the last time the state is valid for: t + h for fmi2OK,
  /// the last good point for fmi2Discard (the state intact there).
  virtual fmi2Status do_step(Context& ctx, double t, double h, double& t_reached) = 0;
  /// Writes every computed variable (outputs) for the current time,
  /// parameters and inputs. Called lazily, before a get that needs them.
  virtual fmi2Status update_outputs(Context& ctx) = 0;
  /// The model's state beyond the table's values.
  virtual void save(StateWriter& w) const = 0;
  /// Reads what save() wrote, after the table's values were restored.
  /// Returns false (with a logged message) if the state cannot be used.
  virtual bool load(StateReader& r, Context& ctx) = 0;
};

/// Everything immutable about one FMU, shared by all its instances.
struct ModelDefinition {
  const char* identifier;   // modelIdentifier (= modelName)
  const char* guid;
  const char* title;        // one line, for the documentation
  const char* summary;      // a paragraph of HTML, for the documentation
  const Variable* variables;  // sorted by value reference, unique
  std::size_t n_variables;
  bool can_interpolate_inputs;
  std::unique_ptr<ModelData> (*create)();

  /// The variable with this value reference, nullptr if none.
  const Variable* find(fmi2ValueReference vr) const;
  const Variable* find(const char* name) const;
};

/// True if the table is sorted by strictly increasing value reference.
constexpr bool sorted_by_vr(const Variable* v, std::size_t n) {
  for (std::size_t i = 1; i < n; ++i)
    if (!(v[i - 1].vr < v[i].vr)) return false;
  return true;
}

// ---------------------------------------------------------------- the instance

/// One FMU instance: the FMI 2.0 co-simulation functions as methods. The
/// exported C functions (fmi2_functions.cpp) forward to these.
///
/// Errors: a call with wrong arguments or in the wrong state returns
/// fmi2Error with a logged message and has no effect (the instance stays
/// usable). A failure of the model itself (initialisation impossible, step
/// failed beyond recovery) returns fmi2Error and puts the instance in the
/// Error state: then only get, reset, free and the FMU state functions are
/// allowed (fmi2SetFMUstate may return to a saved good state).
class Instance {
 public:
  /// nullptr on failure (logged through functions->logger if there is one).
  /// `type` and the status kinds below are the C enums' values as int: an
  /// importer written in C may pass any int, which a C++ enum parameter
  /// must not hold (fmi2_functions.cpp reads them as int at the boundary).
  static Instance* instantiate(const ModelDefinition& def, fmi2String instance_name, int type,
                               fmi2String guid, fmi2String resource_location,
                               const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                               fmi2Boolean logging_on);
  /// The instance behind an fmi2Component, nullptr if it is not one of ours.
  static Instance* from(fmi2Component c);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  fmi2Status set_debug_logging(fmi2Boolean on, std::size_t n, const fmi2String categories[]);
  fmi2Status setup_experiment(fmi2Boolean tolerance_defined, fmi2Real tolerance, fmi2Real start_time,
                              fmi2Boolean stop_time_defined, fmi2Real stop_time);
  fmi2Status enter_initialization_mode();
  fmi2Status exit_initialization_mode();
  fmi2Status terminate();
  fmi2Status reset();

  fmi2Status get_real(const fmi2ValueReference vr[], std::size_t n, fmi2Real value[]);
  fmi2Status get_integer(const fmi2ValueReference vr[], std::size_t n, fmi2Integer value[]);
  fmi2Status get_boolean(const fmi2ValueReference vr[], std::size_t n, fmi2Boolean value[]);
  fmi2Status get_string(const fmi2ValueReference vr[], std::size_t n, fmi2String value[]);
  fmi2Status set_real(const fmi2ValueReference vr[], std::size_t n, const fmi2Real value[]);
  fmi2Status set_integer(const fmi2ValueReference vr[], std::size_t n, const fmi2Integer value[]);
  fmi2Status set_boolean(const fmi2ValueReference vr[], std::size_t n, const fmi2Boolean value[]);
  fmi2Status set_string(const fmi2ValueReference vr[], std::size_t n, const fmi2String value[]);

  fmi2Status get_fmu_state(fmi2FMUstate* state);
  fmi2Status set_fmu_state(fmi2FMUstate state);
  fmi2Status free_fmu_state(fmi2FMUstate* state);
  fmi2Status serialized_fmu_state_size(fmi2FMUstate state, std::size_t* size);
  fmi2Status serialize_fmu_state(fmi2FMUstate state, fmi2Byte bytes[], std::size_t size);
  fmi2Status deserialize_fmu_state(const fmi2Byte bytes[], std::size_t size, fmi2FMUstate* state);

  fmi2Status get_directional_derivative(const fmi2ValueReference unknown[], std::size_t n_unknown,
                                        const fmi2ValueReference known[], std::size_t n_known,
                                        const fmi2Real dv_known[], fmi2Real dv_unknown[]);

  fmi2Status set_real_input_derivatives(const fmi2ValueReference vr[], std::size_t n,
                                        const fmi2Integer order[], const fmi2Real value[]);
  fmi2Status get_real_output_derivatives(const fmi2ValueReference vr[], std::size_t n,
                                         const fmi2Integer order[], fmi2Real value[]);
  fmi2Status do_step(fmi2Real current_communication_point, fmi2Real step_size,
                     fmi2Boolean no_set_fmu_state_prior);
  fmi2Status cancel_step();
  fmi2Status get_status(int kind, fmi2Status* value);
  fmi2Status get_real_status(int kind, fmi2Real* value);
  fmi2Status get_integer_status(int kind, fmi2Integer* value);
  fmi2Status get_boolean_status(int kind, fmi2Boolean* value);
  fmi2Status get_string_status(int kind, fmi2String* value);

  /// Turns an exception escaping a method into fmi2Error (never across the C ABI).
  fmi2Status internal_error(const char* function, const char* what);

  const ModelDefinition& definition() const { return def_; }
  std::uint32_t mode() const { return mode_; }
  double time() const { return time_; }
  Logger& logger() { return log_; }

 private:
  Instance(const ModelDefinition& def, Logger log);

  bool allowed(std::uint32_t mask, const char* function);
  Context context() { return Context{log_, mode_, start_time_}; }
  void apply_start_values();
  fmi2Status ensure_outputs(const char* function);
  template <class T>
  fmi2Status get_values(const char* function, VarType type, const fmi2ValueReference vr[],
                        std::size_t n, T value[]);
  template <class T>
  fmi2Status set_values(const char* function, VarType type, const fmi2ValueReference vr[],
                        std::size_t n, const T value[]);
  const Variable* lookup(const char* function, VarType type, fmi2ValueReference vr);

  /// A new FMU state owned by this instance (freed with it if the importer does not).
  SavedState* new_state();

  void save(std::vector<unsigned char>& out) const;
  bool check_header(const unsigned char* bytes, std::size_t size, const char* function);
  bool load(const std::vector<unsigned char>& bytes, const char* function);

  std::uint64_t tag_;  // identifies a live Instance behind an fmi2Component
  const ModelDefinition& def_;
  Logger log_;
  std::unique_ptr<ModelData> data_;
  std::uint32_t mode_ = kInstantiated;
  double start_time_ = 0.0;
  double stop_time_ = 0.0;
  bool stop_time_defined_ = false;
  double time_ = 0.0;                   // current communication point
  double last_successful_time_ = 0.0;   // fmi2LastSuccessfulTime
  bool terminated_ = false;             // fmi2Terminated (set after a discarded step)
  bool outputs_valid_ = false;          // computed variables up to date
  bool input_derivatives_set_ = false;  // fmi2SetRealInputDerivatives was used (or a state restored)
  std::unordered_set<SavedState*> states_;  // FMU states this instance created and nobody freed yet

 public:
  /// Forgets a state freed through any instance (fmi2FreeFMUstate).
  void forget_state(SavedState* s) { states_.erase(s); }
};

}  // namespace pkm_fmi
