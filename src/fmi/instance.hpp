// SPDX-License-Identifier: BSD-2-Clause
// One FMU instance, whatever the FMI version: the state machine, and every
// FMI function as a method over the model's table and hooks. The thin front
// ends (fmi2_functions.cpp, fmi3_functions.cpp) translate the C calls.
//
// Error policy (docs/robustness.md, "Error policy"): every check runs before anything
// changes. A call with wrong arguments or in the wrong state, parameters
// that cannot be used (ExitInitializationMode: the instance stays in
// initialization mode, where they can be corrected), a step beyond the work
// budget or an FMU state that cannot be used returns Error with a logged
// message and has no effect: the instance stays as it was and usable. Only
// a failure in the middle of a computation (a step failed beyond recovery,
// an internal error) puts the instance in the Error state: then only get,
// reset, free and the FMU state functions are allowed (SetFMUState may
// return to a saved good state). A step that cannot be completed returns
// Discard with the state kept at the last good time; a get whose inputs lie
// outside the model's domain returns Discard with the last good outputs.
//
// Implementation, one concern per file: instance.cpp (creation, state
// machine, initialisation, termination, reset, logging setup),
// variable_access.cpp (get/set), fmu_state.cpp (FMU states and their
// serialisation), stepping.cpp (Co-Simulation), model_exchange.cpp.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "fmi/fmi_status.hpp"
#include "fmi/logger.hpp"
#include "fmi/model_data.hpp"
#include "fmi/variables.hpp"

/// The name of an FMI function in this instance's version, for messages
/// (inside Instance methods): PKM_FN(DoStep) is "fmi2DoStep" or "fmi3DoStep".
#define PKM_FN(name) (version_ == 2 ? "fmi2" #name : "fmi3" #name)
/// Where the two versions spell a name differently: PKM_FN2(fmi2GetFMUstate, fmi3GetFMUState).
#define PKM_FN2(name2, name3) (version_ == 2 ? #name2 : #name3)

namespace pkm_fmi {

/// The states of the FMI 2.0 and 3.0 state machines that this FMU enters
/// (bit masks). CS: StepComplete (2.0) = Step Mode (3.0).
enum Mode : std::uint32_t {
  kInstantiated = 1u << 0,
  kInitializationMode = 1u << 1,
  kEventMode = 1u << 2,           // Model Exchange
  kContinuousTimeMode = 1u << 3,  // Model Exchange
  kStepMode = 1u << 4,            // Co-Simulation
  kStepFailed = 1u << 5,          // Co-Simulation, after a Discard
  kTerminated = 1u << 6,
  kError = 1u << 7,
  kFatal = 1u << 8,
};
const char* mode_name(std::uint32_t mode);
/// The states in which the model runs: Model Exchange's Event and Continuous-Time Modes, Co-Simulation's Step Mode.
constexpr std::uint32_t kRunning = kEventMode | kContinuousTimeMode | kStepMode;
/// The states past a successful ExitInitializationMode, Error aside: the model is built.
constexpr std::uint32_t kInitializedModes = kRunning | kStepFailed | kTerminated;

struct SavedState;  // fmu_state.cpp
enum class Call : unsigned;  // state_machine.hpp

class Instance {
 public:
  /// nullptr on failure (the reason logged through `log`).
  static Instance* create(const ModelDefinition& def, int fmi_version, Interface interface, const char* token,
                          Logger log);
  /// The instance behind a handle, nullptr if it is not a live instance of
  /// this model created through this FMI version.
  static Instance* from(void* handle, const ModelDefinition& def, int fmi_version);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  // ---- lifecycle (instance.cpp)
  Status set_debug_logging(bool on, std::size_t n, const char* const categories[]);
  /// FMI 2.0's fmi2SetupExperiment; FMI 3.0 passes the same to enter_initialization_mode.
  Status setup_experiment(bool tolerance_defined, double tolerance, double start_time, bool stop_time_defined,
                          double stop_time);
  Status enter_initialization_mode();
  Status exit_initialization_mode();
  Status terminate();
  Status reset();

  // ---- variables (variable_access.cpp)
  Status get_real(const std::uint32_t vr[], std::size_t n, double value[]);
  Status get_integer(const std::uint32_t vr[], std::size_t n, std::int32_t value[]);
  Status get_boolean(const std::uint32_t vr[], std::size_t n, int value[]);
  Status set_real(const std::uint32_t vr[], std::size_t n, const double value[]);
  Status set_integer(const std::uint32_t vr[], std::size_t n, const std::int32_t value[]);
  Status set_boolean(const std::uint32_t vr[], std::size_t n, const int value[]);
  /// A getter or setter of a type this model has no variables of.
  Status no_variables_of_type(const char* function, const char* type, const std::uint32_t vr[], std::size_t n,
                              bool setter);

