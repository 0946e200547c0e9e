#include "fmi2_cs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

namespace pkm_fmi {
namespace {

constexpr std::uint64_t kInstanceTag = 0x49324d464d4b5001ull;  // marks a live Instance
constexpr std::uint64_t kStateTag = 0x53324d464d4b5001ull;     // marks a live SavedState

// Serialised FMU state (all fields little-endian):
//   [0, 8)    magic "PKMFMUST"
//   [8, 12)   format version
//   [12, 16)  reserved, 0
//   [16, 24)  total size in bytes, this header and the checksum included
//   [24, 32)  FNV-1a 64 of the model's GUID (a state of another FMU is rejected)
//   [32, n-8) the body: the generic part (Instance::save), then the model's
//   [n-8, n)  FNV-1a 64 of bytes [0, n-8)
constexpr unsigned char kMagic[8] = {'P', 'K', 'M', 'F', 'M', 'U', 'S', 'T'};
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::size_t kHeaderSize = 32;
constexpr std::size_t kTrailerSize = 8;

// Allowed states of each function (FMI 2.0 co-simulation state machine).
constexpr std::uint32_t kAlive = kInstantiated | kInitializationMode | kStepComplete | kStepInProgress |
                                 kStepFailed | kStepCanceled | kTerminated | kError;
constexpr std::uint32_t kMaskSetDebugLogging = kAlive;
constexpr std::uint32_t kMaskSetupExperiment = kInstantiated;
constexpr std::uint32_t kMaskEnterInitialization = kInstantiated;
constexpr std::uint32_t kMaskExitInitialization = kInitializationMode;
constexpr std::uint32_t kMaskTerminate = kStepComplete | kStepFailed | kStepCanceled;
constexpr std::uint32_t kMaskReset = kInstantiated | kInitializationMode | kStepComplete | kStepFailed |
                                     kStepCanceled | kTerminated | kError;
constexpr std::uint32_t kMaskGet =
    kInitializationMode | kStepComplete | kStepFailed | kStepCanceled | kTerminated | kError;
constexpr std::uint32_t kMaskSet = kInstantiated | kInitializationMode | kStepComplete;
constexpr std::uint32_t kMaskFmuState = kMaskReset;
constexpr std::uint32_t kMaskInputDerivatives = kMaskSet;
constexpr std::uint32_t kMaskOutputDerivatives = kStepComplete | kStepFailed | kStepCanceled | kTerminated | kError;
constexpr std::uint32_t kMaskDoStep = kStepComplete;
constexpr std::uint32_t kMaskCancelStep = kStepInProgress;
constexpr std::uint32_t kMaskStatus = kStepComplete | kStepInProgress | kStepFailed | kStepCanceled | kTerminated;
// States an FMU state may carry (the others are transient or unrecoverable).
constexpr std::uint32_t kRestorableModes =
    kInstantiated | kInitializationMode | kStepComplete | kStepFailed | kTerminated | kError;

std::uint64_t fnv1a(const unsigned char* p, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

std::uint64_t fnv1a(const char* s) { return fnv1a(reinterpret_cast<const unsigned char*>(s), std::strlen(s)); }

std::uint64_t read_le64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

std::uint32_t read_le32(const unsigned char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void write_le64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

}  // namespace

// The in-memory FMU state: its serialised form (so that get/set and
// serialise/deserialise share one code path and one format), and the
// instance that created it (fmi2FreeInstance frees the states it created).
struct SavedState {
  std::uint64_t tag = kStateTag;
  std::vector<unsigned char> bytes;
  Instance* owner = nullptr;
};

namespace {

SavedState* as_state(fmi2FMUstate s) {
  auto* p = static_cast<SavedState*>(s);
  return (p && p->tag == kStateTag) ? p : nullptr;
}

// Value of a variable as a double (start values, FMU states).
double read_as_double(ModelData& d, const Variable& v) {
  void* p = v.value(d, v.index);
  switch (v.type) {
    case VarType::Real: return *static_cast<double*>(p);
    case VarType::Integer: return static_cast<double>(*static_cast<fmi2Integer*>(p));
    case VarType::Boolean: return *static_cast<fmi2Boolean*>(p) ? 1.0 : 0.0;
  }
  return 0.0;
}

void write_from_double(ModelData& d, const Variable& v, double x) {
  void* p = v.value(d, v.index);
  switch (v.type) {
    case VarType::Real: *static_cast<double*>(p) = x; break;
    case VarType::Integer: *static_cast<fmi2Integer*>(p) = static_cast<fmi2Integer>(x); break;
    case VarType::Boolean: *static_cast<fmi2Boolean*>(p) = x != 0.0 ? fmi2True : fmi2False; break;
  }
}

}  // namespace

// ---------------------------------------------------------------- names

const char* xml_name(VarType t) {
  switch (t) {
    case VarType::Real: return "Real";
    case VarType::Integer: return "Integer";
    case VarType::Boolean: return "Boolean";
  }
  return "?";
}

const char* xml_name(Causality c) {
  switch (c) {
    case Causality::Parameter: return "parameter";
    case Causality::CalculatedParameter: return "calculatedParameter";
    case Causality::Input: return "input";
    case Causality::Output: return "output";
    case Causality::Local: return "local";
    case Causality::Independent: return "independent";
  }
  return "?";
}

const char* xml_name(Variability v) {
  switch (v) {
    case Variability::Constant: return "constant";
    case Variability::Fixed: return "fixed";
    case Variability::Tunable: return "tunable";
    case Variability::Discrete: return "discrete";
    case Variability::Continuous: return "continuous";
  }
  return "?";
}

const char* xml_name(Initial i) {
  switch (i) {
    case Initial::None: return "";
    case Initial::Exact: return "exact";
    case Initial::Approx: return "approx";
    case Initial::Calculated: return "calculated";
  }
  return "?";
}

const char* mode_name(std::uint32_t mode) {
  switch (mode) {
    case kInstantiated: return "Instantiated";
    case kInitializationMode: return "InitializationMode";
    case kStepComplete: return "StepComplete";
    case kStepInProgress: return "StepInProgress";
    case kStepFailed: return "StepFailed";
    case kStepCanceled: return "StepCanceled";
    case kTerminated: return "Terminated";
    case kError: return "Error";
    case kFatal: return "Fatal";
  }
  return "unknown";
}

// ---------------------------------------------------------------- logger

Logger::Logger(fmi2CallbackLogger logger, fmi2ComponentEnvironment env, std::string instance_name,
               bool logging_on)
    : logger_(logger), env_(env), name_(std::move(instance_name)) {
  enable_all(logging_on);
  if (!logging_on) {
    // Whatever status a call returns other than fmi2OK comes with its reason.
    enable(LogCategory::StatusWarning, true);
    enable(LogCategory::StatusDiscard, true);
    enable(LogCategory::StatusError, true);
    enable(LogCategory::StatusFatal, true);
  }
}

void Logger::enable_all(bool on) {
  for (bool& b : on_) b = on;
}

bool Logger::enabled(LogCategory c) const {
  return logger_ != nullptr &&
         (on_[static_cast<unsigned>(c)] || on_[static_cast<unsigned>(LogCategory::All)]);
}

void Logger::vlog(fmi2Status status, LogCategory c, const char* fmt, va_list args) {
  if (!enabled(c)) return;
  char small[512];
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(small, sizeof small, fmt, copy);
  va_end(copy);
  std::string text;
  if (n < 0) {
    text = fmt;
  } else if (static_cast<std::size_t>(n) < sizeof small) {
    text.assign(small, static_cast<std::size_t>(n));
  } else {
    text.resize(static_cast<std::size_t>(n) + 1);
    std::vsnprintf(&text[0], text.size(), fmt, args);
    text.resize(static_cast<std::size_t>(n));
  }
  // The importer treats the message as a printf format: escape '%'.
  std::string message;
  message.reserve(text.size());
  for (char ch : text) {
    message += ch;
    if (ch == '%') message += '%';
  }
  logger_(env_, name_.c_str(), status, kLogCategoryNames[static_cast<unsigned>(c)], message.c_str());
}

void Logger::log(fmi2Status status, LogCategory c, const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  vlog(status, c, fmt, args);
  va_end(args);
}

#define PKM_FMI_LOG_AS(method, status, category) \
  void Logger::method(const char* fmt, ...) {    \
    va_list args;                                \
    va_start(args, fmt);                         \
    vlog(status, category, fmt, args);           \
    va_end(args);                                \
  }
PKM_FMI_LOG_AS(error, fmi2Error, LogCategory::StatusError)
PKM_FMI_LOG_AS(warning, fmi2Warning, LogCategory::StatusWarning)
PKM_FMI_LOG_AS(discard, fmi2Discard, LogCategory::StatusDiscard)
PKM_FMI_LOG_AS(event, fmi2OK, LogCategory::Events)
PKM_FMI_LOG_AS(trace, fmi2OK, LogCategory::All)
#undef PKM_FMI_LOG_AS

// ---------------------------------------------------------------- state bytes

void StateWriter::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void StateWriter::u64(std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void StateWriter::f64(double v) {
  static_assert(sizeof(double) == 8, "IEEE 754 binary64 expected");
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  u64(bits);
}

bool StateReader::take(std::size_t n) {
  if (!ok_ || static_cast<std::size_t>(end_ - p_) < n) {
    ok_ = false;
    return false;
  }
  return true;
}

std::uint8_t StateReader::u8() {
  if (!take(1)) return 0;
  return *p_++;
}

std::uint32_t StateReader::u32() {
  if (!take(4)) return 0;
  const std::uint32_t v = read_le32(p_);
  p_ += 4;
  return v;
}

std::uint64_t StateReader::u64() {
  if (!take(8)) return 0;
  const std::uint64_t v = read_le64(p_);
  p_ += 8;
  return v;
}

double StateReader::f64() {
  const std::uint64_t bits = u64();
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

// ---------------------------------------------------------------- definition

const Variable* ModelDefinition::find(fmi2ValueReference vr) const {
  const Variable* end = variables + n_variables;
  const Variable* it =
      std::lower_bound(variables, end, vr, [](const Variable& v, fmi2ValueReference r) { return v.vr < r; });
  return (it != end && it->vr == vr) ? it : nullptr;
}

const Variable* ModelDefinition::find(const char* name) const {
  for (std::size_t i = 0; i < n_variables; ++i)
    if (std::strcmp(variables[i].name, name) == 0) return &variables[i];
  return nullptr;
}

// ---------------------------------------------------------------- instance

Instance::Instance(const ModelDefinition& def, Logger log)
    : tag_(kInstanceTag), def_(def), log_(std::move(log)) {}

Instance::~Instance() {
  // FMI 2.0: fmi2FreeInstance frees everything the instance allocated,
  // including FMU states the importer did not free.
  for (SavedState* s : states_) {
    *static_cast<volatile std::uint64_t*>(&s->tag) = 0;
    delete s;
  }
  *static_cast<volatile std::uint64_t*>(&tag_) = 0;  // a dangling handle is no longer taken for an instance
}

SavedState* Instance::new_state() {
  auto owned = std::make_unique<SavedState>();
  owned->owner = this;
  states_.insert(owned.get());  // may throw: then nothing leaks
  return owned.release();
}

Instance* Instance::from(fmi2Component c) {
  auto* i = static_cast<Instance*>(c);
  return (i && i->tag_ == kInstanceTag) ? i : nullptr;
}

Instance* Instance::instantiate(const ModelDefinition& def, fmi2String instance_name, int type,
                                fmi2String guid, fmi2String resource_location,
                                const fmi2CallbackFunctions* functions, fmi2Boolean visible,
                                fmi2Boolean logging_on) {
  (void)resource_location;  // no resources
  (void)visible;            // no user interface
  Logger log(functions ? functions->logger : nullptr, functions ? functions->componentEnvironment : nullptr,
             instance_name ? instance_name : "", logging_on != fmi2False);
  if (!instance_name) {
    log.error("fmi2Instantiate: instanceName is NULL");
    return nullptr;
  }
  if (type != fmi2CoSimulation) {
    log.error("fmi2Instantiate: %s is a co-simulation FMU only (fmuType = %d requested)", def.identifier,
              static_cast<int>(type));
    return nullptr;
  }
  if (!guid || std::strcmp(guid, def.guid) != 0) {
    log.error("fmi2Instantiate: GUID %s does not match this binary's %s (modelDescription.xml from another build?)",
              guid ? guid : "(NULL)", def.guid);
    return nullptr;
  }
  try {
    std::unique_ptr<Instance> inst(new Instance(def, log));
    inst->data_ = def.create();
    inst->apply_start_values();
    inst->data_->reset();
    inst->log_.trace("fmi2Instantiate(%s, GUID %s): %s", instance_name, guid, def.identifier);
    return inst.release();
  } catch (const std::exception& e) {
    log.error("fmi2Instantiate: %s", e.what());
    return nullptr;
  }
}

fmi2Status Instance::internal_error(const char* function, const char* what) {
  log_.error("%s: internal error: %s", function, what);
  mode_ = kError;
  return fmi2Error;
}

bool Instance::allowed(std::uint32_t mask, const char* function) {
  if (mode_ & mask) return true;
  log_.error("%s: not allowed in state %s (illegal call sequence); the call has no effect", function,
             mode_name(mode_));
  return false;
}

void Instance::apply_start_values() {
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.has_start()) write_from_double(*data_, v, v.start);
    if (v.derivative) *static_cast<double*>(v.derivative(*data_, v.index)) = 0.0;
  }
}

fmi2Status Instance::set_debug_logging(fmi2Boolean on, std::size_t n, const fmi2String categories[]) {
  if (!allowed(kMaskSetDebugLogging, "fmi2SetDebugLogging")) return fmi2Error;
  if (n == 0) {
    log_.enable_all(on != fmi2False);
    return fmi2OK;
  }
  if (!categories) {
    log_.error("fmi2SetDebugLogging: categories is NULL");
    return fmi2Error;
  }
  int index[kLogCategoryCount * 4];
  if (n > sizeof index / sizeof index[0]) {
    log_.error("fmi2SetDebugLogging: %zu categories given, at most %zu expected", n,
               sizeof index / sizeof index[0]);
    return fmi2Error;
  }
  for (std::size_t k = 0; k < n; ++k) {
    index[k] = -1;
    for (int c = 0; c < kLogCategoryCount; ++c)
      if (categories[k] && std::strcmp(categories[k], kLogCategoryNames[c]) == 0) index[k] = c;
    if (index[k] < 0) {
      log_.error("fmi2SetDebugLogging: unknown log category \"%s\" (known: logEvents, logStatusWarning, "
                 "logStatusDiscard, logStatusError, logStatusFatal, logAll)",
                 categories[k] ? categories[k] : "(NULL)");
      return fmi2Error;
    }
  }
  for (std::size_t k = 0; k < n; ++k) log_.enable(static_cast<LogCategory>(index[k]), on != fmi2False);
  return fmi2OK;
}

fmi2Status Instance::setup_experiment(fmi2Boolean tolerance_defined, fmi2Real tolerance, fmi2Real start_time,
                                      fmi2Boolean stop_time_defined, fmi2Real stop_time) {
  if (!allowed(kMaskSetupExperiment, "fmi2SetupExperiment")) return fmi2Error;
  log_.trace("fmi2SetupExperiment(toleranceDefined = %d, tolerance = %g, startTime = %.17g, stopTimeDefined = %d, "
             "stopTime = %.17g)",
             tolerance_defined, tolerance, start_time, stop_time_defined, stop_time);
  if (!std::isfinite(start_time)) {
    log_.error("fmi2SetupExperiment: startTime = %g is not finite", start_time);
    return fmi2Error;
  }
  if (stop_time_defined && !(stop_time >= start_time)) {
    log_.error("fmi2SetupExperiment: stopTime = %.17g lies before startTime = %.17g", stop_time, start_time);
    return fmi2Error;
  }
  if (tolerance_defined)
    log_.event("fmi2SetupExperiment: tolerance %g not used (the model's own parameters set its accuracy)",
               tolerance);
  start_time_ = start_time;
  stop_time_defined_ = stop_time_defined != fmi2False;
  stop_time_ = stop_time_defined_ ? stop_time : 0.0;
  time_ = last_successful_time_ = start_time;
  return fmi2OK;
}

fmi2Status Instance::enter_initialization_mode() {
  if (!allowed(kMaskEnterInitialization, "fmi2EnterInitializationMode")) return fmi2Error;
  mode_ = kInitializationMode;
  time_ = last_successful_time_ = start_time_;
  outputs_valid_ = false;
  log_.event("fmi2EnterInitializationMode: initialization mode at t = %.17g", start_time_);
  return fmi2OK;
}

fmi2Status Instance::exit_initialization_mode() {
  if (!allowed(kMaskExitInitialization, "fmi2ExitInitializationMode")) return fmi2Error;
  Context ctx = context();
  fmi2Status s = data_->exit_initialization(ctx);
  outputs_valid_ = false;
  if (s == fmi2OK || s == fmi2Warning) {
    mode_ = kStepComplete;
    time_ = last_successful_time_ = start_time_;
    terminated_ = false;
    log_.event("fmi2ExitInitializationMode: initialised at t = %.17g", start_time_);
    return s;
  }
  mode_ = s == fmi2Fatal ? kFatal : kError;
  return s == fmi2Fatal ? fmi2Fatal : fmi2Error;
}

fmi2Status Instance::terminate() {
  if (!allowed(kMaskTerminate, "fmi2Terminate")) return fmi2Error;
  mode_ = kTerminated;
  log_.event("fmi2Terminate at t = %.17g", time_);
  return fmi2OK;
}

fmi2Status Instance::reset() {
  if (!allowed(kMaskReset, "fmi2Reset")) return fmi2Error;
  apply_start_values();
  data_->reset();
  input_derivatives_set_ = false;
  mode_ = kInstantiated;
  start_time_ = stop_time_ = time_ = last_successful_time_ = 0.0;
  stop_time_defined_ = false;
  terminated_ = false;
  outputs_valid_ = false;
  log_.event("fmi2Reset: back to the instantiated state with the start values");
  return fmi2OK;
}

// ---------------------------------------------------------------- get / set

const Variable* Instance::lookup(const char* function, VarType type, fmi2ValueReference vr) {
  const Variable* v = def_.find(vr);
  if (!v || v->type != type) {
    log_.error("%s: unknown value reference %u (no %s variable has it)", function, static_cast<unsigned>(vr),
               xml_name(type));
    return nullptr;
  }
  return v;
}

fmi2Status Instance::ensure_outputs(const char* function) {
  if (outputs_valid_) return fmi2OK;
  Context ctx = context();
  const fmi2Status s = data_->update_outputs(ctx);
  if (s == fmi2OK || s == fmi2Warning) {
    outputs_valid_ = true;
  } else {
    log_.trace("%s: outputs not available", function);
  }
  return s;
}

template <class T>
fmi2Status Instance::get_values(const char* function, VarType type, const fmi2ValueReference vr[],
                                std::size_t n, T value[]) {
  if (!allowed(kMaskGet, function)) return fmi2Error;
  if (n == 0) return fmi2OK;
  if (!vr || !value) {
    log_.error("%s: NULL value reference or value array", function);
    return fmi2Error;
  }
  bool computed = false;
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(function, type, vr[k]);
    if (!v) return fmi2Error;
    computed = computed || v->computed();
  }
  fmi2Status s = fmi2OK;
  if (computed) {
    s = ensure_outputs(function);
    if (s != fmi2OK && s != fmi2Warning) return s;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = def_.find(vr[k]);
    value[k] = *static_cast<T*>(v->value(*data_, v->index));
  }
  return s;
}

template <class T>
fmi2Status Instance::set_values(const char* function, VarType type, const fmi2ValueReference vr[],
                                std::size_t n, const T value[]) {
  if (!allowed(kMaskSet, function)) return fmi2Error;
  if (n == 0) return fmi2OK;
  if (!vr || !value) {
    log_.error("%s: NULL value reference or value array", function);
    return fmi2Error;
  }
  // Check everything first: a rejected call changes nothing.
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(function, type, vr[k]);
    if (!v) return fmi2Error;
    if (!v->stored_in_state() || v->variability == Variability::Constant) {
      log_.error("%s: %s (value reference %u) is a %s %s variable and cannot be set", function, v->name,
                 static_cast<unsigned>(v->vr), xml_name(v->variability), xml_name(v->causality));
      return fmi2Error;
    }
    if (v->causality == Causality::Parameter && v->variability == Variability::Fixed &&
        !(mode_ & (kInstantiated | kInitializationMode))) {
      log_.error("%s: %s is a fixed parameter: it can only be set before fmi2ExitInitializationMode", function,
                 v->name);
      return fmi2Error;
    }
    if constexpr (std::is_same<T, fmi2Real>::value) {
      if (!std::isfinite(value[k])) {
        log_.error("%s: %s = %g is not finite; value rejected", function, v->name, value[k]);
        return fmi2Error;
      }
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = def_.find(vr[k]);
    void* p = v->value(*data_, v->index);
    if (type == VarType::Boolean) {
      *static_cast<T*>(p) = value[k] != 0 ? fmi2True : fmi2False;
    } else {
      *static_cast<T*>(p) = value[k];
    }
    // A derivative refers to the value it was given with.
    if (v->derivative) *static_cast<double*>(v->derivative(*data_, v->index)) = 0.0;
    if (log_.enabled(LogCategory::All))
      log_.trace("%s: %s = %.17g", function, v->name, static_cast<double>(value[k]));
  }
  outputs_valid_ = false;
  return fmi2OK;
}

fmi2Status Instance::get_real(const fmi2ValueReference vr[], std::size_t n, fmi2Real value[]) {
  return get_values("fmi2GetReal", VarType::Real, vr, n, value);
}
fmi2Status Instance::get_integer(const fmi2ValueReference vr[], std::size_t n, fmi2Integer value[]) {
  return get_values("fmi2GetInteger", VarType::Integer, vr, n, value);
}
fmi2Status Instance::get_boolean(const fmi2ValueReference vr[], std::size_t n, fmi2Boolean value[]) {
  return get_values("fmi2GetBoolean", VarType::Boolean, vr, n, value);
}
fmi2Status Instance::set_real(const fmi2ValueReference vr[], std::size_t n, const fmi2Real value[]) {
  return set_values("fmi2SetReal", VarType::Real, vr, n, value);
}
fmi2Status Instance::set_integer(const fmi2ValueReference vr[], std::size_t n, const fmi2Integer value[]) {
  return set_values("fmi2SetInteger", VarType::Integer, vr, n, value);
}
fmi2Status Instance::set_boolean(const fmi2ValueReference vr[], std::size_t n, const fmi2Boolean value[]) {
  return set_values("fmi2SetBoolean", VarType::Boolean, vr, n, value);
}

fmi2Status Instance::get_string(const fmi2ValueReference vr[], std::size_t n, fmi2String value[]) {
  if (!allowed(kMaskGet, "fmi2GetString")) return fmi2Error;
  (void)value;
  if (n == 0) return fmi2OK;
  log_.error("fmi2GetString: unknown value reference %u (this FMU has no String variables)",
             vr ? static_cast<unsigned>(vr[0]) : 0u);
  return fmi2Error;
}

fmi2Status Instance::set_string(const fmi2ValueReference vr[], std::size_t n, const fmi2String value[]) {
  if (!allowed(kMaskSet, "fmi2SetString")) return fmi2Error;
  (void)value;
  if (n == 0) return fmi2OK;
  log_.error("fmi2SetString: unknown value reference %u (this FMU has no String variables)",
             vr ? static_cast<unsigned>(vr[0]) : 0u);
  return fmi2Error;
}

// ---------------------------------------------------------------- FMU states

void Instance::save(std::vector<unsigned char>& out) const {
  out.clear();
  StateWriter w(out);
  for (unsigned char c : kMagic) w.u8(c);
  w.u32(kFormatVersion);
  w.u32(0);
  w.u64(0);  // total size, patched below
  w.u64(fnv1a(def_.guid));
  // Generic part.
  w.u32(mode_);
  w.u8(stop_time_defined_ ? 1 : 0);
  w.u8(terminated_ ? 1 : 0);
  w.f64(start_time_);
  w.f64(stop_time_);
  w.f64(time_);
  w.f64(last_successful_time_);
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < def_.n_variables; ++i)
    count += (def_.variables[i].stored_in_state() ? 1u : 0u) + (def_.variables[i].derivative ? 1u : 0u);
  w.u32(count);
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.stored_in_state()) continue;
    if (v.type == VarType::Real) {
      w.f64(*static_cast<double*>(v.value(*data_, v.index)));
    } else {
      w.i64(static_cast<std::int64_t>(read_as_double(*data_, v)));
    }
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.derivative) w.f64(*static_cast<double*>(v.derivative(*data_, v.index)));
  }
  // The model's part.
  data_->save(w);
  write_le64(out.data() + 16, out.size() + kTrailerSize);
  w.u64(fnv1a(out.data(), out.size()));
}

