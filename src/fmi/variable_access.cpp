// SPDX-License-Identifier: BSD-2-Clause
// Get and set through the variable table.
#include <cmath>
#include <type_traits>
#include <vector>

#include "fmi/instance.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {

// A get or set looks each value reference up once: the first this many
// (every control tick's) are kept on the stack, beyond them found again.
constexpr std::size_t kFoundCache = 32;

const Variable* Instance::unknown_reference(const char* function, VarType type, std::uint32_t vr) {
  log_.error("%s: unknown value reference %u (no %s variable has it)", function, static_cast<unsigned>(vr),
             version_ == 2 ? fmi2_type_name(type) : fmi3_type_name(type));
  return nullptr;
}

Status Instance::ensure_outputs(const char* function, unsigned needed) {
  const unsigned missing = needed & ~valid_groups_;
  if (!missing) return Status::OK;
  Context ctx = context();
  const Status s = data_->update_outputs(ctx, missing);
  if (succeeded(s)) {
    valid_groups_ |= missing;
  } else {
    log_.call("%s: outputs not available", function);
  }
  return s;
}

template <class T>
Status Instance::get_values(const char* function, VarType type, const std::uint32_t vr[], std::size_t n,
                            T value[]) {
  if (!allowed(Call::Get, function)) return Status::Error;
  if (n == 0) return Status::OK;
  if (!vr || !value) {
    log_.error("%s: NULL value reference or value array", function);
    return Status::Error;
  }
  unsigned needed = 0;  // the output groups this call reads
  const Variable* found[kFoundCache];  // the first loop's look-ups, reused by the second
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(function, type, vr[k]);
    if (!v) return Status::Error;
    if (k < kFoundCache) found[k] = v;
    // Before initialisation only start values exist (FMI 3.0.2 2.3.2).
    if (mode_ == kInstantiated && !v->has_start()) {
      log_.error("%s: %s has no start value: it is computed from %s on; the call has no effect", function, v->name,
                 PKM_FN(EnterInitializationMode));
      return Status::Error;
    }
    if (v->computed()) needed |= v->group;
  }
  Status s = Status::OK;
  if (needed) {
    // Discard: the inputs lie outside the model's domain (reason logged);
    // the computed variables keep the values of the last good evaluation.
    s = ensure_outputs(function, needed);
    if (s == Status::Error || s == Status::Fatal) return s;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = k < kFoundCache ? found[k] : def_.find(vr[k]);
    value[k] = v->causality == Causality::Independent ? static_cast<T>(time_) : *static_cast<T*>(address(v));
  }
  return s;
}

