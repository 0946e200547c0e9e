// SPDX-License-Identifier: BSD-2-Clause
#pragma once
// PKM4PUU.fmu: forward dynamics of the 4-PUU robot (the plant), over
// pkm::Plant: the instance data and the hooks of the generic FMI layer
// (fmi/model_data.hpp). Variables, names and units: variables.cpp.
//
// Immutable: the table below and the ModelDefinition (shared by every
// instance); pkm::Model, built once per instance at the end of
// initialisation and owned by the instance's pkm::Plant.
// Per instance (PlantData): parameter values, inputs and their first
// derivatives, the output cache and the Plant (integrated state).
//
// Time stepping: every fmi2DoStep integrates with inputs
// u(t) = u + du (t - t_step_start) (du from fmi2SetRealInputDerivatives,
// reset to 0 whenever u is set). After a step the inputs hold their
// extrapolated values u + du h, the inputs at the new time. CVODE continues
// its history across the communication point (Plant::advance with
// continuous = true: no restart) when the inputs did not jump there
// (inputs_continue): every input at the step start equals its value at the
// end of the previous step within kInputJump (relative: rounding) -- inputs
// held constant, or a ramp whose values and slopes the master sets each
// step (a change of slope is a kink, which CVODE's error test resolves).
// A value that differs is a jump, and CVODE restarts at the step start:
// integrating across a jump from the old history costs accuracy (the
// docs' "CVODE across communication points" measures how much).
// FMU states: the Plant's snapshot with everything RK4 and ROS2 carry
// between steps (pkm::SolverMemory, whole), so that a restored run
// continues bit for bit like the original. CVODE's multistep history is not
// part of it (SUNDIALS has no way to set it): the first step after a
// SetFMUState restarts CVODE, so a restored CVODE run agrees with the
// original within CVODE's tolerance (bit for bit where the original
// restarted there too, at a jump of the inputs). Taking a state changes
// nothing: the run goes on as without it.
//
// Outputs are computed lazily by group (the state's copies, the legs, the
// dynamics, the machine, the health measures: kGroup* below), each on the
// first get that reads it after anything changed, so that a controller
// reading the pose and the sliders does not pay for the multipliers. The
// accelerations, hence lambda, depend on the inputs at the current time.
//
// Model Exchange: the continuous states are the pose and its velocity (the
// outputs x..dphi) and the energy audit's two running integrals
// (actuator_work, dissipated_energy); the importer's integrator sets them and
// the time, the legs are reconstructed from the pose (closed form), so the
// states never leave the constraint manifold. The event indicators are the
// singularity guards (pkm::guard_indicators), whose crossing terminates the
// simulation with a logged reason as a discarded step does in
// Co-Simulation, and the end stops (rho_i - rho_min, rho_max - rho_i), whose
// crossings are events logged under logEvents.
#include <cstdint>
#include <memory>