bool Instance::check_header(const unsigned char* bytes, std::size_t size, const char* function) {
  if (!bytes || size < kHeaderSize + kTrailerSize || std::memcmp(bytes, kMagic, sizeof kMagic) != 0) {
    log_.error("%s: not a serialised FMU state of this FMU (size %zu, no magic number)", function, size);
    return false;
  }
  const std::uint32_t version = read_le32(bytes + 8);
  if (version != kFormatVersion) {
    log_.error("%s: FMU state format version %u, this FMU reads version %u", function, version, kFormatVersion);
    return false;
  }
  if (read_le64(bytes + 16) != size) {
    log_.error("%s: FMU state of %zu bytes says it has %llu", function, size,
               static_cast<unsigned long long>(read_le64(bytes + 16)));
    return false;
  }
  if (read_le64(bytes + 24) != fnv1a(def_.guid)) {
    log_.error("%s: the FMU state belongs to another FMU (GUID differs from %s)", function, def_.guid);
    return false;
  }
  if (read_le64(bytes + size - kTrailerSize) != fnv1a(bytes, size - kTrailerSize)) {
    log_.error("%s: FMU state corrupted (checksum mismatch)", function);
    return false;
  }
  return true;
}

bool Instance::load(const std::vector<unsigned char>& bytes, const char* function) {
  if (!check_header(bytes.data(), bytes.size(), function)) return false;
  StateReader r(bytes.data() + kHeaderSize, bytes.size() - kHeaderSize - kTrailerSize);
  const std::uint32_t mode = r.u32();
  const bool stop_defined = r.u8() != 0;
  const bool terminated = r.u8() != 0;
  const double start_time = r.f64();
  const double stop_time = r.f64();
  const double time = r.f64();
  const double last_time = r.f64();
  const std::uint32_t count = r.u32();
  std::uint32_t expected = 0;
  for (std::size_t i = 0; i < def_.n_variables; ++i)
    expected += (def_.variables[i].stored_in_state() ? 1u : 0u) + (def_.variables[i].derivative ? 1u : 0u);
  if (!r.ok() || count != expected || !(mode & kRestorableModes) || (mode & (mode - 1)) != 0) {
    log_.error("%s: malformed FMU state (mode %u, %u values where %u expected)", function, mode, count, expected);
    return false;
  }
  // Read every value before changing anything.
  std::vector<double> values;
  values.reserve(count);
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.stored_in_state()) continue;
    if (v.type == VarType::Real) {
      values.push_back(r.f64());
    } else {
      const std::int64_t x = r.i64();
      if (x < INT32_MIN || x > INT32_MAX) {
        log_.error("%s: malformed FMU state (%s = %lld)", function, v.name, static_cast<long long>(x));
        return false;
      }
      values.push_back(static_cast<double>(x));
    }
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i)
    if (def_.variables[i].derivative) values.push_back(r.f64());
  if (!r.ok()) {
    log_.error("%s: malformed FMU state (truncated)", function);
    return false;
  }
  for (double x : values) {
    if (!std::isfinite(x)) {
      log_.error("%s: malformed FMU state (a non-finite value)", function);
      return false;
    }
  }
  // Commit, keeping a copy of the current state to fall back to.
  std::vector<unsigned char> backup;
  save(backup);
  std::size_t k = 0;
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.stored_in_state()) write_from_double(*data_, v, values[k++]);
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.derivative) *static_cast<double*>(v.derivative(*data_, v.index)) = values[k++];
  }
  input_derivatives_set_ = true;  // the restored state may carry derivatives
  mode_ = mode;
  stop_time_defined_ = stop_defined;
  terminated_ = terminated;
  start_time_ = start_time;
  stop_time_ = stop_time;
  time_ = time;
  last_successful_time_ = last_time;
  outputs_valid_ = false;
  data_->reset();
  Context ctx = context();
  const bool ok = data_->load(r, ctx) && r.ok() && r.at_end();
  if (ok) return true;
  log_.error("%s: the FMU state cannot be restored; the previous state is kept", function);
  if (!load(backup, function)) mode_ = kError;  // cannot happen: the backup was just written
  return false;
}

