// SPDX-License-Identifier: BSD-2-Clause
// PKM4PUU_Inverse.fmu's interface: every variable of its model descriptions,
// with where its value lives in InverseData (inverse_data.hpp) and what it
// depends on.
#include <iterator>
#include <memory>

#include "models/PKM4PUU_Inverse/inverse_data.hpp"
#include "models/models.hpp"

namespace pkm_fmi {
namespace {

using namespace pkm4puu_inverse_model;

// ---------------------------------------------------------------- the table

#define INV(member) \
  [](ModelData& d, int i) -> void* { return &static_cast<InverseData&>(d).member[i]; }
#define INV_SCALAR(member) [](ModelData& d, int) -> void* { return &static_cast<InverseData&>(d).member; }

// The multipliers: invariant to a vertical translation. The forces follow z
// too, through the end stops (beyond them), and dz through the joints'
// friction and the stops' damping (which act on the sliders only, so the
// multipliers do not see them).
constexpr std::uint8_t kMultipliers = kOnPositions | kOnRates | kOnInputs;
constexpr std::uint8_t kForces = kMultipliers | kOnHeight | kOnHeightRate;

// clang-format off
constexpr Variable kOwnVariables[] = {
  time_variable(0),
  // Inputs: 1..16.
  real_input(1, "x", 0.0, "m", "Platform reference point P (centre of mass), x in the base frame", INV(pose), 0, nullptr, kOnPositions),
  real_input(2, "y", 0.0, "m", "Platform reference point P (centre of mass), y in the base frame", INV(pose), 1, nullptr, kOnPositions),
  real_input(3, "z", 0.05, "m", "Platform reference point P (centre of mass), z in the base frame (home pose: 0.05 m)", INV(pose), 2, nullptr, kOnHeight),
  real_input(4, "phi", 0.0, "rad", "Platform rotation about z of the base frame", INV(pose), 3, nullptr, kOnPositions),
  real_input(5, "dx", 0.0, "m/s", "Velocity of P, x component", INV(vel), 0, nullptr, kOnRates),
  real_input(6, "dy", 0.0, "m/s", "Velocity of P, y component", INV(vel), 1, nullptr, kOnRates),
  real_input(7, "dz", 0.0, "m/s", "Velocity of P, z component", INV(vel), 2, nullptr, kOnHeightRate),
  real_input(8, "dphi", 0.0, "rad/s", "Platform angular velocity about z", INV(vel), 3, nullptr, kOnRates),
  real_input(9, "ddx", 0.0, "m/s2", "Acceleration of P, x component", INV(acc), 0, nullptr, kOnInputs),
  real_input(10, "ddy", 0.0, "m/s2", "Acceleration of P, y component", INV(acc), 1, nullptr, kOnInputs),
  real_input(11, "ddz", 0.0, "m/s2", "Acceleration of P, z component", INV(acc), 2, nullptr, kOnInputs),
  real_input(12, "ddphi", 0.0, "rad/s2", "Platform angular acceleration about z", INV(acc), 3, nullptr, kOnInputs),
  real_input(13, "Fe[1]", 0.0, "N", "External force on the platform at P, x component (base frame)", INV(wrench), 0, nullptr, kOnInputs),
  real_input(14, "Fe[2]", 0.0, "N", "External force on the platform at P, y component (base frame)", INV(wrench), 1, nullptr, kOnInputs),
  real_input(15, "Fe[3]", 0.0, "N", "External force on the platform at P, z component (base frame)", INV(wrench), 2, nullptr, kOnInputs),
  real_input(16, "Me_z", 0.0, "N.m", "External moment on the platform about z", INV(wrench), 3, nullptr, kOnInputs),
  // Outputs: 20..51.
  real_output(20, "F[1]", "N", "Actuator force on the slider of leg 1, along +z (Eq. 11)", INV(F), 0, kForces, kGroupActuators),
  real_output(21, "F[2]", "N", "Actuator force on the slider of leg 2, along +z (Eq. 11)", INV(F), 1, kForces, kGroupActuators),
  real_output(22, "F[3]", "N", "Actuator force on the slider of leg 3, along +z (Eq. 11)", INV(F), 2, kForces, kGroupActuators),
  real_output(23, "F[4]", "N", "Actuator force on the slider of leg 4, along +z (Eq. 11)", INV(F), 3, kForces, kGroupActuators),
  real_output(24, "rho[1]", "m", "Actuated prismatic joint of leg 1 (slider position)", INV(rho), 0, kOnPositions | kOnHeight, kGroupActuators),
  real_output(25, "rho[2]", "m", "Actuated prismatic joint of leg 2 (slider position)", INV(rho), 1, kOnPositions | kOnHeight, kGroupActuators),
  real_output(26, "rho[3]", "m", "Actuated prismatic joint of leg 3 (slider position)", INV(rho), 2, kOnPositions | kOnHeight, kGroupActuators),
  real_output(27, "rho[4]", "m", "Actuated prismatic joint of leg 4 (slider position)", INV(rho), 3, kOnPositions | kOnHeight, kGroupActuators),
  real_output(28, "drho[1]", "m/s", "Slider velocity of leg 1", INV(drho), 0, kOnPositions | kOnRates | kOnHeightRate, kGroupActuators),
  real_output(29, "drho[2]", "m/s", "Slider velocity of leg 2", INV(drho), 1, kOnPositions | kOnRates | kOnHeightRate, kGroupActuators),
  real_output(30, "drho[3]", "m/s", "Slider velocity of leg 3", INV(drho), 2, kOnPositions | kOnRates | kOnHeightRate, kGroupActuators),
  real_output(31, "drho[4]", "m/s", "Slider velocity of leg 4", INV(drho), 3, kOnPositions | kOnRates | kOnHeightRate, kGroupActuators),
  real_output(32, "tau[1]", "N.m", "Equivalent motor torque of leg 1, F[1] screw_lead/(2 pi)", INV(tau), 0, kForces, kGroupActuators),
  real_output(33, "tau[2]", "N.m", "Equivalent motor torque of leg 2", INV(tau), 1, kForces, kGroupActuators),
  real_output(34, "tau[3]", "N.m", "Equivalent motor torque of leg 3", INV(tau), 2, kForces, kGroupActuators),
  real_output(35, "tau[4]", "N.m", "Equivalent motor torque of leg 4", INV(tau), 3, kForces, kGroupActuators),
  real_output(40, "lambda[1]", "N", "Lagrange multiplier of leg 1's loop closure, x row (Eq. 10)", INV(lambda), 0, kMultipliers, kGroupMultipliers),
  real_output(41, "lambda[2]", "N", "Lagrange multiplier of leg 1's loop closure, y row (Eq. 10)", INV(lambda), 1, kMultipliers, kGroupMultipliers),
  real_output(42, "lambda[3]", "N", "Lagrange multiplier of leg 1's loop closure, z row (Eq. 10)", INV(lambda), 2, kMultipliers, kGroupMultipliers),
  real_output(43, "lambda[4]", "N", "Lagrange multiplier of leg 2's loop closure, x row (Eq. 10)", INV(lambda), 3, kMultipliers, kGroupMultipliers),
  real_output(44, "lambda[5]", "N", "Lagrange multiplier of leg 2's loop closure, y row (Eq. 10)", INV(lambda), 4, kMultipliers, kGroupMultipliers),
  real_output(45, "lambda[6]", "N", "Lagrange multiplier of leg 2's loop closure, z row (Eq. 10)", INV(lambda), 5, kMultipliers, kGroupMultipliers),
  real_output(46, "lambda[7]", "N", "Lagrange multiplier of leg 3's loop closure, x row (Eq. 10)", INV(lambda), 6, kMultipliers, kGroupMultipliers),
  real_output(47, "lambda[8]", "N", "Lagrange multiplier of leg 3's loop closure, y row (Eq. 10)", INV(lambda), 7, kMultipliers, kGroupMultipliers),
  real_output(48, "lambda[9]", "N", "Lagrange multiplier of leg 3's loop closure, z row (Eq. 10)", INV(lambda), 8, kMultipliers, kGroupMultipliers),
  real_output(49, "lambda[10]", "N", "Lagrange multiplier of leg 4's loop closure, x row (Eq. 10)", INV(lambda), 9, kMultipliers, kGroupMultipliers),
  real_output(50, "lambda[11]", "N", "Lagrange multiplier of leg 4's loop closure, y row (Eq. 10)", INV(lambda), 10, kMultipliers, kGroupMultipliers),
  real_output(51, "lambda[12]", "N", "Lagrange multiplier of leg 4's loop closure, z row (Eq. 10)", INV(lambda), 11, kMultipliers, kGroupMultipliers),
  real_output(52, "leg_measure_min", "", "Smallest |cos(theta2) sin(theta2)| of the four legs (0 at a leg singularity; the guard min_leg_measure)", INV_SCALAR(leg_measure_min), 0, kOnPositions, kGroupActuators),
  real_output(53, "jacobian_condition", "", "Condition number of the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi), its phi column divided by 0.1 m (the guard max_jacobian_condition)", INV_SCALAR(condition), 0, kOnPositions, kGroupCondition),
};
// clang-format on

#undef INV
#undef INV_SCALAR

// Parameters: the mechanism (100..120), the guards (146..147), the machine
// (150..160): the parameter table's rows.
static_assert(sorted_by_vr(kOwnVariables, std::size(kOwnVariables)), "the table must be sorted by value reference");
constexpr auto kVariables = merge_by_vr(kOwnVariables, parameter_variables<pkm::kFmuInverse>());
static_assert(sorted_by_vr(kVariables.data(), kVariables.size()), "value references must be unique");
static_assert(kVariables[1].vr == 1 && kVariables[16].vr == 16 && kVariables[17].vr == 20,
              "partial_derivatives: the inputs are value references 1..16, in the order of their row");

std::unique_ptr<ModelData> create() { return std::make_unique<InverseData>(); }

const ModelDefinition kDefinition{
    "PKM4PUU_Inverse",
    "4-PUU Schoenflies-motion parallel robot: inverse dynamics (computed-force feed-forward)",
    "<p>Inverse dynamics of the 4-PUU parallel kinematics machine with three translations and one rotation "
    "(3T1R) of M. Ruggiu, P. Rea and E. Ottaviano, <i>Dynamic model of a 3T1R parallel kinematics machine</i>. "
    "Given the platform pose, velocity and acceleration and an external wrench, it solves the position, "
    "velocity and acceleration problems of the legs (Eqs. 2-9, elbow-down) and then Eqs. 10-11 for the "
    "Lagrange multipliers and the four actuator forces. The outputs are algebraic functions of the inputs at "
    "the current time (direct feedthrough): in Co-Simulation a step only advances time.</p>"
    "<p>An unreachable pose makes the get of an output return Error with a message; no output is written "
    "then. A pose beyond a singularity guard (min_leg_measure, max_jacobian_condition, as in the plant) makes "
    "it return Discard with the reason logged and the outputs of the last pose within the guards. At rest at "
    "the home pose (0, 0, 0.05 m, 0) with g = 9.81 m/s2 each actuator carries 2.655616050 N.</p>",
    kVariables.data(),
    kVariables.size(),
    /*n_states=*/0,
    /*n_position_states=*/0,
    /*n_event_indicators=*/0,
    /*can_interpolate_inputs=*/false,
    /*default_step=*/1e-3,
    /*default_stop=*/2.0,
    &create,
    /*provides_derivatives=*/true,
};

}  // namespace

const ModelDefinition& pkm4puu_inverse_definition() { return kDefinition; }

}  // namespace pkm_fmi
