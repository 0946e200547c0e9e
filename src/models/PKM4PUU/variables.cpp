// SPDX-License-Identifier: BSD-2-Clause
// PKM4PUU.fmu's interface: every variable of its model descriptions, with
// where its value lives in PlantData (plant_data.hpp) and what it depends on.
#include <iterator>
#include <memory>

#include "models/PKM4PUU/plant_data.hpp"
#include "models/models.hpp"
#include "pkm4puu/kinematics/constraints.hpp"

namespace pkm_fmi {
namespace {

using namespace pkm4puu_model;

// ---------------------------------------------------------------- the table

#define PLANT(member) \
  [](ModelData& d, int i) -> void* { return &static_cast<PlantData&>(d).member[i]; }
#define PLANT_SCALAR(member) \
  [](ModelData& d, int) -> void* { return &static_cast<PlantData&>(d).member; }

// The states' scales (nominal), which importers use for their absolute
// tolerance (rtol x nominal): the workspace spans centimetres, so 0.1 m; the
// spec's test motion peaks at 0.019 m/s and 0.065 rad/s, so 0.01 m/s and
// 0.1 rad/s (a rate scale of 0.1 m/s would let an importer's velocity error
// grow tenfold before its error test notices, and z, which no stiffness
// holds, integrates that error); the rotation 1 rad; the energy integrals
// 0.1 J (the auto-test does about 0.2 J of work).
constexpr double kNominalLength = 0.1, kNominalAngle = 1.0, kNominalEnergy = 0.1;
constexpr double kNominalSpeed = 0.01, kNominalAngularSpeed = 0.1;

// What the outputs depend on. Only the slider positions follow z (the
// mechanism is otherwise invariant to a vertical translation), and through
// them whatever the end stops act on; only the slider velocities follow dz,
// and through them friction and the stops' damping.
constexpr std::uint8_t kSliders = kOnPositions | kOnHeight;
constexpr std::uint8_t kSliderRates = kOnPositions | kOnRates | kOnHeightRate;
constexpr std::uint8_t kEverything = kSliders | kSliderRates | kOnInputs;
constexpr std::uint8_t kWrench = kOnInputs | kOnWrench;  // the kind of Fe, Me_z

// clang-format off
constexpr Variable kOwnVariables[] = {
  time_variable(0),
  // Inputs: 1..8.
  real_input(1, "F[1]", kHoldingForce, "N", "Actuator force on the slider of leg 1, along +z", PLANT(u), 0, PLANT(du), kOnInputs),
  real_input(2, "F[2]", kHoldingForce, "N", "Actuator force on the slider of leg 2, along +z", PLANT(u), 1, PLANT(du), kOnInputs),
  real_input(3, "F[3]", kHoldingForce, "N", "Actuator force on the slider of leg 3, along +z", PLANT(u), 2, PLANT(du), kOnInputs),
  real_input(4, "F[4]", kHoldingForce, "N", "Actuator force on the slider of leg 4, along +z", PLANT(u), 3, PLANT(du), kOnInputs),
  real_input(5, "Fe[1]", 0.0, "N", "External force on the platform at P, x component (base frame)", PLANT(u), 4, PLANT(du), kWrench),
  real_input(6, "Fe[2]", 0.0, "N", "External force on the platform at P, y component (base frame)", PLANT(u), 5, PLANT(du), kWrench),
  real_input(7, "Fe[3]", 0.0, "N", "External force on the platform at P, z component (base frame)", PLANT(u), 6, PLANT(du), kWrench),
  real_input(8, "Me_z", 0.0, "N.m", "External moment on the platform about z", PLANT(u), 7, PLANT(du), kWrench),
  // Outputs: 10..53; x..dphi are the continuous states (Model Exchange).
  state_output(10, "x", "m", "Platform reference point P (centre of mass), x in the base frame", PLANT(pose), 0, 0, kOnPositions, kNominalLength, kGroupState),
  state_output(11, "y", "m", "Platform reference point P (centre of mass), y in the base frame", PLANT(pose), 1, 1, kOnPositions, kNominalLength, kGroupState),
  state_output(12, "z", "m", "Platform reference point P (centre of mass), z in the base frame", PLANT(pose), 2, 2, kOnHeight, kNominalLength, kGroupState),
  state_output(13, "phi", "rad", "Platform rotation about z of the base frame", PLANT(pose), 3, 3, kOnPositions, kNominalAngle, kGroupState),
  state_output(14, "dx", "m/s", "Velocity of P, x component", PLANT(vel), 0, 4, kOnRates, kNominalSpeed, kGroupState),
  state_output(15, "dy", "m/s", "Velocity of P, y component", PLANT(vel), 1, 5, kOnRates, kNominalSpeed, kGroupState),
  state_output(16, "dz", "m/s", "Velocity of P, z component", PLANT(vel), 2, 6, kOnHeightRate, kNominalSpeed, kGroupState),
  state_output(17, "dphi", "rad/s", "Platform angular velocity about z", PLANT(vel), 3, 7, kOnRates, kNominalAngularSpeed, kGroupState),
  state_output(18, "actuator_work", "J", "Work done on the machine since the start: integral of (F_i + (2 pi/screw_lead) tau_i) drho_i plus the external wrench's power, plus at each payload change (a grasp or release) its jump of kinetic and potential energy", PLANT(energy), 0, 8, kOnEnergy, kNominalEnergy, kGroupEnergy),
  state_output(19, "dissipated_energy", "J", "Energy dissipated since the start by joint friction and the end stops' damping", PLANT(energy), 1, 9, kOnEnergy, kNominalEnergy, kGroupEnergy),
  real_output(20, "rho[1]", "m", "Actuated prismatic joint of leg 1 (slider position)", PLANT(rho), 0, kSliders, kGroupSliders),
  real_output(21, "rho[2]", "m", "Actuated prismatic joint of leg 2 (slider position)", PLANT(rho), 1, kSliders, kGroupSliders),
  real_output(22, "rho[3]", "m", "Actuated prismatic joint of leg 3 (slider position)", PLANT(rho), 2, kSliders, kGroupSliders),
  real_output(23, "rho[4]", "m", "Actuated prismatic joint of leg 4 (slider position)", PLANT(rho), 3, kSliders, kGroupSliders),
  real_output(24, "drho[1]", "m/s", "Slider velocity of leg 1", PLANT(drho), 0, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(25, "drho[2]", "m/s", "Slider velocity of leg 2", PLANT(drho), 1, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(26, "drho[3]", "m/s", "Slider velocity of leg 3", PLANT(drho), 2, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(27, "drho[4]", "m/s", "Slider velocity of leg 4", PLANT(drho), 3, kOnPositions | kOnRates | kOnHeightRate, kGroupJoints),
  real_output(28, "theta1[1]", "rad", "First revolute joint of leg 1 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 0, kOnPositions, kGroupJoints),
  real_output(29, "theta1[2]", "rad", "First revolute joint of leg 2 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 1, kOnPositions, kGroupJoints),
  real_output(30, "theta1[3]", "rad", "First revolute joint of leg 3 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 2, kOnPositions, kGroupJoints),
  real_output(31, "theta1[4]", "rad", "First revolute joint of leg 4 (axis parallel to the prismatic axis), continuous", PLANT(theta1), 3, kOnPositions, kGroupJoints),
  real_output(32, "theta2[1]", "rad", "Second revolute joint of leg 1 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 0, kOnPositions, kGroupJoints),
  real_output(33, "theta2[2]", "rad", "Second revolute joint of leg 2 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 1, kOnPositions, kGroupJoints),
  real_output(34, "theta2[3]", "rad", "Second revolute joint of leg 3 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 2, kOnPositions, kGroupJoints),
  real_output(35, "theta2[4]", "rad", "Second revolute joint of leg 4 (horizontal axis), elbow-down: -pi/2 < theta2 < 0", PLANT(theta2), 3, kOnPositions, kGroupJoints),
  real_output(36, "stop_force[1]", "N", "End-stop force on the slider of leg 1, along +z (0 within its travel)", PLANT(stop_force), 0, kEverything & ~kOnInputs, kGroupMachine),
  real_output(37, "stop_force[2]", "N", "End-stop force on the slider of leg 2, along +z", PLANT(stop_force), 1, kEverything & ~kOnInputs, kGroupMachine),
  real_output(38, "stop_force[3]", "N", "End-stop force on the slider of leg 3, along +z", PLANT(stop_force), 2, kEverything & ~kOnInputs, kGroupMachine),
  real_output(39, "stop_force[4]", "N", "End-stop force on the slider of leg 4, along +z", PLANT(stop_force), 3, kEverything & ~kOnInputs, kGroupMachine),
  real_output(40, "lambda[1]", "N", "Lagrange multiplier of leg 1's loop closure, x row (Eq. 1)", PLANT(lambda), 0, kEverything, kGroupDynamics),
  real_output(41, "lambda[2]", "N", "Lagrange multiplier of leg 1's loop closure, y row (Eq. 1)", PLANT(lambda), 1, kEverything, kGroupDynamics),
  real_output(42, "lambda[3]", "N", "Lagrange multiplier of leg 1's loop closure, z row (Eq. 1)", PLANT(lambda), 2, kEverything, kGroupDynamics),
  real_output(43, "lambda[4]", "N", "Lagrange multiplier of leg 2's loop closure, x row (Eq. 1)", PLANT(lambda), 3, kEverything, kGroupDynamics),
  real_output(44, "lambda[5]", "N", "Lagrange multiplier of leg 2's loop closure, y row (Eq. 1)", PLANT(lambda), 4, kEverything, kGroupDynamics),
  real_output(45, "lambda[6]", "N", "Lagrange multiplier of leg 2's loop closure, z row (Eq. 1)", PLANT(lambda), 5, kEverything, kGroupDynamics),
  real_output(46, "lambda[7]", "N", "Lagrange multiplier of leg 3's loop closure, x row (Eq. 1)", PLANT(lambda), 6, kEverything, kGroupDynamics),
  real_output(47, "lambda[8]", "N", "Lagrange multiplier of leg 3's loop closure, y row (Eq. 1)", PLANT(lambda), 7, kEverything, kGroupDynamics),
  real_output(48, "lambda[9]", "N", "Lagrange multiplier of leg 3's loop closure, z row (Eq. 1)", PLANT(lambda), 8, kEverything, kGroupDynamics),
  real_output(49, "lambda[10]", "N", "Lagrange multiplier of leg 4's loop closure, x row (Eq. 1)", PLANT(lambda), 9, kEverything, kGroupDynamics),
  real_output(50, "lambda[11]", "N", "Lagrange multiplier of leg 4's loop closure, y row (Eq. 1)", PLANT(lambda), 10, kEverything, kGroupDynamics),
  real_output(51, "lambda[12]", "N", "Lagrange multiplier of leg 4's loop closure, z row (Eq. 1)", PLANT(lambda), 11, kEverything, kGroupDynamics),
  real_output(52, "constraint_residual", "m", "Norm of the loop closures ||C(q)|| (Eq. 15) at the current state", PLANT_SCALAR(residual), 0, kOnPositions, kGroupHealth),
  real_output(53, "jacobian_condition", "", "Condition number of the 4x4 actuator Jacobian d(rho)/d(x, y, z, phi), its phi column divided by 0.1 m", PLANT_SCALAR(condition), 0, kOnPositions, kGroupHealth),
  real_output(54, "F_hold[1]", "N", "Actuator force of leg 1 that would hold the current pose at rest under gravity, the payload and the current external wrench", PLANT(F_hold), 0, kOnPositions | kOnWrench, kGroupMachine),
  real_output(55, "F_hold[2]", "N", "The same for leg 2", PLANT(F_hold), 1, kOnPositions | kOnWrench, kGroupMachine),
  real_output(56, "F_hold[3]", "N", "The same for leg 3", PLANT(F_hold), 2, kOnPositions | kOnWrench, kGroupMachine),
  real_output(57, "F_hold[4]", "N", "The same for leg 4", PLANT(F_hold), 3, kOnPositions | kOnWrench, kGroupMachine),
  real_output(58, "kinetic_energy", "J", "Kinetic energy of the mechanism, the payload and the rotors", PLANT_SCALAR(kinetic), 0, kSliderRates, kGroupMachine),
  real_output(59, "potential_energy", "J", "Potential energy: gravity plus the end stops' springs", PLANT_SCALAR(potential), 0, kSliders, kGroupMachine),
  // Derivatives of the continuous states: 60..67.
  state_derivative(60, "der(x)", "m/s", "Derivative of x", PLANT(dy), 0, 0, kOnRates, kGroupState),
  state_derivative(61, "der(y)", "m/s", "Derivative of y", PLANT(dy), 1, 1, kOnRates, kGroupState),
  state_derivative(62, "der(z)", "m/s", "Derivative of z", PLANT(dy), 2, 2, kOnRates, kGroupState),
  state_derivative(63, "der(phi)", "rad/s", "Derivative of phi", PLANT(dy), 3, 3, kOnRates, kGroupState),
  state_derivative(64, "der(dx)", "m/s2", "Acceleration of P, x component (Eq. 13)", PLANT(dy), 4, 4, kEverything, kGroupDynamics),
  state_derivative(65, "der(dy)", "m/s2", "Acceleration of P, y component (Eq. 13)", PLANT(dy), 5, 5, kEverything, kGroupDynamics),
  state_derivative(66, "der(dz)", "m/s2", "Acceleration of P, z component (Eq. 13)", PLANT(dy), 6, 6, kEverything, kGroupDynamics),
  state_derivative(67, "der(dphi)", "rad/s2", "Angular acceleration of the platform about z (Eq. 13)", PLANT(dy), 7, 7, kEverything, kGroupDynamics),
  state_derivative(68, "der(actuator_work)", "W", "Power of the actuators, drives and external wrench", PLANT(dy), 8, 8, kSliderRates | kOnInputs, kGroupMachine),
  state_derivative(69, "der(dissipated_energy)", "W", "Power dissipated by friction and the end stops' damping", PLANT(dy), 9, 9, kEverything & ~kOnInputs, kGroupMachine),
  // Event indicators (Model Exchange): 70..74.
  event_indicator(70, "guard_condition_margin", "",
                  "1/jacobian_condition - 1/max_jacobian_condition: event indicator of the parallel-singularity guard "
                  "(positive within it)", PLANT(z), 0, 0, kOnPositions, kGroupHealth),
  event_indicator(71, "guard_leg_margin[1]", "",
                  "|cos(theta2) sin(theta2)| of leg 1 - min_leg_measure: event indicator of the leg-singularity guard "
                  "(positive within it)", PLANT(z), 1, 1, kOnPositions, kGroupHealth),
  event_indicator(72, "guard_leg_margin[2]", "", "The same for leg 2", PLANT(z), 2, 2, kOnPositions, kGroupHealth),
  event_indicator(73, "guard_leg_margin[3]", "", "The same for leg 3", PLANT(z), 3, 3, kOnPositions, kGroupHealth),
  event_indicator(74, "guard_leg_margin[4]", "", "The same for leg 4", PLANT(z), 4, 4, kOnPositions, kGroupHealth),
  event_indicator(75, "stop_margin_lower[1]", "m", "rho[1] - rho_min, +1e-12 m out of contact, -1e-12 m in contact (hysteresis): event indicator of leg 1's lower end stop (negative in contact)", PLANT(z), 5, 5, kSliders, kGroupMachine),
  event_indicator(76, "stop_margin_lower[2]", "m", "rho[2] - rho_min", PLANT(z), 6, 6, kSliders, kGroupMachine),
  event_indicator(77, "stop_margin_lower[3]", "m", "rho[3] - rho_min", PLANT(z), 7, 7, kSliders, kGroupMachine),
  event_indicator(78, "stop_margin_lower[4]", "m", "rho[4] - rho_min", PLANT(z), 8, 8, kSliders, kGroupMachine),
  event_indicator(79, "stop_margin_upper[1]", "m", "rho_max - rho[1]: event indicator of leg 1's upper end stop (negative in contact)", PLANT(z), 9, 9, kSliders, kGroupMachine),
  event_indicator(80, "stop_margin_upper[2]", "m", "rho_max - rho[2]", PLANT(z), 10, 10, kSliders, kGroupMachine),
  event_indicator(81, "stop_margin_upper[3]", "m", "rho_max - rho[3]", PLANT(z), 11, 11, kSliders, kGroupMachine),
  event_indicator(82, "stop_margin_upper[4]", "m", "rho_max - rho[4]", PLANT(z), 12, 12, kSliders, kGroupMachine),
  event_indicator(83, "stop_push_margin[1]", "N",
                  "k delta + d delta_dot of leg 1's end stop in contact, +1e-9 N while it pushes, -1e-9 N while "
                  "clamped (it would pull: no force): event indicator of the release within a contact; 1 without "
                  "contact", PLANT(z), 13, 13, kSliders | kSliderRates, kGroupMachine),
  event_indicator(84, "stop_push_margin[2]", "N", "The same for leg 2", PLANT(z), 14, 14, kSliders | kSliderRates, kGroupMachine),
  event_indicator(85, "stop_push_margin[3]", "N", "The same for leg 3", PLANT(z), 15, 15, kSliders | kSliderRates, kGroupMachine),
  event_indicator(86, "stop_push_margin[4]", "N", "The same for leg 4", PLANT(z), 16, 16, kSliders | kSliderRates, kGroupMachine),
  // Motor torques: 90..93.
  real_input(90, "tau[1]", 0.0, "N.m", "Motor torque of leg 1's drive: adds (2 pi/screw_lead) tau to F[1]", PLANT(u), 8, PLANT(du), kOnInputs),
  real_input(91, "tau[2]", 0.0, "N.m", "Motor torque of leg 2's drive", PLANT(u), 9, PLANT(du), kOnInputs),
  real_input(92, "tau[3]", 0.0, "N.m", "Motor torque of leg 3's drive", PLANT(u), 10, PLANT(du), kOnInputs),
  real_input(93, "tau[4]", 0.0, "N.m", "Motor torque of leg 4's drive", PLANT(u), 11, PLANT(du), kOnInputs),
};
// clang-format on

#undef PLANT
#undef PLANT_SCALAR

// Parameters: the mechanism (100..120), the initial state (130..137), the
// solver (140..147), the end stops' compliance (148..149), the machine
// (150..160), the solver's checks (161..162): the parameter table's rows.
static_assert(sorted_by_vr(kOwnVariables, std::size(kOwnVariables)), "the table must be sorted by value reference");
constexpr auto kVariables = merge_by_vr(kOwnVariables, parameter_variables<pkm::kFmuPlant>());
static_assert(sorted_by_vr(kVariables.data(), kVariables.size()), "value references must be unique");

std::unique_ptr<ModelData> create() { return std::make_unique<PlantData>(); }

const ModelDefinition kDefinition{
    "PKM4PUU",
    "4-PUU Schoenflies-motion parallel robot: forward dynamics (the plant)",
    "<p>Forward dynamics of the 4-PUU parallel kinematics machine with three translations and one rotation "
    "(3T1R) of M. Ruggiu, P. Rea and E. Ottaviano, <i>Dynamic model of a 3T1R parallel kinematics machine</i>: "
    "Lagrange equations in 16 redundant coordinates with 12 loop-closure constraints (Eq. 1), integrated on "
    "the platform pose and velocity (4 degrees of freedom). Inputs are the four actuator forces and an external "
    "wrench on the platform; outputs are the platform pose and velocity, the joint coordinates of the legs, the "
    "Lagrange multipliers, the constraint residual and the condition number of the actuator Jacobian. The legs "
    "work elbow-down (the platform hangs below the rods).</p>"
    "<p><b>Co-Simulation:</b> each communication step is integrated by CVODE (default) or by fixed-step RK4, "
    "with the end stops' contacts located as events inside the step. CVODE continues its history across "
    "communication points while the inputs continue smoothly, and restarts where they jump, after a failed step "
    "and after a restored FMU state. With FMI 2.0 the inputs can be interpolated linearly within a step "
    "(fmi2SetRealInputDerivatives, order 1). A step that cannot be completed, or that ends near a leg "
    "singularity (min_leg_measure) or a parallel singularity (max_jacobian_condition), returns Discard: with FMI 2.0 the "
    "last good state is kept at the last successful time and terminated = true; with FMI 3.0 the FMU is back in "
    "the state at the call, still in Step Mode, and the step may be retried. <b>Model Exchange:</b> the legs are reconstructed in closed form from the continuous "
    "states, so the loop closures hold exactly whatever the importer's integrator does. The event indicators "
    "are the singularity guards, whose crossing ends the simulation with a logged reason, and the end stops, "
    "whose crossings are events logged under logEvents. A pose that no leg can reach is refused by "
    "SetContinuousStates with Discard. FMU states can be saved, restored and serialised.</p>",
    kVariables.data(),
    kVariables.size(),
    /*n_states=*/kStates,
    /*n_position_states=*/4,
    /*n_event_indicators=*/kIndicators,
    /*can_interpolate_inputs=*/true,
    /*default_step=*/1e-3,
    /*default_stop=*/2.0,
    &create,
    /*provides_derivatives=*/true,
};

}  // namespace

const ModelDefinition& pkm4puu_definition() { return kDefinition; }

}  // namespace pkm_fmi