fmi2Status Instance::get_fmu_state(fmi2FMUstate* state) {
  if (!allowed(kMaskFmuState, "fmi2GetFMUstate")) return fmi2Error;
  if (!state) {
    log_.error("fmi2GetFMUstate: FMUstate is NULL");
    return fmi2Error;
  }
  SavedState* s = nullptr;
  if (*state) {
    s = as_state(*state);
    if (!s) {
      log_.error("fmi2GetFMUstate: *FMUstate is neither NULL nor an FMU state of this FMU");
      return fmi2Error;
    }
  } else {
    s = new_state();
    *state = s;
  }
  save(s->bytes);
  log_.event("fmi2GetFMUstate: state saved at t = %.17g (%zu bytes)", time_, s->bytes.size());
  return fmi2OK;
}

fmi2Status Instance::set_fmu_state(fmi2FMUstate state) {
  if (!allowed(kMaskFmuState, "fmi2SetFMUstate")) return fmi2Error;
  SavedState* s = as_state(state);
  if (!s) {
    log_.error("fmi2SetFMUstate: not an FMU state of this FMU");
    return fmi2Error;
  }
  if (!load(s->bytes, "fmi2SetFMUstate")) return fmi2Error;
  log_.event("fmi2SetFMUstate: state restored at t = %.17g (%s)", time_, mode_name(mode_));
  return fmi2OK;
}

