// SPDX-License-Identifier: BSD-2-Clause
// The contract between the generic FMI layer and a model (Reference-FMUs'
// model.h, in C++): the per-instance data the variable table points into,
// and the hooks the FMI functions call. A model knows nothing of FMI
// versions; the layer knows nothing of mechanics.
#pragma once

#include <cstddef>
#include <cstdint>

#include "fmi/fmi_status.hpp"
#include "fmi/logger.hpp"
#include "fmi/state_bytes.hpp"

namespace pkm_fmi {

struct Variable;

/// What a hook may see of its instance.
struct Context {
  Logger& log;
  Interface interface;
  bool initialization_mode;  // between Enter- and ExitInitializationMode
  double start_time;  // the model's time is the time since this
  bool initialized = false;  // past a successful ExitInitializationMode (not in Error): the model is built
  double model_time = 0.0;   // Co-Simulation: the time since start_time, summed from the steps taken
};

/// Per-instance data of a model. Start values are written through the
/// table by the layer; parameters, inputs and input derivatives are saved in
/// FMU states by the layer too.
class ModelData {
 public:
  virtual ~ModelData() = default;
  /// After instantiation and reset, once the start values are written:
  /// forget everything derived (solvers, caches).
  virtual void reset() = 0;
  /// ExitInitializationMode: build the model from the parameters and set the
  /// initial state at model time 0 (= ctx.start_time). Error with a logged
  /// message if impossible. Every time the layer passes to a model is the
  /// time since ctx.start_time.
  virtual Status exit_initialization(Context& ctx) = 0;
  /// Writes the computed variables of the output groups `groups` (bits of
  /// Variable::group) for the current time, state, parameters and inputs.
  /// Called lazily, before a get that reads them, once per group until
  /// anything changes; a model may write more than it is asked for. Discard
  /// (reason logged): the inputs lie outside the model's domain, the
  /// computed variables are left as they were and the get hands those out.
  virtual Status update_outputs(Context& ctx, unsigned groups) = 0;
  /// The model's state beyond the table's values. Saving is an observation:
  /// a run with GetFMUState before every step is the run without.
  virtual void save(StateWriter& w) const = 0;
  /// Reads what save() wrote, after the table's values and the instance's
  /// mode and times were restored (ctx tells them); false (with a logged
  /// message) if the state cannot be used or is none the instance can be in.
  virtual bool load(StateReader& r, Context& ctx) = 0;
  /// Tunable parameters were set while running (Co-Simulation's Step Mode,
  /// Model Exchange's Event Mode): take their new values into the running
  /// model. states_changed: the continuous states changed with them (Model
  /// Exchange's next event update says so). Error (logged): nothing changed,
  /// and the table holds the values in effect again.
  virtual Status tune(Context& ctx, const char* function, bool& states_changed) {
    (void)ctx, (void)function;
    states_changed = false;
    return Status::OK;
  }

  // ---- Co-Simulation
  /// From t to t + h (t is the current time). On return t_reached is the last
  /// time the state is valid for: t + h for OK, the last good point for Discard.
  virtual Status do_step(Context& ctx, double t, double h, double& t_reached) = 0;
  /// Whether do_step may change anything but the time or answer Discard: if
  /// not (an algebraic model), FMI 3.0's DoStep need not save the state at
  /// the call to go back to.
  virtual bool step_has_effects() const { return true; }
  /// Before do_step, nothing changed yet: Error (reason logged) if a step of
  /// h would exceed the model's work budget or is too short for its
  /// integrator to start. The instance stays usable.
  virtual Status check_step(Context& ctx, double h) const { (void)ctx, (void)h; return Status::OK; }

  // ---- Model Exchange (models without states keep the defaults)
  virtual void set_time(double t) { (void)t; }
  virtual Status get_states(Context& ctx, double x[]) { (void)ctx, (void)x; return Status::OK; }
  /// New states from the importer's integrator: Discard (state unchanged,
  /// reason logged) if they cannot be used.
  virtual Status set_states(Context& ctx, const double x[]) { (void)ctx, (void)x; return Status::OK; }
  virtual Status get_derivatives(Context& ctx, double dx[]) { (void)ctx, (void)dx; return Status::OK; }
  virtual Status get_event_indicators(Context& ctx, double z[]) { (void)ctx, (void)z; return Status::OK; }
  /// Event mode: the discrete reaction to what the indicators located.
  /// terminate = true asks the importer to stop (with a logged reason).
  virtual Status event_update(Context& ctx, bool& terminate) { (void)ctx; terminate = false; return Status::OK; }

  // ---- Partial derivatives (directional_derivatives.cpp; models whose
  // definition sets provides_derivatives)
  /// d(unknowns[i])/d(knowns[j]) at the current time, state and inputs into
  /// J[i * nk + j]. The layer has checked the references (each unknown an
  /// output or a state derivative, each known a continuous state or an
  /// input) and asks only about unknowns that depend on one of the knowns.
  /// Error with a logged message naming an unknown it cannot differentiate.
  virtual Status partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                                     const Variable* const knowns[], std::size_t nk, double J[]) {
    (void)unknowns, (void)nu, (void)knowns, (void)nk, (void)J;
    ctx.log.error("partial derivatives are not provided by this model");
    return Status::Error;
  }
};

}  // namespace pkm_fmi
