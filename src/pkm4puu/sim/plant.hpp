// SPDX-License-Identifier: BSD-2-Clause
// Forward-dynamics simulation of the mechanism: the state, the solver
// settings and the integrators around state_derivative(). One Plant per
// simulated machine; no global state, so instances are independent.
#pragma once

#include <string>

#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/integrators/cvode_integrator.hpp"
#include "pkm4puu/kinematics/theta1_continuity.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "pkm4puu/sim/input_signal.hpp"
#include "pkm4puu/sim/solver_memory.hpp"
#include "pkm4puu/sim/solver_settings.hpp"

namespace pkm {

/// The fastest the platform can move: |dx|, |dy|, |dz| and 0.1 m * |dphi|
/// at most 1e3 m/s, a fifth of the speed of sound in steel (a rigid-body
/// model of a 0.1 m machine means nothing faster). Checked with the
/// singularity guards: a step ending faster is undone (SolverFailure), an
/// initial velocity or a restored state faster is refused.
constexpr double kMaxSpeed = 1e3;

/// The running integrals of the plant's energy audit (J), integrated with
/// the motion by the same integrator: kinetic + potential - actuator_work +
/// dissipated stays constant.
struct EnergyIntegrals {
  double actuator_work = 0;  // of (F_i + (2 pi/p) tau_i) rhod_i plus the external wrench's power, plus retune's jumps
  double dissipated = 0;     // friction plus the end stops' damping
};

/// Everything a run continues from (Plant::snapshot, Plant::restore): with
/// RK4 and ROS2 a restored run is the original's bit for bit; CVODE
/// restarts its history there (its multistep history is not part of it).
struct PlantSnapshot {
  double t = 0;
  Vec8 y = Vec8::Zero();  // [pose; velocity]
  Vec4 theta1_ref = Vec4::Zero();
  EnergyIntegrals energy;  // as held (memory.balance_pending: the dissipated energy is brought up to date when read)
  unsigned stops = 0;      // the contact mode (end_stops.hpp)
  SolverMemory memory;
};

/// The machine's outputs at the current time (docs/model.md "The machine
/// around the mechanism").
struct MachineOutputs {
  Vec4 rho = Vec4::Zero(), rhod = Vec4::Zero();  // m, m/s
  Vec4 stop_force = Vec4::Zero();      // N, signed along +z
  Vec4 friction_force = Vec4::Zero();  // N, signed along +z
  Vec4 F_hold = Vec4::Zero();          // N: holds the current pose at rest (gravity, payload, wrench)
  double kinetic_energy = 0;           // J, rotors included
  double potential_energy = 0;         // J, gravity plus the stops' springs
  double actuator_work = 0;            // J, running integral
  double dissipated_energy = 0;        // J, running integral
  double actuator_power = 0;           // W, d(actuator_work)/dt
  double dissipation_rate = 0;         // W, d(dissipated_energy)/dt
  /// Event indicators (end_stops.hpp): rho_i - rho_min, then rho_max - rho_i,
  /// each offset by the hysteresis under the contact mode.
  double stop_indicators[kStopIndicators] = {};
  /// Then the clamps' (end_stops.hpp's clamp_indicators).
  double clamp_indicators[kLegs] = {};
};

class Plant {
 public:
  explicit Plant(const Model& model);

  const Model& model() const { return model_; }

  /// Replaces the solver settings (validated first).
  Status set_solver(const SolverSettings& s, std::string* error = nullptr);
  const SolverSettings& solver() const { return settings_; }

  /// Applies new values of the tunable parameters (the parameter table's
  /// Tunable rows: the payload) to the running plant; every other member of
  /// `p` must equal model().p. The state is kept: the platform's velocity is
  /// continuous (a part grasped or released at rest relative to it), the
  /// jump of kinetic plus potential energy is booked into actuator_work (the
  /// work of the grasp: the audit stays constant), and CVODE restarts.
  /// InvalidParameter (p invalid) or InvalidArgument (a fixed parameter
  /// differs): nothing changes, last_error() says why.
  Status retune(const Params& p);

  /// Consistent initial state at time t0 from a pose and a velocity
  /// (position and velocity problems). Status::Unreachable if the pose
  /// cannot be assembled elbow-down, ::Singular if it lies beyond the
  /// singularity limits of the solver settings, ::NonFinite if the state
  /// derivative there is not finite (velocity far too large); last_error()
  /// says which leg and why. On failure nothing changes.
  Status initialize(double t0, const Pose& pose, const Pose& velocity);