fmi2Status Instance::free_fmu_state(fmi2FMUstate* state) {
  if (!allowed(kMaskFmuState, "fmi2FreeFMUstate")) return fmi2Error;
  if (!state || !*state) return fmi2OK;
  SavedState* s = as_state(*state);
  if (!s) {
    log_.error("fmi2FreeFMUstate: not an FMU state of this FMU");
    return fmi2Error;
  }
  if (s->owner) s->owner->forget_state(s);  // freed through another instance of this FMU: its creator forgets it
  *static_cast<volatile std::uint64_t*>(&s->tag) = 0;
  delete s;
  *state = nullptr;
  return fmi2OK;
}

fmi2Status Instance::serialized_fmu_state_size(fmi2FMUstate state, std::size_t* size) {
  if (!allowed(kMaskFmuState, "fmi2SerializedFMUstateSize")) return fmi2Error;
  SavedState* s = as_state(state);
  if (!s || !size) {
    log_.error("fmi2SerializedFMUstateSize: %s", size ? "not an FMU state of this FMU" : "size is NULL");
    return fmi2Error;
  }
  *size = s->bytes.size();
  return fmi2OK;
}

fmi2Status Instance::serialize_fmu_state(fmi2FMUstate state, fmi2Byte bytes[], std::size_t size) {
  if (!allowed(kMaskFmuState, "fmi2SerializeFMUstate")) return fmi2Error;
  SavedState* s = as_state(state);
  if (!s || !bytes) {
    log_.error("fmi2SerializeFMUstate: %s", bytes ? "not an FMU state of this FMU" : "serializedState is NULL");
    return fmi2Error;
  }
  if (size < s->bytes.size()) {
    log_.error("fmi2SerializeFMUstate: buffer of %zu bytes, %zu needed (fmi2SerializedFMUstateSize)", size,
               s->bytes.size());
    return fmi2Error;
  }
  std::memcpy(bytes, s->bytes.data(), s->bytes.size());
  return fmi2OK;
}