  // ---- FMU states (fmu_state.cpp)
  Status get_fmu_state(void** state);
  Status set_fmu_state(void* state);
  Status free_fmu_state(void** state);
  Status serialized_fmu_state_size(void* state, std::size_t* size);
  Status serialize_fmu_state(void* state, unsigned char bytes[], std::size_t size);
  Status deserialize_fmu_state(const unsigned char bytes[], std::size_t size, void** state);

  // ---- Co-Simulation (stepping.cpp)
  Status set_real_input_derivatives(const std::uint32_t vr[], std::size_t n, const std::int32_t order[],
                                    const double value[]);
  Status get_real_output_derivatives(const char* function);
  Status do_step(double t, double h, bool* terminate, double* last_successful_time);
  Status last_successful_time(double* t);
  Status terminated(bool* t);
  Status not_pending(const char* function);

  // ---- Model Exchange (model_exchange.cpp)
  Status enter_event_mode();
  Status event_update(bool* discrete_states_need_update, bool* terminate, bool* nominals_changed,
                      bool* values_changed, bool* next_event_time_defined, double* next_event_time);
  Status enter_continuous_time_mode();
  Status completed_integrator_step(bool* enter_event_mode, bool* terminate);
  Status set_time(double t);
  Status set_continuous_states(const double x[], std::size_t n);
  Status get_continuous_states(double x[], std::size_t n);
  Status get_derivatives(double dx[], std::size_t n);
  Status get_event_indicators(double z[], std::size_t n);
  Status get_nominals(double x[], std::size_t n);
  Status get_number_of(const char* what, std::size_t count, std::size_t* n);

  // ---- partial derivatives (directional_derivatives.cpp)
  /// fmi2/fmi3GetDirectionalDerivative (adjoint = false: sensitivity =
  /// J seed) and fmi3GetAdjointDerivative (adjoint = true: sensitivity =
  /// J^T seed), J = d(unknowns)/d(knowns). n_seed and n_sensitivity as FMI
  /// 3.0 passes them (FMI 2.0: the counts they must have).
  Status partial_derivative(const char* function, bool adjoint, const std::uint32_t unknowns[], std::size_t nu,
                            const std::uint32_t knowns[], std::size_t nk, const double seed[], std::size_t n_seed,
                            double sensitivity[], std::size_t n_sensitivity);

  // ---- not provided
  Status not_supported(const char* function, const char* why);

  /// Turns an exception escaping a method into Error (never across the C ABI).
  Status internal_error(const char* function, const char* what);

  /// One call at a time: FMI does not allow an instance to be used from two
  /// threads at once. A call that finds another one running answers
  /// concurrent_call() (Error, no effect) instead of racing it.
  class Busy {
   public:
    explicit Busy(Instance& i) : i_(i), entered_(!i.busy_.exchange(true, std::memory_order_acquire)) {}
    ~Busy() {
      if (entered_) i_.busy_.store(false, std::memory_order_release);
    }
    Busy(const Busy&) = delete;
    Busy& operator=(const Busy&) = delete;
    explicit operator bool() const { return entered_; }

   private:
    Instance& i_;
    bool entered_;
  };
  Status concurrent_call(const char* function);

  /// fmi2FreeInstance / fmi3FreeInstance: deletes the instance behind
  /// `handle`, unless a call on it is running on another thread; then it logs
  /// the misuse and leaves the instance alive (a leak, not a use after free).
  static void free(void* handle, const ModelDefinition& def, int fmi_version, const char* function);

  const ModelDefinition& definition() const { return def_; }
  std::uint32_t mode() const { return mode_; }
  Interface interface() const { return interface_; }
  double time() const { return time_; }
  Logger& logger() { return log_; }
  /// "fmi2" or "fmi3": the prefix of function names in messages.
  const char* prefix() const { return version_ == 2 ? "fmi2" : "fmi3"; }
  int version() const { return version_; }

 private:
  Instance(const ModelDefinition& def, int fmi_version, Interface interface, Logger log);