  /// Integrates to t_end with the given inputs. `continuous` tells that the
  /// inputs continue smoothly those of the previous call (CVODE keeps its
  /// history); otherwise CVODE restarts at the current time. On failure the
  /// state stays at the last point reached successfully (RK4: the last
  /// whole step; CVODE: the start of the call). Every step's end state is
  /// checked against the singularity limits (check_configuration): a step
  /// ending beyond them is undone and Status::Singular (or ::Unreachable)
  /// returned, with last_error() naming the leg or the condition number.
  Status advance(double t_end, const InputSignal& inputs, bool continuous = false);
  /// Why an advance over `span` seconds would be refused before any work
  /// ("" if it would not; advance returns Status::InvalidArgument with it):
  /// CVODE over less than kMinCvodeSpan, or more fixed grid steps than one
  /// call may take (kMaxInnerStepsPerCall). `what` names the span in the
  /// message ("an interval", "a communication step").
  std::string advance_refusal(double span, const char* what) const;

  bool initialized() const { return initialized_; }
  double time() const { return t_; }
  /// The integrated state [pose; velocity].
  const Vec8& state() const { return y_; }
  /// The current state with everything the integrators carry between
  /// advances (reading changes nothing the run depends on).
  PlantSnapshot snapshot() const;
  /// Continues from a snapshot: RK4 and ROS2 bit for bit as the run it was
  /// taken from, CVODE restarted there. Refused (nothing changes,
  /// last_error() says why: InvalidArgument, NonFinite, or the guard's
  /// status) if y lies beyond the singularity limits or kMaxSpeed,
  /// theta1_ref is not the pose's closed-form theta1 (modulo 2 pi), an
  /// energy is not finite, the memory is none a run can have
  /// (solver_memory_fault), or the contact mode names no stop, both stops of
  /// one leg or the clamp of a stop not held. `settled`: the contact mode
  /// must also be the one the event rule keeps at y (stops_after_event),
  /// as it is wherever advance() and update_stops() leave it; without it
  /// the mode may lag the state (Model Exchange between events).
  /// snapshot.stops = kStopsFromState: the mode the event rule gives at y
  /// from none.
  Status restore(const PlantSnapshot& snapshot, bool settled = true);

  /// The contact mode (end_stops.hpp): which end stops act. Set at
  /// initialize() and restore() by the event rule, switched at every event
  /// located by advance() and by update_stops(), and nothing else: the
  /// derivatives, the outputs and both integrators use it, so that
  /// Co-Simulation and Model Exchange are the same hybrid model.
  unsigned stops() const { return stops_; }
  /// Model Exchange's Event Mode: switches the contact mode by the event
  /// rule (stops_after_event) at the current state; returns the stops
  /// switched (Unreachable off the workspace: nothing changes).
  Status update_stops(unsigned& switched);
  /// The contact mode's event indicators at the current state
  /// (end_stops.hpp's contact_indicators, under stops()).
  Status contact_indicators(double z[kContactIndicators]) const;

  /// The running energy integrals (zero at initialize()).
  const EnergyIntegrals& energy_integrals() const {
    settle_energy();
    return energy_;
  }

  /// stop_force, F_hold, energies and the stop indicators at the current
  /// time, for the inputs at that time.
  Status machine_outputs(const InputSignal& inputs, MachineOutputs& out) const;

  /// End-stop contact events located so far (RK4 step splits, CVODE roots).
  long contact_events() const { return contact_events_; }

  // ---- Model Exchange: the importer's integrator owns time and state.
  /// Sets the time (the state is kept).
  void set_time(double t) { t_ = t; }
  /// Sets the state [pose; velocity] reached by the importer's integrator
  /// (the contact mode is kept: relations change in Event Mode only):
  /// Status::Unreachable (nothing changes, last_error() says which leg) if a
  /// leg cannot be assembled there, ::NonFinite if y is not finite. The
  /// singularity limits are not checked here: the event indicators
  /// (guard_indicators) locate their crossing.
  Status set_state(const Vec8& y);
  /// Sets the running energy integrals (the importer integrates them too).
  void set_energy_integrals(const EnergyIntegrals& e) {
    energy_ = e;
    memory_.balance_pending = 0;
  }
  /// d/dt of [y; actuator_work; dissipated] at the current time and state
  /// for the given inputs, under the contact mode stops().
  Status derivative_now(const InputSignal& inputs, Vec10& xdot) const;

  /// q, qd, qdd and lambda at the current time, for the inputs at that time
  /// (evaluated on demand; theta1 continuous in time). Reading changes nothing.
  Status mechanism(const InputSignal& inputs, MechanismState& out) const;
  /// q and qd at the current state (closed form, theta1 continuous): the
  /// legs without the dynamics.
  Status coordinates(Vec16& q, Vec16& qd) const;
  /// theta1 of each leg at the current time, unwrapped continuously since
  /// initialisation. Brought up to date when read (not in every advance:
  /// that would cost four atan2 per step); continuity holds as long as theta1
  /// moves less than pi between reads, which the workspace guarantees.
  const Vec4& theta1_ref() const;

  /// The actuator positions rho_1..4 at the current state
  /// (pkm::actuator_positions, bit for bit; the integrators compute them at
  /// the end of every step for the end stops, so reading them is a copy).
  Status actuator_positions(Vec4& rho) const;