fmi2Status Instance::deserialize_fmu_state(const fmi2Byte bytes[], std::size_t size, fmi2FMUstate* state) {
  if (!allowed(kMaskFmuState, "fmi2DeSerializeFMUstate")) return fmi2Error;
  if (!state) {
    log_.error("fmi2DeSerializeFMUstate: FMUstate is NULL");
    return fmi2Error;
  }
  const auto* p = reinterpret_cast<const unsigned char*>(bytes);
  if (!check_header(p, size, "fmi2DeSerializeFMUstate")) return fmi2Error;
  std::vector<unsigned char> copy(p, p + size);
  SavedState* s = new_state();
  s->bytes.swap(copy);
  *state = s;
  return fmi2OK;
}

fmi2Status Instance::get_directional_derivative(const fmi2ValueReference[], std::size_t,
                                                const fmi2ValueReference[], std::size_t, const fmi2Real[],
                                                fmi2Real[]) {
  if (!allowed(kMaskGet, "fmi2GetDirectionalDerivative")) return fmi2Error;
  log_.error("fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative = false)");
  return fmi2Error;
}

// ---------------------------------------------------------------- co-simulation

fmi2Status Instance::set_real_input_derivatives(const fmi2ValueReference vr[], std::size_t n,
                                                const fmi2Integer order[], const fmi2Real value[]) {
  static const char* const fn = "fmi2SetRealInputDerivatives";
  if (!allowed(kMaskInputDerivatives, fn)) return fmi2Error;
  if (!def_.can_interpolate_inputs) {
    log_.error("%s: %s does not interpolate inputs (canInterpolateInputs = false)", fn, def_.identifier);
    return fmi2Error;
  }
  if (n == 0) return fmi2OK;
  if (!vr || !order || !value) {
    log_.error("%s: NULL argument", fn);
    return fmi2Error;
  }
  bool higher = false;
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(fn, VarType::Real, vr[k]);
    if (!v) return fmi2Error;
    if (!v->derivative) {
      log_.error("%s: %s is not a continuous Real input", fn, v->name);
      return fmi2Error;
    }
    if (order[k] < 1) {
      log_.error("%s: derivative order %d of %s must be at least 1", fn, static_cast<int>(order[k]), v->name);
      return fmi2Error;
    }
    if (!std::isfinite(value[k])) {
      log_.error("%s: derivative of %s = %g is not finite; rejected", fn, v->name, value[k]);
      return fmi2Error;
    }
    higher = higher || order[k] > 1;
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (order[k] != 1) continue;
    const Variable* v = def_.find(vr[k]);
    *static_cast<double*>(v->derivative(*data_, v->index)) = value[k];
    input_derivatives_set_ = true;
    if (log_.enabled(LogCategory::All)) log_.trace("%s: d%s/dt = %.17g", fn, v->name, value[k]);
  }
  if (higher) {
    log_.warning("%s: derivatives of order 2 and higher ignored (inputs are interpolated linearly)", fn);
    return fmi2Warning;
  }
  return fmi2OK;
}

