// SPDX-License-Identifier: BSD-2-Clause
// Model Exchange: the importer integrates the continuous states; the model
// gives their derivatives and its event indicators.
#include <algorithm>
#include <cmath>

#include "fmi/instance.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {

Status Instance::enter_event_mode() {
  const char* fn = PKM_FN(EnterEventMode);
  if (!allowed(Call::EnterEventMode, fn)) return Status::Error;
  if (past_stop_time(fn, time_, "an event")) return Status::Error;
  mode_ = kEventMode;
  time_floor_ = std::max(time_floor_, time_);  // no going back past an event
  log_.event("%s at t = %.17g", fn, time_);
  return Status::OK;
}

Status Instance::event_update(bool* discrete_states_need_update, bool* terminate, bool* nominals_changed,
                              bool* values_changed, bool* next_event_time_defined, double* next_event_time) {
  const char* fn = PKM_FN2(fmi2NewDiscreteStates, fmi3UpdateDiscreteStates);
  if (!allowed(Call::EventUpdate, fn)) return Status::Error;
  Context ctx = context();
  bool stop = false;
  const Status s = data_->event_update(ctx, stop);
  valid_groups_ = 0;
  if (discrete_states_need_update) *discrete_states_need_update = false;
  if (terminate) *terminate = stop;
  if (nominals_changed) *nominals_changed = false;
  // A tunable parameter set in this Event Mode may have changed the states
  // (ModelData::tune): the importer reads them again.
  if (values_changed) *values_changed = states_changed_;
  states_changed_ = false;
  if (next_event_time_defined) *next_event_time_defined = false;
  if (next_event_time) *next_event_time = 0.0;
  if (s == Status::Error) mode_ = kError;
  if (s == Status::Fatal) mode_ = kFatal;
  return s;
}

Status Instance::enter_continuous_time_mode() {
  const char* fn = PKM_FN(EnterContinuousTimeMode);
  if (!allowed(Call::EnterContinuousTimeMode, fn)) return Status::Error;
  mode_ = kContinuousTimeMode;
  states_changed_ = false;
  return Status::OK;
}

Status Instance::completed_integrator_step(bool* enter_event_mode, bool* terminate) {
  const char* fn = PKM_FN(CompletedIntegratorStep);
  if (!allowed(Call::CompletedIntegratorStep, fn)) return Status::Error;
  if (past_stop_time(fn, time_, "the integrator step accepted")) return Status::Error;
  if (enter_event_mode) *enter_event_mode = false;  // no step events: the indicators locate every event
  if (terminate) *terminate = false;
  return Status::OK;
}

Status Instance::set_time(double t) {
  const char* fn = PKM_FN(SetTime);
  if (!allowed(Call::SetTime, fn)) return Status::Error;
  // FMI 2.0.4 3.2.3, condition 8: in Event Mode "only for a Pure
  // Discrete-Time FMU", one without continuous states.
  if (mode_ == kEventMode && def_.n_states > 0) {
    log_.error("%s: not allowed in state %s for an FMU with continuous states (only a pure discrete-time FMU sets "
               "the time in Event Mode); the call has no effect",
               fn, mode_name(mode_));
    return Status::Error;
  }
  if (!std::isfinite(t)) {
    log_.error("%s: time = %g is not finite; the call has no effect", fn, t);
    return Status::Error;
  }
  // FMI 3.0.2 3.2.1: time >= startTime and the time of the last
  // EnterEventMode (FMI 2.0.4 3.2.2 alike: no going back past an event). The
  // third bound, the second last CompletedIntegratorStep, is not enforced:
  // importers locating roots (fmpy with CVODE) go back over several of them
  // within one internal step, and nothing in this model depends on it. No
  // upper bound in Continuous-Time Mode: a trial evaluation past stopTime
  // computes nothing that is kept (past_stop_time, instance.cpp); in Event
  // Mode (FMI 2.0, a pure discrete-time FMU) the time is the next event's.
  if (mode_ == kEventMode && past_stop_time(fn, t, "the event")) return Status::Error;
  if (t < time_floor_) {
    log_.error("%s: time = %.17g lies before %.17g (%s); the call has no effect", fn, t, time_floor_,
               time_floor_ == start_time_ ? "startTime"
                                          : "the last event: the FMU cannot go back past it");
    return Status::Error;
  }
  time_ = t;
  data_->set_time(t - start_time_);
  valid_groups_ = 0;
  return Status::OK;
}

bool Instance::array_call_allowed(Call call, const char* fn, const char* what, std::size_t given,
                                  std::size_t expected, const void* array) {
  if (!allowed(call, fn)) return false;
  if (given != expected) {
    log_.error("%s: %llu %s given, this FMU has %llu; the call has no effect", fn,
               static_cast<unsigned long long>(given), what, static_cast<unsigned long long>(expected));
    return false;
  }
  if (!array && given > 0) {
    log_.error("%s: NULL array", fn);
    return false;
  }
  return true;
}

Status Instance::set_continuous_states(const double x[], std::size_t n) {
  const char* fn = PKM_FN(SetContinuousStates);
  if (!array_call_allowed(Call::SetContinuousStates, fn, "states", n, def_.n_states, x)) return Status::Error;
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(x[k])) {
      log_.error("%s: state %llu = %g is not finite; the states are unchanged", fn, static_cast<unsigned long long>(k),
                 x[k]);
      return Status::Error;
    }
  }
  Context ctx = context();
  const Status s = data_->set_states(ctx, x);
  valid_groups_ = 0;
  return s;
}

Status Instance::get_continuous_states(double x[], std::size_t n) {
  const char* fn = PKM_FN(GetContinuousStates);
  if (!array_call_allowed(Call::GetContinuousStates, fn, "states", n, def_.n_states, x)) return Status::Error;
  Context ctx = context();
  return data_->get_states(ctx, x);
}

Status Instance::get_derivatives(double dx[], std::size_t n) {
  const char* fn = PKM_FN2(fmi2GetDerivatives, fmi3GetContinuousStateDerivatives);
  if (!array_call_allowed(Call::GetDerivatives, fn, "derivatives", n, def_.n_states, dx)) return Status::Error;
  Context ctx = context();
  return data_->get_derivatives(ctx, dx);
}

Status Instance::get_event_indicators(double z[], std::size_t n) {
  const char* fn = PKM_FN(GetEventIndicators);
  if (!array_call_allowed(Call::GetEventIndicators, fn, "event indicators", n, def_.n_event_indicators, z))
    return Status::Error;
  Context ctx = context();
  return data_->get_event_indicators(ctx, z);
}

Status Instance::get_nominals(double x[], std::size_t n) {
  const char* fn = PKM_FN2(fmi2GetNominalsOfContinuousStates, fmi3GetNominalsOfContinuousStates);
  if (!array_call_allowed(Call::GetNominals, fn, "nominals", n, def_.n_states, x)) return Status::Error;
  for (std::size_t k = 0; k < def_.n_variables; ++k)
    if (def_.variables[k].state >= 0) x[def_.variables[k].state] = def_.variables[k].nominal;
  return Status::OK;
}

Status Instance::get_number_of(const char* what, std::size_t count, std::size_t* n) {
  if (!allowed(Call::GetNumberOf, what)) return Status::Error;
  if (!n) {
    log_.error("%s: NULL argument", what);
    return Status::Error;
  }
  *n = count;
  return Status::OK;
}

}  // namespace pkm_fmi