#include "models/common/dependencies.hpp"
#include "models/common/parameter_variables.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace pkm_fmi {
// The plant FMU's instance data and its hooks (plant_data.cpp); its
// variable table: variables.cpp.
namespace pkm4puu_model {


constexpr int kStates = 10;  // pose, velocity, actuator_work, dissipated_energy
constexpr int kIndicators = pkm::kGuardIndicators + pkm::kContactIndicators;
constexpr int kInputs = 12;  // F[1..4], Fe[1..3], Me_z, tau[1..4]
// docs/model.md "Bodies": each actuator's share of the
// weight at the default initial pose, the start value of F[1..4] (so that a
// plant nothing drives stays where it is).
constexpr double kHoldingForce = 2.655616050;
// An input jumps at a communication point when it differs from its value at
// the end of the previous step by more than this, relative to 1 + |value|
// (in N, N*m): far above the rounding of a master that evaluates a ramp
// a + b t where the FMU extrapolated u + b h (a few 1e-16), far below any
// jump that matters (a jump of 1e-12 N moves the platform by ~1e-16 m in a
// millisecond).
constexpr double kInputJump = 1e-12;

// The output groups (Variable::group): a get computes only the groups it
// reads, each once until the state, time or inputs change.
enum : std::uint8_t {
  kGroupState = 1u << 0,     // pose, velocity, der(pose): copies of the state
  kGroupJoints = 1u << 1,    // drho, theta1, theta2: the legs in closed form
  kGroupDynamics = 1u << 2,  // accelerations and multipliers: the full forward dynamics
  kGroupMachine = 1u << 3,   // end stops, holding forces, energies and their rates
  kGroupHealth = 1u << 4,    // loop-closure residual, Jacobian condition, guard indicators
  kGroupSliders = 1u << 5,   // rho: the closed form without angles (what a joint-space controller reads)
  kGroupEnergy = 1u << 6,    // the energy integrals (Rosenbrock: the dissipated energy's balance, computed on read)
};

struct PlantData final : MechanismData {
  // Inputs u = [F1..F4, Fe1..Fe3, Me_z, tau1..tau4] at the current time, and du/dt.
  double u[kInputs] = {kHoldingForce, kHoldingForce, kHoldingForce, kHoldingForce};
  double du[kInputs] = {};
  // Outputs (computed by update_outputs).
  double pose[4] = {}, vel[4] = {};
  double rho[4] = {}, drho[4] = {}, theta1[4] = {}, theta2[4] = {};
  double lambda[12] = {};
  double residual = 0.0, condition = 0.0;
  double F_hold[4] = {}, stop_force[4] = {};
  double kinetic = 0.0, potential = 0.0;
  double energy[2] = {};  // actuator_work, dissipated_energy (states)
  double dy[kStates] = {};  // der(x) .. der(dphi), der(actuator_work), der(dissipated_energy)
  double z[kIndicators] = {};  // the event indicators: guards, then end stops, then their clamps
  // The contact mode last logged (the Plant's, end_stops.hpp), to log
  // contacts and releases.
  unsigned logged_stops = 0;
  // Co-Simulation: end-stop events located so far (logged per step).
  long contact_events = 0;
  // Co-Simulation: the inputs at the end of the last step and whether CVODE
  // may continue from there (no restart, failure or restored state since).
  double u_end[kInputs] = {};
  bool may_continue = false;
  // The simulated machine (nullptr before initialisation).
  std::unique_ptr<pkm::Plant> plant;
  // The state derivative's Jacobians at (y, u, contact mode) of the last
  // partial_derivatives: an importer builds a full Jacobian with one
  // directional derivative per seed (FMI 2: one column a call), and every
  // such call at the same point reuses one evaluation. Invalid whenever the
  // plant is replaced.
  struct JacobianCache {
    bool valid = false;
    pkm::Vec8 y;
    double u[kInputs];
    unsigned stops = 0;
    pkm::Mat8 A;
    pkm::Mat8x12 B;
    pkm::JointJacobians joints;
    pkm::Vec4 rho;
    /// Whether it holds the Jacobians at exactly this point.
    bool holds(const pkm::Vec8& y_now, const double u_now[], unsigned stops_now) const;
  } jacobian_cache;

  void reset() override {
    plant.reset();
    jacobian_cache.valid = false;
    may_continue = false;
  }
  /// Whether every input continues its value at the end of the last step (kInputJump).
  bool inputs_continue() const;
  Status exit_initialization(Context& ctx) override;
  Status do_step(Context& ctx, double t, double h, double& t_reached) override;
  Status check_step(Context& ctx, double h) const override;
  Status update_outputs(Context& ctx, unsigned groups) override;
  void save(StateWriter& w) const override;
  bool load(StateReader& r, Context& ctx) override;
  /// The payload changed between steps or in Event Mode: Plant::retune.
  Status tune(Context& ctx, const char* function, bool& states_changed) override;

  void set_time(double t) override {
    if (plant) plant->set_time(t);
  }
  Status get_states(Context& ctx, double x[]) override;
  Status set_states(Context& ctx, const double x[]) override;
  Status get_derivatives(Context& ctx, double dx[]) override;
  Status get_event_indicators(Context& ctx, double z[]) override;
  Status event_update(Context& ctx, bool& terminate) override;
  Status partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                             const Variable* const knowns[], std::size_t nk, double J[]) override;

  /// The absolute time of the plant (its own time is the time since startTime), for messages.
  double absolute_time(const Context& ctx) const { return ctx.start_time + plant->time(); }
  /// The model and solver settings of the current parameters (Error, logged, if unusable).
  Status configuration(Context& ctx, const char* function, pkm::Model& model, pkm::SolverSettings& s) const;
  /// A Plant for the current parameters (not yet initialised).
  Status make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const;
  /// Whether the plant exists and was built from these parameters and settings.
  bool built_from(const pkm::Model& model, const pkm::SolverSettings& s) const;
  /// make_plant, then the consistent initial state from x0..phi0, dx0..dphi0.
  Status build(Context& ctx, const char* function);
  /// The plant, built from the current parameters in initialisation mode.
  Status ready(Context& ctx, const char* function);
  pkm::LinearInputs inputs(double t0) const;
  /// Logs (logEvents) each stop passed or left since the last call.
  void log_stop_changes(Context& ctx, unsigned now, const char* where);
};

}  // namespace pkm4puu_model
}  // namespace pkm_fmi