fmi2Status Instance::get_real_output_derivatives(const fmi2ValueReference[], std::size_t, const fmi2Integer[],
                                                 fmi2Real[]) {
  if (!allowed(kMaskOutputDerivatives, "fmi2GetRealOutputDerivatives")) return fmi2Error;
  log_.error("fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder = 0)");
  return fmi2Error;
}

fmi2Status Instance::do_step(fmi2Real t, fmi2Real h, fmi2Boolean no_set_fmu_state_prior) {
  if (!allowed(kMaskDoStep, "fmi2DoStep")) return fmi2Error;
  (void)no_set_fmu_state_prior;
  if (log_.enabled(LogCategory::All)) log_.trace("fmi2DoStep(%.17g, %.17g)", t, h);
  if (!std::isfinite(h) || !(h > 0.0)) {
    log_.error("fmi2DoStep: communicationStepSize = %g must be positive and finite; the call has no effect", h);
    return fmi2Error;
  }
  const double tolerance = 1e-9 * std::max(1.0, std::abs(time_));
  if (!std::isfinite(t) || std::abs(t - time_) > tolerance) {
    log_.error("fmi2DoStep: currentCommunicationPoint = %.17g differs from the FMU's time %.17g; the call has no "
               "effect",
               t, time_);
    return fmi2Error;
  }
  if (!std::isfinite(t + h)) {
    log_.error("fmi2DoStep: currentCommunicationPoint + communicationStepSize = %g is not finite; the call has no "
               "effect",
               t + h);
    return fmi2Error;
  }
  // Inputs interpolated with their derivatives must stay finite over the step
  // (only once a derivative was ever set: the loop is not free).
  for (std::size_t i = 0; input_derivatives_set_ && i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.derivative) continue;
    const double u = *static_cast<double*>(v.value(*data_, v.index));
    const double du = *static_cast<double*>(v.derivative(*data_, v.index));
    if (!std::isfinite(u + du * h)) {
      log_.error("fmi2DoStep: input %s extrapolated with its derivative %g to t = %.17g is not finite; the call has "
                 "no effect",
                 v.name, du, t + h);
      return fmi2Error;
    }
  }
  // FMI 2.0, fmi2SetupExperiment: computing past a defined stopTime is an error.
  if (stop_time_defined_ && t + h > stop_time_ + 1e-9 * std::max(1.0, std::abs(stop_time_))) {
    log_.error("fmi2DoStep: the step to t = %.17g would pass stopTime = %.17g (fmi2SetupExperiment); the call has "
               "no effect",
               t + h, stop_time_);
    return fmi2Error;
  }
  Context ctx = context();
  double reached = time_;
  const fmi2Status s = data_->do_step(ctx, t, h, reached);
  outputs_valid_ = false;
  switch (s) {
    case fmi2OK:
    case fmi2Warning:
      time_ = last_successful_time_ = t + h;
      return s;
    case fmi2Discard:
      time_ = last_successful_time_ = reached;
      terminated_ = true;
      mode_ = kStepFailed;
      return s;
    case fmi2Fatal:
      mode_ = kFatal;
      return s;
    default:
      last_successful_time_ = reached;
      mode_ = kError;
      return fmi2Error;
  }
}

