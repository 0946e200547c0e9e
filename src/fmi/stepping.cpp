// SPDX-License-Identifier: BSD-2-Clause
// Co-Simulation: communication steps, input interpolation, step status.
#include <algorithm>
#include <cmath>

#include "fmi/instance.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {

Status Instance::set_real_input_derivatives(const std::uint32_t vr[], std::size_t n, const std::int32_t order[],
                                            const double value[]) {
  static const char* const fn = "fmi2SetRealInputDerivatives";
  if (!allowed(Call::InputDerivatives, fn)) return Status::Error;
  if (!def_.can_interpolate_inputs) {
    log_.error("%s: %s does not interpolate inputs (canInterpolateInputs = false)", fn, def_.identifier);
    return Status::Error;
  }
  if (n == 0) return Status::OK;
  if (!vr || !order || !value) {
    log_.error("%s: NULL argument", fn);
    return Status::Error;
  }
  bool higher = false;
  for (std::size_t k = 0; k < n; ++k) {
    const Variable* v = lookup(fn, VarType::Real, vr[k]);
    if (!v) return Status::Error;
    if (!v->derivative) {
      log_.error("%s: %s is not a continuous Real input", fn, v->name);
      return Status::Error;
    }
    if (order[k] < 1) {
      log_.error("%s: derivative order %d of %s must be at least 1", fn, static_cast<int>(order[k]), v->name);
      return Status::Error;
    }
    if (!std::isfinite(value[k])) {
      log_.error("%s: derivative of %s = %g is not finite; rejected", fn, v->name, value[k]);
      return Status::Error;
    }
    higher = higher || order[k] > 1;
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (order[k] != 1) continue;
    const Variable* v = def_.find(vr[k]);
    *static_cast<double*>(v->derivative(*data_, v->index)) = value[k];
    input_derivatives_set_ = true;
    if (log_.enabled(LogCategory::Calls)) log_.call("%s: d%s/dt = %.17g", fn, v->name, value[k]);
  }
  if (higher) {
    log_.warning("%s: derivatives of order 2 and higher ignored (inputs are interpolated linearly)", fn);
    return Status::Warning;
  }
  return Status::OK;
}

Status Instance::get_real_output_derivatives(const char* function) {
  if (!allowed(Call::OutputDerivatives, function)) return Status::Error;
  log_.error("%s: not provided (maxOutputDerivativeOrder = 0)", function);
  return Status::Error;
}

Status Instance::do_step(double t, double h, bool* terminate, double* last_successful) {
  const char* fn = PKM_FN(DoStep);
  if (!allowed(Call::DoStep, fn)) return Status::Error;
  if (log_.enabled(LogCategory::Calls)) log_.call("%s(%.17g, %.17g)", fn, t, h);
  if (!std::isfinite(h) || !(h > 0.0)) {
    log_.error("%s: communicationStepSize = %g must be positive and finite; the call has no effect", fn, h);
    return Status::Error;
  }
  const double tolerance = 1e-9 * std::max(1.0, std::abs(time_));
  if (!std::isfinite(t) || std::abs(t - time_) > tolerance) {
    log_.error("%s: currentCommunicationPoint = %.17g differs from the FMU's time %.17g; the call has no effect",
               fn, t, time_);
    return Status::Error;
  }
  if (!std::isfinite(t + h)) {
    log_.error("%s: currentCommunicationPoint + communicationStepSize = %g is not finite; the call has no effect",
               fn, t + h);
    return Status::Error;
  }
  if (t + h == t) {
    log_.error("%s: communicationStepSize = %.17g vanishes at currentCommunicationPoint = %.17g (t + h == t in "
               "double precision): nothing would advance; the call has no effect",
               fn, h, t);
    return Status::Error;
  }
  // Inputs interpolated with their derivatives must stay finite over the step
  // (only once a derivative was ever set: the loop is not free).
  for (std::size_t i = derivatives_begin_; input_derivatives_set_ && i < derivatives_end_; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.derivative) continue;
    const double u = *static_cast<double*>(v.value(*data_, v.index));
    const double du = *static_cast<double*>(v.derivative(*data_, v.index));
    if (!std::isfinite(u + du * h)) {
      log_.error("%s: input %s extrapolated with its derivative %g to t = %.17g is not finite; the call has no "
                 "effect",
                 fn, v.name, du, t + h);
      return Status::Error;
    }
  }
  if (past_stop_time(fn, t + h, "the end of the communication step")) return Status::Error;
  Context ctx = context();
  if (data_->check_step(ctx, h) != Status::OK) return Status::Error;
  // FMI 3.0.2 4.2.3: a Discard leaves the FMU in the state before the call.
  // The model keeps only its last good point (RK4: the last whole step), so
  // the state at the call is kept here (a buffer sized at initialisation).
  const bool rollback = version_ == 3 && data_->step_has_effects();
  if (rollback) save(step_start_);
  // The model integrates from elapsed_ by h; the reported time follows the
  // master's t + h.
  double reached = elapsed_;
  const Status s = data_->do_step(ctx, elapsed_, h, reached);
  valid_groups_ = 0;
  switch (s) {
    case Status::OK:
    case Status::Warning:
      elapsed_ += h;
      time_ = last_successful_time_ = t + h;
      break;
    case Status::Discard:
      if (version_ == 3) {
        // Back to the state at the call, still in Step Mode: the importer may
        // retry with other inputs or a shorter step.
        if (rollback && !load(step_start_.data(), step_start_.size(), fn, false)) {
          mode_ = kError;
          return Status::Error;
        }
        log_.discard("%s: the step from t = %.17g was discarded; the FMU is back in the state at the call (t = "
                     "%.17g), still in Step Mode: retry with other inputs or a shorter step",
                     fn, t, time_);
        break;
      }
      // FMI 2.0.4 4.2.3: fmi2DoStep returned fmi2Discard: StepFailed, the
      // state at fmi2LastSuccessfulTime, fmi2Terminated = true.
      time_ = last_successful_time_ = t + (reached - elapsed_);  // t itself when nothing was reached
      elapsed_ = reached;
      terminated_ = true;
      mode_ = kStepFailed;
      break;
    case Status::Fatal:
      mode_ = kFatal;
      break;
    case Status::Error:
      last_successful_time_ = t + (reached - elapsed_);
      mode_ = kError;
      break;
  }
  if (terminate) *terminate = terminated_;
  if (last_successful) *last_successful = last_successful_time_;
  return s;
}

Status Instance::last_successful_time(double* t) {
  const char* fn = "fmi2GetRealStatus";
  if (!allowed(Call::StepStatus, fn)) return Status::Error;
  if (!t) {
    log_.error("%s: value is NULL", fn);
    return Status::Error;
  }
  *t = last_successful_time_;
  return Status::OK;
}

Status Instance::terminated(bool* t) {
  const char* fn = "fmi2GetBooleanStatus";
  if (!allowed(Call::StepStatus, fn)) return Status::Error;
  if (!t) {
    log_.error("%s: value is NULL", fn);
    return Status::Error;
  }
  *t = terminated_;
  return Status::OK;
}

Status Instance::not_pending(const char* function) {
  if (!allowed(Call::StepStatus, function)) return Status::Error;
  return Status::Discard;  // fmi2DoStep is synchronous: no status of a pending step
}

}  // namespace pkm_fmi