  /// ||C(q)|| at the current state (m).
  double constraint_residual() const;
  /// Condition number of the actuator Jacobian (docs/model.md), +inf if singular.
  double jacobian_condition() const;

  long rhs_evaluations() const { return rhs_count_; }
  /// CVODE's internal steps so far (0 with RK4, whose steps are rk4_step).
  long cvode_steps() const { return cvode_ready_ ? cvode_.steps() : 0; }
  const std::string& last_error() const { return error_; }

 private:
  friend struct PlantOde;  // the integrators' view (plant.cpp)
  static int cvode_rhs(double t, const Vec10& x, Vec10& xdot, void* self);
  static int cvode_roots(double t, const Vec10& x, double* g, void* self);
  /// BDF's Jacobian: the analytic one of the pose and velocity rates
  /// (state_derivative_jacobians), as ROS2's.
  static int cvode_jacobian(double t, const Vec10& x, Mat10& J, void* self);
  /// Whether this CVODE advance has used up kMaxCvodeEvaluationsPerCall
  /// (then the callbacks abort it).
  bool cvode_capped();
  /// d/dt of x = [y; actuator_work; dissipated] for the integrators
  /// (counts the evaluation; the inputs of the current advance, the stops held).
  Status derivative(double t, const Vec10& x, Vec10& xdot);
  /// The same for any inputs and stops (the integrators' and Model
  /// Exchange's); *inputs_fault tells a NonFinite caused by the inputs.
  Status machine_rates(const InputSignal& inputs, double t, const Vec10& x, unsigned stops, Vec10& xdot,
                       bool* inputs_fault = nullptr) const;
  /// rho and rhod at the state y (closed form).
  Status joint_motion(const Vec8& y, Vec4& rho, Vec4& rhod) const;
  /// [y; energy integrals] (`settle`: the dissipated energy brought up to date first).
  Vec10 packed(bool settle = true) const;
  /// Brings energy_.dissipated to the balance if ROS2 left it pending.
  void settle_energy() const;
  void unpack(const Vec10& x);
  /// The contact mode at x (located_rk4.hpp): the event rule
  /// (stops_after_event) from the held mode (stops_) at x, the clamps
  /// included; ~0u if unreachable. rho receives the actuator positions
  /// there (valid unless ~0u).
  unsigned contact_mode(const Vec10& x, Vec4& rho) const;
  /// The same with rho, the actuator positions at x, known.
  unsigned contact_mode_at(const Vec10& x, const Vec4& rho) const;
  /// Creates CVODE's objects (once, when it is the solver), so that no step
  /// allocates: at initialize() and restore().
  Status prepare_cvode();
  /// RK4 or ROS2 (settings_.solver) on whole grid steps of at most rk4_step.
  Status advance_fixed(double t_end);
  /// Kinetic plus potential energy at y (J).
  Status mechanical_energy(const Vec8& y, double& e) const;
  /// ROS2's dissipated energy over the grid step to x: the balance of the
  /// work and of the mechanical energy (e_mech at its start, updated);
  /// with energy_tolerance, a step that gains more energy than that fails.
  Status rosenbrock_dissipation(Vec10& x, double& e_mech, double t0, double t1);
  /// kinetic + potential - actuator_work + dissipated at the current state (J).
  Status energy_audit(double& value) const;
  Status advance_cvode(double t_end, bool continuous);
  /// check_configuration of y's pose against the settings' limits; on
  /// failure error_ describes it.
  Status guard(const Vec8& y, double t);
  /// Brings theta1_ref_ to the closed-form q of the current state.
  void follow_theta1(const Vec16& q) const;

  Model model_;
  SolverSettings settings_;
  CvodeIntegrator cvode_;
  bool cvode_ready_ = false;
  InputSignal inputs_;
  bool initialized_ = false;
  double t_ = 0;
  Vec8 y_ = Vec8::Zero();
  mutable EnergyIntegrals energy_;
  // What the integrators carry between advances (solver_memory.hpp), ROS2's
  // energy balance included: its dissipated energy, the audit's balance, is
  // brought up to date when read (settle_energy), since the mechanical
  // energy costs a third of a ROS2 step.
  mutable SolverMemory memory_;
  long contact_events_ = 0;
  unsigned stops_ = 0;  // the contact mode (stops()): never kStopsFromState
  // actuator_positions at y_, when rho_valid_ (every change of y_ clears it).
  mutable Vec4 rho_ = Vec4::Zero();
  mutable bool rho_valid_ = false;
  mutable Theta1References theta1_;
  mutable bool theta1_stale_ = false;
  long rhs_count_ = 0;
  Status rhs_status_ = Status::Ok;
  // Within one CVODE advance: rhs_count_ at its start, and whether it hit
  // kMaxCvodeEvaluationsPerCall.
  long cvode_call_start_ = 0;
  bool cvode_work_capped_ = false;
  std::string error_;
};

}  // namespace pkm