fmi2Status Instance::cancel_step() {
  if (!allowed(kMaskCancelStep, "fmi2CancelStep")) return fmi2Error;
  return fmi2Error;  // unreachable: fmi2DoStep never returns fmi2Pending
}

fmi2Status Instance::get_status(int kind, fmi2Status* value) {
  if (!allowed(kMaskStatus, "fmi2GetStatus")) return fmi2Error;
  if (!value) {
    log_.error("fmi2GetStatus: value is NULL");
    return fmi2Error;
  }
  if (kind == fmi2DoStepStatus) {
    *value = fmi2OK;  // fmi2DoStep is synchronous: never pending
    return fmi2OK;
  }
  return fmi2Discard;
}

fmi2Status Instance::get_real_status(int kind, fmi2Real* value) {
  if (!allowed(kMaskStatus, "fmi2GetRealStatus")) return fmi2Error;
  if (!value) {
    log_.error("fmi2GetRealStatus: value is NULL");
    return fmi2Error;
  }
  if (kind == fmi2LastSuccessfulTime) {
    *value = last_successful_time_;
    return fmi2OK;
  }
  return fmi2Discard;
}

fmi2Status Instance::get_integer_status(int, fmi2Integer* value) {
  if (!allowed(kMaskStatus, "fmi2GetIntegerStatus")) return fmi2Error;
  (void)value;
  return fmi2Discard;  // no integer status is defined for FMI 2.0 co-simulation
}

fmi2Status Instance::get_boolean_status(int kind, fmi2Boolean* value) {
  if (!allowed(kMaskStatus, "fmi2GetBooleanStatus")) return fmi2Error;
  if (!value) {
    log_.error("fmi2GetBooleanStatus: value is NULL");
    return fmi2Error;
  }
  if (kind == fmi2Terminated) {
    *value = terminated_ ? fmi2True : fmi2False;
    return fmi2OK;
  }
  return fmi2Discard;
}

fmi2Status Instance::get_string_status(int, fmi2String* value) {
  if (!allowed(kMaskStatus, "fmi2GetStringStatus")) return fmi2Error;
  (void)value;
  return fmi2Discard;  // fmi2PendingStatus: never pending
}

}  // namespace pkm_fmi
