// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/instance.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "fmi/fmu_state.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {
namespace {

constexpr std::uint64_t kInstanceTag2 = 0x49324d464d4b5002ull;  // marks a live FMI 2.0 Instance
constexpr std::uint64_t kInstanceTag3 = 0x49334d464d4b5002ull;  // marks a live FMI 3.0 Instance

std::uint64_t tag_of(int version) { return version == 2 ? kInstanceTag2 : kInstanceTag3; }

}  // namespace

const char* mode_name(std::uint32_t mode) {
  switch (mode) {
    case kInstantiated: return "Instantiated";
    case kInitializationMode: return "InitializationMode";
    case kEventMode: return "EventMode";
    case kContinuousTimeMode: return "ContinuousTimeMode";
    case kStepMode: return "StepMode";
    case kStepFailed: return "StepFailed";
    case kTerminated: return "Terminated";
    case kError: return "Error";
    case kFatal: return "Fatal";
  }
  return "unknown";
}

Instance::Instance(const ModelDefinition& def, int fmi_version, Interface interface, Logger log)
    : tag_(tag_of(fmi_version)), def_(def), token_(def.guid()), version_(fmi_version), interface_(interface), log_(std::move(log)) {
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    if (!def_.variables[i].derivative) continue;
    if (derivatives_end_ == 0) derivatives_begin_ = i;
    derivatives_end_ = i + 1;
  }
}

Instance::~Instance() {
  // FreeInstance frees everything the instance allocated, including FMU
  // states the importer did not free.
  for (SavedState* s : states_) destroy_state(s);
  *static_cast<volatile std::uint64_t*>(&tag_) = 0;  // a dangling handle is no longer taken for an instance
}

Instance* Instance::from(void* handle, const ModelDefinition& def, int fmi_version) {
  auto* i = static_cast<Instance*>(handle);
  // The definition's address tells this model's instances from another FMU's
  // (another binary loaded in the same process has its own definitions).
  return (i && i->tag_ == tag_of(fmi_version) && &i->def_ == &def) ? i : nullptr;
}

Instance* Instance::create(const ModelDefinition& def, int fmi_version, Interface interface, const char* token,
                           Logger log) {
  const char* fn = fmi_version == 2 ? "fmi2Instantiate" : interface == Interface::ModelExchange
                                                              ? "fmi3InstantiateModelExchange"
                                                              : "fmi3InstantiateCoSimulation";
  const std::string expected = def.guid();
  if (!token || expected != token) {
    log.error("%s: %s %s does not match this binary's %s (modelDescription.xml from another build?)", fn,
              fmi_version == 2 ? "GUID" : "instantiationToken", token ? token : "(NULL)", expected.c_str());
    return nullptr;
  }
  std::unique_ptr<Instance> inst(new Instance(def, fmi_version, interface, std::move(log)));
  inst->data_ = def.create();
  inst->address_.resize(def.n_variables);
  for (std::size_t i = 0; i < def.n_variables; ++i) {
    const Variable& v = def.variables[i];
    inst->address_[i] = v.value ? v.value(*inst->data_, v.index) : nullptr;
  }
  inst->apply_start_values();
  inst->data_->reset();
  inst->log_.call("%s(%s, %s): %s, %s", fn, inst->log_.instance_name().c_str(), token, def.identifier,
                  interface_name(interface));
  return inst.release();
}

Status Instance::internal_error(const char* function, const char* what) {
  log_.error("%s: internal error: %s", function, what);
  mode_ = kError;
  return Status::Error;
}

void Instance::free(void* handle, const ModelDefinition& def, int fmi_version, const char* function) {
  Instance* inst = from(handle, def, fmi_version);
  if (!inst) return;
  // Not Busy: its destructor would clear the flag of a deleted instance.
  if (inst->busy_.exchange(true, std::memory_order_acquire)) {
    inst->concurrent_call(function);  // logged; the instance is not freed
    return;
  }
  delete inst;
}

Status Instance::concurrent_call(const char* function) {
  log_.error("%s: called while another call on this instance is running (from another thread?): an instance must "
             "be used by one thread at a time; the call has no effect",
             function);
  return Status::Error;
}

Status Instance::not_supported(const char* function, const char* why) {
  if (!allowed(Call::NotProvided, function)) return Status::Error;
  log_.error("%s: not supported by %s: %s; the call has no effect", function, def_.identifier, why);
  return Status::Error;
}

bool Instance::allowed(Call call, const char* function) {
  const CallRule& rule = call_rule(call);
  const unsigned mine = interface_ == Interface::ModelExchange ? kForME : kForCS;
  if (!(rule.interfaces & mine)) {
    log_.error("%s: a %s function, not allowed on this instance, instantiated for %s; the call has no effect",
               function, interface_name(interface_ == Interface::ModelExchange ? Interface::CoSimulation
                                                                               : Interface::ModelExchange),
               interface_name(interface_));
    return false;
  }
  if (mode_ & allowed_states(call, version_)) return true;
  log_.error("%s: not allowed in state %s (illegal call sequence); the call has no effect", function,
             mode_name(mode_));
  return false;
}

void Instance::apply_start_values() {
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.has_start() && v.value) write_from_double(*data_, v, v.start);
    if (v.derivative) *static_cast<double*>(v.derivative(*data_, v.index)) = 0.0;
  }
}