template <class T>
Status Instance::set_values(const char* function, VarType type, const std::uint32_t vr[], std::size_t n,
                            const T value[]) {
  if (!allowed(type == VarType::Real ? Call::Set : Call::SetNonReal, function)) return Status::Error;
  if (n == 0) return Status::OK;
  if (!vr || !value) {
    log_.error("%s: NULL value reference or value array", function);
    return Status::Error;
  }
  // Continuous states (the outputs that are states) are set by value
  // reference in Model Exchange's Event and Continuous-Time Modes, as
  // SetContinuousStates sets them (FMI 2.0.4 state table, footnote on
  // fmi2SetReal; FMI 3.0.2 §3.2.1, §2.3.5), and nowhere else.
  const bool states_settable = interface_ == Interface::ModelExchange && (mode_ & kSetStatesByReference);
  bool sets_states = false;
  // Check everything first: a rejected call changes nothing.
  const Variable* found[kFoundCache];  // the checks' look-ups, reused to write
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(function, type, vr[k]);
    if (!v) return Status::Error;
    if (k < kFoundCache) found[k] = v;
    const bool as_state = states_settable && v->state >= 0 && v->value;
    sets_states = sets_states || as_state;
    if (!as_state && (!v->stored_in_state() || v->variability == Variability::Constant || !v->value)) {
      log_.error("%s: %s (value reference %u) is a %s %s variable and cannot be set", function, v->name,
                 static_cast<unsigned>(v->vr), xml_name(v->variability), xml_name(v->causality));
      return Status::Error;
    }
    if (v->causality == Causality::Parameter && v->variability == Variability::Fixed &&
        !(mode_ & (kInstantiated | kInitializationMode))) {
      log_.error("%s: %s is a fixed parameter: it can only be set before %s", function, v->name,
                 PKM_FN(ExitInitializationMode));
      return Status::Error;
    }
    // A tunable parameter changes at an event or a communication point, never
    // while the importer integrates: not in Continuous-Time Mode (FMI 2.0.4
    // 3.2.3, fmi2SetReal's conditions 4 and 5; FMI 3.0.2 2.4.7.4 and 3.2.1).
    if (v->causality == Causality::Parameter && v->variability == Variability::Tunable &&
        mode_ == kContinuousTimeMode) {
      log_.error("%s: %s is a tunable parameter: in Model Exchange it can be set in Event Mode (%s), not in "
                 "Continuous-Time Mode",
                 function, v->name, PKM_FN(EnterEventMode));
      return Status::Error;
    }
    const double x = static_cast<double>(value[k]);
    if (std::is_floating_point<T>::value && !std::isfinite(x)) {
      log_.error("%s: %s = %g is not finite; value rejected", function, v->name, x);
      return Status::Error;
    }
    if (!(x >= v->min && x <= v->max)) {
      log_.error("%s: %s = %.17g lies outside its range [%.17g, %.17g]%s%s; value rejected", function, v->name, x,
                 v->min, v->max, *v->unit ? " " : "", v->unit);
      return Status::Error;
    }
  }
  Context ctx = context();
  if (sets_states) {  // all at once, as SetContinuousStates: refused (Discard, Error) with nothing changed
    double fixed[32];  // no allocation for the models' few states
    std::vector<double> more(def_.n_states > 32 ? def_.n_states : 0);
    double* x = more.empty() ? fixed : more.data();
    Status s = data_->get_states(ctx, x);
    for (std::size_t k = 0; k < n && s == Status::OK; ++k) {
      const Variable* v = def_.find(vr[k]);
      if (v->state >= 0) x[static_cast<std::size_t>(v->state)] = static_cast<double>(value[k]);
    }
    if (s == Status::OK) s = data_->set_states(ctx, x);
    valid_groups_ = 0;
    if (s != Status::OK) return s;
  }
  const bool log_calls = log_.enabled(LogCategory::Calls);
  bool tuned = false;  // a tunable parameter set while running: the model takes it at once
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = k < kFoundCache ? found[k] : def_.find(vr[k]);
    if (sets_states && v->state >= 0) {
      if (log_calls) log_.call("%s: %s = %.17g (state)", function, v->name, static_cast<double>(value[k]));
      continue;
    }
    tuned = tuned || (v->causality == Causality::Parameter && v->variability == Variability::Tunable &&
                      (mode_ & (kEventMode | kStepMode)));
    void* p = address(v);
    if (type == VarType::Boolean) {
      *static_cast<T*>(p) = value[k] != 0 ? 1 : 0;
    } else {
      *static_cast<T*>(p) = value[k];
    }
    // A derivative refers to the value it was given with.
    if (v->derivative) *static_cast<double*>(v->derivative(*data_, v->index)) = 0.0;
    if (log_calls) log_.call("%s: %s = %.17g", function, v->name, static_cast<double>(value[k]));
  }
  valid_groups_ = 0;
  if (tuned) {
    bool states_changed = false;
    const Status s = data_->tune(ctx, function, states_changed);
    if (s != Status::OK) return s;
    states_changed_ = states_changed_ || states_changed;
  }
  return Status::OK;
}

Status Instance::get_real(const std::uint32_t vr[], std::size_t n, double value[]) {
  return get_values(PKM_FN2(fmi2GetReal, fmi3GetFloat64), VarType::Real, vr, n, value);
}
Status Instance::get_integer(const std::uint32_t vr[], std::size_t n, std::int32_t value[]) {
  return get_values(PKM_FN2(fmi2GetInteger, fmi3GetInt32), VarType::Integer, vr, n, value);
}
Status Instance::get_boolean(const std::uint32_t vr[], std::size_t n, int value[]) {
  return get_values(PKM_FN(GetBoolean), VarType::Boolean, vr, n, value);
}
Status Instance::set_real(const std::uint32_t vr[], std::size_t n, const double value[]) {
  return set_values(PKM_FN2(fmi2SetReal, fmi3SetFloat64), VarType::Real, vr, n, value);
}
Status Instance::set_integer(const std::uint32_t vr[], std::size_t n, const std::int32_t value[]) {
  return set_values(PKM_FN2(fmi2SetInteger, fmi3SetInt32), VarType::Integer, vr, n, value);
}
Status Instance::set_boolean(const std::uint32_t vr[], std::size_t n, const int value[]) {
  return set_values(PKM_FN(SetBoolean), VarType::Boolean, vr, n, value);
}

Status Instance::no_variables_of_type(const char* function, const char* type, const std::uint32_t vr[],
                                      std::size_t n, bool setter) {
  if (!allowed(setter ? Call::SetNonReal : Call::Get, function)) return Status::Error;
  if (n == 0) return Status::OK;
  log_.error("%s: unknown value reference %u (this FMU has no %s variables)", function,
             vr ? static_cast<unsigned>(vr[0]) : 0u, type);
  return Status::Error;
}

}  // namespace pkm_fmi
