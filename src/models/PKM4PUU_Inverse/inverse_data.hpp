// SPDX-License-Identifier: BSD-2-Clause
#pragma once
// PKM4PUU_Inverse.fmu: inverse dynamics of the 4-PUU robot (computed-force
// feed-forward), over pkm::inverse_dynamics. An algebraic FMU: its outputs
// are functions of the inputs at the communication point (direct
// feedthrough), computed lazily on the first get after an input changed.
//
// Immutable: the table and ModelDefinition (shared), and pkm::Model built
// once per instance at the end of initialisation. Per instance
// (InverseData): parameter and input values and the output cache.
//
// The legs' positions are the closed-form elbow-down inverse kinematics
// (the reduced inverse dynamics, inverse_lanes.hpp: no iteration), so the
// outputs are a pure function of the current inputs and parameters (bit
// for bit, whatever was computed before; nothing to carry in FMU states).
// Outputs are computed lazily by group (kGroup* below), each on the first
// get that reads it after an input changed: reading the forces does not pay
// for the multipliers or the Jacobian's condition number.
//
// The plant's singularity guards (workspace_guard.hpp, the same parameters
// max_jacobian_condition and min_leg_measure): near a leg or parallel
// singularity the forces grow without bound (1e19 N with a rod horizontal),
// numbers no drive should be handed. A pose beyond a guard makes the get
// answer Discard with the reason logged and the outputs of the last pose
// within the guards; the outputs jacobian_condition and leg_measure_min tell
// the master how close it is.
#include <cstdint>
#include <optional>

#include "models/common/dependencies.hpp"
#include "models/common/parameter_variables.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"

namespace pkm_fmi {
namespace pkm4puu_inverse_model {


// The output groups (Variable::group).
enum : std::uint8_t {
  kGroupActuators = 1u << 0,    // F, tau, rho, drho, leg_measure_min: the reduced inverse dynamics
  kGroupMultipliers = 1u << 1,  // lambda: the legs' angles and rows as well
  kGroupCondition = 1u << 2,    // jacobian_condition: an SVD of the actuator Jacobian
};

struct InverseData final : MechanismData {
  // Inputs.
  double pose[4] = {0.0, 0.0, 0.05, 0.0};  // x, y, z, phi
  double vel[4] = {}, acc[4] = {};
  double wrench[4] = {};  // Fe1..Fe3, Me_z
  // Outputs.
  double F[4] = {}, tau[4] = {}, rho[4] = {}, drho[4] = {}, lambda[12] = {};
  double condition = 0.0, leg_measure_min = 0.0;
  // Joints beyond their end stops at the last evaluation (bit i: below
  // rho_min, 4 + i: above rho_max): a warning is given on entering, once.
  unsigned beyond_stops = 0;
  // Built at the end of initialisation.
  std::unique_ptr<pkm::Model> model;
  // The singularity guards' limits of the model last made (make).
  pkm::GuardLimits limits{};

  void reset() override { model.reset(); }
  Status exit_initialization(Context& ctx) override;
  Status do_step(Context&, double t, double h, double& t_reached) override {
    t_reached = t + h;  // no dynamics: the outputs follow the inputs
    return Status::OK;
  }
  bool step_has_effects() const override { return false; }
  Status update_outputs(Context& ctx, unsigned groups) override;
  /// update_outputs with the model to evaluate with.
  Status compute_outputs(Context& ctx, const pkm::Model& with, unsigned groups);
  void save(StateWriter& w) const override;
  bool load(StateReader& r, Context& ctx) override;
  /// The payload changed between steps or in Event Mode: the model made again.
  Status tune(Context& ctx, const char* function, bool& states_changed) override;

  Status partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                             const Variable* const knowns[], std::size_t nk, double J[]) override;

  /// The model of the current parameters, and their guards' limits into `limits`.
  Status make(Context& ctx, const char* function, pkm::Model& out);
  /// The model to evaluate with: the instance's, or in initialisation mode
  /// one made into `temporary` (constructed only then) from the current
  /// parameters; nullptr (logged) if there is none.
  const pkm::Model* current_model(Context& ctx, const char* function, std::optional<pkm::Model>& temporary);
};

}  // namespace pkm4puu_inverse_model
}  // namespace pkm_fmi