Status Instance::set_debug_logging(bool on, std::size_t n, const char* const categories[]) {
  const char* fn = PKM_FN(SetDebugLogging);
  if (!allowed(Call::SetDebugLogging, fn)) return Status::Error;
  if (n == 0) {
    log_.set_default(on);
    return Status::OK;
  }
  if (!categories) {
    log_.error("%s: categories is NULL", fn);
    return Status::Error;
  }
  // Check every name before changing anything.
  bool named[kLogCategoryCount] = {};
  for (std::size_t k = 0; k < n; ++k) {
    const int c = log_category(categories[k]);
    if (c < 0) {
      log_.error("%s: unknown log category \"%s\" (known: logEvents, logStatusWarning, logStatusDiscard, "
                 "logStatusError, logStatusFatal, logCalls); nothing changed",
                 fn, categories[k] ? categories[k] : "(NULL)");
      return Status::Error;
    }
    named[c] = true;
  }
  log_.select(named, on);
  return Status::OK;
}

Status Instance::setup_experiment(bool tolerance_defined, double tolerance, double start_time,
                                  bool stop_time_defined, double stop_time) {
  const char* fn = version_ == 2 ? "fmi2SetupExperiment" : "fmi3EnterInitializationMode";
  if (!allowed(Call::SetupExperiment, fn)) return Status::Error;
  log_.call("%s(toleranceDefined = %d, tolerance = %g, startTime = %.17g, stopTimeDefined = %d, stopTime = %.17g)",
            fn, tolerance_defined, tolerance, start_time, stop_time_defined, stop_time);
  if (!std::isfinite(start_time)) {
    log_.error("%s: startTime = %g is not finite", fn, start_time);
    return Status::Error;
  }
  if (stop_time_defined && !(stop_time >= start_time)) {
    log_.error("%s: stopTime = %.17g lies before startTime = %.17g", fn, stop_time, start_time);
    return Status::Error;
  }
  if (tolerance_defined)
    log_.event("%s: tolerance %g not used (the parameters rtol and atol set CVODE's accuracy)", fn,
               tolerance);
  start_time_ = start_time;
  stop_time_defined_ = stop_time_defined;
  stop_time_ = stop_time_defined_ ? stop_time : 0.0;
  time_ = last_successful_time_ = start_time;
  return Status::OK;
}

// "If the environment tries to compute past stopTime, the FMU has to return
// Error" (FMI 2.0.4 2.1.6, FMI 3.0.2 2.3.2): asked by what advances the
// simulation (DoStep, CompletedIntegratorStep's "accepted values", an event),
// not by an integrator's trial evaluations in Continuous-Time Mode, which it
// may go back over (FMI 3.0.2 2.2.6, 3.2.1). docs/importers.md, "stopTime".
bool Instance::past_stop_time(const char* fn, double t, const char* what) {
  if (!stop_time_defined_ || !(t > stop_time_ + 1e-9 * std::max(1.0, std::abs(stop_time_)))) return false;
  log_.error("%s: %s at t = %.17g lies past stopTime = %.17g (computing past a defined stopTime is an error); the "
             "call has no effect",
             fn, what, t, stop_time_);
  return true;
}

Status Instance::enter_initialization_mode() {
  const char* fn = PKM_FN(EnterInitializationMode);
  if (!allowed(Call::EnterInitializationMode, fn)) return Status::Error;
  mode_ = kInitializationMode;
  time_ = last_successful_time_ = start_time_;
  elapsed_ = 0.0;
  valid_groups_ = 0;
  data_->set_time(0.0);
  log_.event("%s: initialization mode at t = %.17g", fn, start_time_);
  return Status::OK;
}

Status Instance::exit_initialization_mode() {
  const char* fn = PKM_FN(ExitInitializationMode);
  if (!allowed(Call::ExitInitializationMode, fn)) return Status::Error;
  Context ctx = context();
  const Status s = data_->exit_initialization(ctx);
  valid_groups_ = 0;
  if (succeeded(s)) {
    reserve_state_buffers();
    mode_ = interface_ == Interface::CoSimulation ? kStepMode : kEventMode;
    time_ = last_successful_time_ = time_floor_ = start_time_;
    elapsed_ = 0.0;
    terminated_ = false;
    log_.event("%s: initialised at t = %.17g, now in %s", fn, start_time_, mode_name(mode_));
    return s;
  }
  // Refused (the parameters cannot be used, reason logged): nothing changed,
  // still in initialization mode, where the parameters can be corrected.
  if (s == Status::Fatal) mode_ = kFatal;
  return s == Status::Fatal ? Status::Fatal : Status::Error;
}

Status Instance::terminate() {
  const char* fn = PKM_FN(Terminate);
  if (!allowed(Call::Terminate, fn)) return Status::Error;
  mode_ = kTerminated;
  log_.event("%s at t = %.17g", fn, time_);
  return Status::OK;
}

Status Instance::reset() {
  const char* fn = PKM_FN(Reset);
  if (!allowed(Call::Reset, fn)) return Status::Error;
  apply_start_values();
  data_->reset();
  input_derivatives_set_ = false;
  states_changed_ = false;
  mode_ = kInstantiated;
  start_time_ = stop_time_ = time_ = last_successful_time_ = elapsed_ = time_floor_ = 0.0;
  stop_time_defined_ = false;
  terminated_ = false;
  valid_groups_ = 0;
  log_.event("%s: back to the instantiated state with the start values", fn);
  return Status::OK;
}

}  // namespace pkm_fmi