  /// The call's row of the state table (state_machine.hpp) for this
  /// instance's FMI version and interface; false (logged) refuses the call.
  bool allowed(Call call, const char* function);
  /// allowed() for a Model Exchange array get or set, then its length
  /// (given, of what) against this FMU's and the array not NULL; false
  /// (logged) refuses the call.
  bool array_call_allowed(Call call, const char* fn, const char* what, std::size_t given,
                          std::size_t expected, const void* array);
  /// Whether `t` lies past a defined stopTime (beyond rounding: 1e-9
  /// relative); if so logs "fn: <what> at t = .. lies past stopTime" and the
  /// caller refuses the call with Error and no effect. Asked only by the
  /// calls that advance the simulation (instance.cpp says which and why).
  bool past_stop_time(const char* fn, double t, const char* what);
  Context context() {
    return Context{log_, interface_, mode_ == kInitializationMode, start_time_, (mode_ & kInitializedModes) != 0,
                   elapsed_};
  }
  void apply_start_values();
  /// Brings the output groups `needed` up to date (those not already).
  Status ensure_outputs(const char* function, unsigned needed);
  template <class T>
  Status get_values(const char* function, VarType type, const std::uint32_t vr[], std::size_t n, T value[]);
  template <class T>
  Status set_values(const char* function, VarType type, const std::uint32_t vr[], std::size_t n, const T value[]);
  /// The variable of this type with this value reference (inline: every
  /// value of every get and set), else nullptr with unknown_reference's error.
  const Variable* lookup(const char* function, VarType type, std::uint32_t vr) {
    const Variable* v = def_.find(vr);
    if (v && v->type == type && (v->value || v->causality == Causality::Independent)) return v;
    return unknown_reference(function, type, vr);
  }
  const Variable* unknown_reference(const char* function, VarType type, std::uint32_t vr);

  SavedState* new_state();
  /// allowed(Call::FmuState) and the FMU state argument: the saved state,
  /// or NULL (logged) to refuse the call, also when the call's output out,
  /// named out_name, is NULL (out_name NULL: the call has no output).
  SavedState* state_argument(const char* fn, void* state, const void* out = nullptr,
                             const char* out_name = nullptr);
  void save(std::vector<unsigned char>& out) const;
  bool check_header(const unsigned char* bytes, std::size_t size, const char* function);
  /// The mode and fmi2Terminated of a state being loaded: ones this
  /// instance's version and interface can be in together (else logged).
  bool modes_consistent(std::uint32_t mode, bool terminated, const char* function);
  /// The times of a state being loaded: finite and in order (else logged).
  bool times_consistent(std::uint32_t mode, double start, bool stop_defined, double stop, double time,
                        double last_successful, double elapsed, const char* function);
  /// Restores a serialised state; keep_backup: on failure return to the
  /// current state (saved into load_backup_ first).
  bool load(const unsigned char* bytes, std::size_t size, const char* function, bool keep_backup);
  /// The buffers save() and load() reuse so that SetFMUState allocates
  /// nothing once initialised (sized at instantiation and initialisation).
  void reserve_state_buffers();

  std::uint64_t tag_;  // identifies a live Instance of this version behind a handle
  const ModelDefinition& def_;
  std::string token_;  // def_.guid()
  int version_;
  Interface interface_;
  Logger log_;
  std::unique_ptr<ModelData> data_;
  // Each variable's value (its Ref asked once, at instantiation; nullptr
  // without one), by table index: get and set call no Ref per value.
  std::vector<void*> address_;
  void* address(const Variable* v) const { return address_[static_cast<std::size_t>(v - def_.variables)]; }
  std::uint32_t mode_ = kInstantiated;
  double start_time_ = 0.0;
  double stop_time_ = 0.0;
  bool stop_time_defined_ = false;
  double time_ = 0.0;                   // current time (CS: communication point)
  // Time since startTime, the model's time: summed from the step sizes, so
  // that the motion does not depend on startTime (at 1e9 s, t + 1 ms rounds
  // to 0.12 us: 7e-5 s lost over 1 s when the model integrated t + h - t).
  double elapsed_ = 0.0;
  double last_successful_time_ = 0.0;   // CS
  double time_floor_ = 0.0;  // ME: the earliest time SetTime may go to (startTime, the last EnterEventMode)
  bool terminated_ = false;             // CS: set after a discarded step
  unsigned valid_groups_ = 0;           // output groups (Variable::group) up to date
  bool input_derivatives_set_ = false;  // SetRealInputDerivatives was used (or a state restored)
  bool states_changed_ = false;  // ME: a tunable parameter set in this Event Mode changed the continuous states
  // The table's variables with an input derivative lie in [derivatives_begin_,
  // derivatives_end_) (do_step checks only these, every step).
  std::size_t derivatives_begin_ = 0, derivatives_end_ = 0;
  std::unordered_set<SavedState*> states_;  // FMU states this instance created and nobody freed yet
  std::atomic<bool> busy_{false};           // a call is running (Busy)
  // partial_derivative's buffers (kept to reuse their capacity).
  std::vector<const Variable*> d_unknowns_, d_knowns_, d_asked_;
  std::vector<std::size_t> d_rows_;
  std::vector<double> d_jacobian_, d_asked_jacobian_;
  // load()'s buffers (reserve_state_buffers).
  std::vector<double> load_values_;
  std::vector<unsigned char> load_backup_;
  std::vector<unsigned char> step_start_;  // FMI 3.0 DoStep: the state at the call, restored on Discard

 public:
  /// Forgets a state freed through any instance (FreeFMUState).
  void forget_state(SavedState* s) { states_.erase(s); }
};

}  // namespace pkm_fmi
