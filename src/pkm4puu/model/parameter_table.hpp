// SPDX-License-Identifier: BSD-2-Clause
// The one table of the parameters: every parameter of the FMUs and the C
// API, one row each, as an X-macro list (MuJoCo's mjxmacro.h pattern). Each
// user expands the rows it needs: the range checks and their messages
// (params.cpp, workspace_guard.cpp, solver_settings.cpp), the rows as data
// with their accessors (sim/parameters.hpp: the C API's parameters by name,
// the FMUs' parameter variables, the documentation's reference).
//
// A row: X(vr, name, target, member, type, unit, lo, hi, rule, variability, fmus, description)
//   vr           the FMUs' value reference (stable: part of their interface)
//   name         the FMUs' name, which the C API and Python take too
//   target       where the value lives: Model (pkm::Params), Guard
//                (pkm::GuardLimits, also in pkm::SolverSettings), Solver
//                (pkm::SolverSettings), Initial (the plant FMU's initial state)
//   member       the member expression within the target
//   type         Real or Integer (an enumeration, stored as int32 by the FMUs)
//   unit         the FMUs' unit ("" dimensionless)
//   lo, hi       the closed range (the model descriptions' min and max)
//   rule         what the message says outside it (ParameterRule below)
//   variability  Fixed or Tunable: the FMUs' variability; a Tunable row may change
//                during a run (Co-Simulation: between steps; Model Exchange:
//                in Event Mode; the C API: pkm_set_parameter keeps the run),
//                which Plant::retune applies
//   fmus         Both or Plant: the FMUs that have it
//   description  the FMUs' description
// Rows are in increasing value reference. The default is the target
// struct's own (Params{}, SolverSettings{}, GuardLimits{}, InitialState{}).
// PKM_PARAMETER_TABLE(PKM_PARAMETER_ONLY_Model) applies PKM_PARAMETER_ROW,
// which the user defines, to the rows of that target only (likewise _Guard,
// _Solver, _Initial).
#pragma once

#include <limits>
#include <string>
#include <type_traits>

namespace pkm {

/// What a parameter's message says when its value lies outside [lo, hi]:
/// a floor that makes it positive or zero ("must be positive: at least
/// 1e-06 m"), or a sentence of its own (choices), else the range.
struct ParameterRule {
  enum Kind { InRange, Positive, NonNegative, Says } kind;
  const char* text;  // Says: the sentence, e.g. "must be 0 (Adams) or 1 (BDF)"
};
inline constexpr ParameterRule kInRange{ParameterRule::InRange, ""};
inline constexpr ParameterRule kPositive{ParameterRule::Positive, ""};
inline constexpr ParameterRule kNonNegative{ParameterRule::NonNegative, ""};
constexpr ParameterRule says(const char* text) { return {ParameterRule::Says, text}; }
/// hi of a parameter without an upper bound (no max attribute).
inline constexpr double kNoUpperLimit = std::numeric_limits<double>::infinity();

/// "" if value lies in [lo, hi]; otherwise "parameter <name> = <value> ..."
/// worded by the rule (a non-finite value "is not finite"; an Integer row's
/// value must be a whole number).
std::string check_parameter(const char* name, double value, double lo, double hi, const char* unit,
                            const ParameterRule& rule, bool integer = false);

}  // namespace pkm

// Reading a target member as a double, and writing one (Integer: the
// member is an enumeration).
#define PKM_PARAMETER_GET_Real(e) (e)
#define PKM_PARAMETER_GET_Integer(e) static_cast<double>(static_cast<int>(e))
#define PKM_PARAMETER_SET_Real(e, v) ((e) = (v))
#define PKM_PARAMETER_SET_Integer(e, v) ((e) = static_cast<std::decay_t<decltype(e)>>(static_cast<int>(v)))
#define PKM_PARAMETER_IS_INTEGER_Real false
#define PKM_PARAMETER_IS_INTEGER_Integer true
// A row's check of object.member, inside a function returning the message
// (std::string): PKM_PARAMETER_ROW(...) defined as PKM_PARAMETER_CHECK(object, ...).
#define PKM_PARAMETER_CHECK(object, vr, name, target, member, type, unit, lo, hi, rule, ...)                  \
  if (std::string why = ::pkm::check_parameter(name, PKM_PARAMETER_GET_##type((object).member), lo, hi, unit, \
                                               rule, PKM_PARAMETER_IS_INTEGER_##type);                       \
      !why.empty())                                                                                          \
    return why;

// clang-format off
#define PKM_PARAMETER_TABLE(X) \
  X(100, "h", Model, h, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, \
    "Height of the first revolute joint above the slider position: DH d1 = rho + h (Table II)") \
  X(101, "l", Model, l, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, "Rod length, DH a3 (Table II)") \
  X(102, "h_prime", Model, h_prime, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, \
    "Offset of the platform joint Q along the third revolute axis, DH d4 (Table II)") \
  X(103, "r_b", Model, r_b, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, \
    "Radius of the circle of the prismatic axes on the base (Table II)") \
  X(104, "r_Q", Model, r_Q, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, \
    "Radius of the circle of the joints Q_i on the platform (Table II)") \
  X(105, "beta[1]", Model, beta[0], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, \
    "Angle of leg 1 on the base: B_1 = r_b (cos beta_1, sin beta_1, 0), leg frame Rz(beta_1)") \
  X(106, "beta[2]", Model, beta[1], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, "Angle of leg 2 on the base") \
  X(107, "beta[3]", Model, beta[2], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, "Angle of leg 3 on the base") \
  X(108, "beta[4]", Model, beta[3], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, "Angle of leg 4 on the base") \
  X(109, "gamma[1]", Model, gamma[0], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, \
    "Platform joint angle offset of leg 1: r_Q1 = r_Q (cos(beta_1 + gamma_1), sin(beta_1 + gamma_1), 0)") \
  X(110, "gamma[2]", Model, gamma[1], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, \
    "Platform joint angle offset of leg 2") \
  X(111, "gamma[3]", Model, gamma[2], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, \
    "Platform joint angle offset of leg 3") \
  X(112, "gamma[4]", Model, gamma[3], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Both, \
    "Platform joint angle offset of leg 4") \
  X(113, "m_slider", Model, m_slider, Real, "kg", kMinMass, kMaxMass, kPositive, Fixed, Both, \
    "Mass of each slider, link 1 (Table III)") \
  X(114, "m_rod", Model, m_rod, Real, "kg", kMinMass, kMaxMass, kPositive, Fixed, Both, "Mass of each rod, link 3 (Table III)") \
  X(115, "I_rod[1]", Model, I_rod[0], Real, "kg.m2", kMinInertia, kMaxInertia, kPositive, Fixed, Both, \
    "Rod inertia about its centre of mass, DH frame 3 axis x3 (along the rod) (Table III)") \
  X(116, "I_rod[2]", Model, I_rod[1], Real, "kg.m2", kMinInertia, kMaxInertia, kPositive, Fixed, Both, \
    "Rod inertia about its centre of mass, DH frame 3 axis y3 (Table III)") \
  X(117, "I_rod[3]", Model, I_rod[2], Real, "kg.m2", kMinInertia, kMaxInertia, kPositive, Fixed, Both, \
    "Rod inertia about its centre of mass, DH frame 3 axis z3 (Table III)") \
  X(118, "m_platform", Model, m_platform, Real, "kg", kMinMass, kMaxMass, kPositive, Fixed, Both, \
    "Mass of the moving platform (Table III)") \
  X(119, "Izz_platform", Model, Izz_platform, Real, "kg.m2", kMinInertia, kMaxInertia, kPositive, Fixed, Both, \
    "Platform inertia about the vertical axis through P (Table III)") \
  X(120, "g", Model, g, Real, "m/s2", -kMaxGravity, kMaxGravity, kInRange, Fixed, Both, \
    "Gravitational acceleration, along -z of the base frame (0 switches gravity off)") \
  X(130, "x0", Initial, pose0[0], Real, "m", -kMaxLength, kMaxLength, kInRange, Fixed, Plant, "Initial x of P") \
  X(131, "y0", Initial, pose0[1], Real, "m", -kMaxLength, kMaxLength, kInRange, Fixed, Plant, "Initial y of P") \
  X(132, "z0", Initial, pose0[2], Real, "m", -kMaxLength, kMaxLength, kInRange, Fixed, Plant, \
    "Initial z of P (home pose: 0.05 m)") \
  X(133, "phi0", Initial, pose0[3], Real, "rad", -kMaxAngle, kMaxAngle, kInRange, Fixed, Plant, \
    "Initial platform rotation about z") \
  X(134, "dx0", Initial, vel0[0], Real, "m/s", -kMaxSpeed, kMaxSpeed, kInRange, Fixed, Plant, \
    "Initial velocity of P, x component") \
  X(135, "dy0", Initial, vel0[1], Real, "m/s", -kMaxSpeed, kMaxSpeed, kInRange, Fixed, Plant, \
    "Initial velocity of P, y component") \
  X(136, "dz0", Initial, vel0[2], Real, "m/s", -kMaxSpeed, kMaxSpeed, kInRange, Fixed, Plant, \
    "Initial velocity of P, z component") \
  X(137, "dphi0", Initial, vel0[3], Real, "rad/s", -kMaxSpeed / kConditionLength, kMaxSpeed / kConditionLength, \
    kInRange, Fixed, Plant, "Initial platform angular velocity about z") \
  X(140, "solver", Solver, solver, Integer, "", 0, 2, says("must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)"), Fixed, Plant, \
    "Co-Simulation integrator: 0 = CVODE (variable step, rtol and atol), 1 = fixed-step RK4 (rk4_step), as in " \
    "the paper, sub-stepped where friction or a held end stop is stiff, 2 = fixed-step Rosenbrock (ROS2, " \
    "linearly implicit with the analytic Jacobian: stiff friction and end stops in real time)") \
  X(141, "rk4_step", Solver, rk4_step, Real, "s", kMinRk4Step, kMaxRk4Step, kPositive, Fixed, Plant, \
    "Fixed step of RK4 and Rosenbrock: a communication step is split into whole steps no longer than this") \
  X(142, "rtol", Solver, rtol, Real, "", kMinRtol, kMaxRtol, kInRange, Fixed, Plant, \
    "CVODE relative tolerance (looser than its maximum, impacts on undamped stiff stops run away)") \
  X(143, "atol", Solver, atol, Real, "", kMinAtol, kMaxAtol, kInRange, Fixed, Plant, \
    "CVODE absolute tolerance (on the pose, m and rad, the velocity, and the energy integrals, J; on the " \
    "velocities at most friction_velocity / 10 where Coulomb friction acts): below its minimum the stiffest " \
    "stops' impact needs more work than one step may take, above its maximum impacts on undamped stiff stops " \
    "run away") \
  X(144, "cvode_method", Solver, cvode_method, Integer, "", 0, 1, says("must be 0 (Adams) or 1 (BDF)"), Fixed, Plant, \
    "CVODE method: 0 = Adams-Moulton (non-stiff; BDF on a machine whose friction or stop damping against the " \
    "slider's mass exceeds 1e5 1/s), 1 = BDF") \
  X(145, "formulation", Solver, formulation, Integer, "", 0, 2, \
    says("must be 0 (Eq. 12), 1 (Eq. 13, QR) or 2 (Eq. 13, leg-partitioned)"), Fixed, Plant, \
    "Forward dynamics: 0 = augmented saddle-point system (Eq. 12), 1 = null-space projection with a QR " \
    "(Eq. 13), 2 = null space from the leg blocks (Eq. 13, leg-partitioned)") \
  X(146, "max_jacobian_condition", Guard, max_jacobian_condition, Real, "", kLeastConditionLimit, kNoUpperLimit, \
    says("must be greater than 1 (a condition number is at least 1)"), Fixed, Both, \
    "Parallel-singularity guard: largest admissible condition number of the actuator Jacobian (phi " \
    "column divided by 0.1 m); a pose beyond it is refused (plant: the step is discarded, state " \
    "kept, or in Model Exchange an event indicator ends the run; inverse: Discard, last good " \
    "outputs kept); > 1") \
  X(147, "min_leg_measure", Guard, min_leg_measure, Real, "", 0.0, kGreatestLegMeasureLimit, \
    says("must lie in [0, 0.5) (|cos theta2 sin theta2| is at most 0.5)"), Fixed, Both, \
    "Leg-singularity guard: smallest admissible |cos(theta2) sin(theta2)| of every leg (rod nearly " \
    "horizontal or vertical below it); a pose beyond it is refused as for max_jacobian_condition; " \
    "in [0, 0.5)") \
  X(148, "stop_stiffness", Model, stop_stiffness, Real, "N/m", 0.0, kMaxStiffness, kNonNegative, Fixed, Plant, \
    "Stiffness k of the compliant end stops: k delta + d delta_dot pushes a slider back past rho_min or rho_max by " \
    "delta (never pulls)") \
  X(149, "stop_damping", Model, stop_damping, Real, "N.s/m", 0.0, kMaxDamping, kNonNegative, Fixed, Plant, \
    "Damping d of the end stops") \
  X(150, "screw_lead", Model, screw_lead, Real, "m", kMinLength, kMaxLength, kPositive, Fixed, Both, \
    "Lead p of each ball screw, per revolution: a motor torque tau acts as (2 pi/p) tau on its slider") \
  X(151, "rotor_inertia", Model, rotor_inertia, Real, "kg.m2", 0.0, kMaxInertia, kNonNegative, Fixed, Both, \
    "Inertia J of each motor and screw: adds the reflected mass J (2 pi/p)^2 to its slider") \
  X(152, "friction_viscous", Model, friction_viscous, Real, "N.s/m", 0.0, kMaxDamping, kNonNegative, Fixed, Both, \
    "Viscous friction b of each prismatic joint: -b drho") \
  X(153, "friction_coulomb", Model, friction_coulomb, Real, "N", 0.0, kMaxForce, kNonNegative, Fixed, Both, \
    "Coulomb friction F_c of each prismatic joint, regularised: -F_c tanh(drho/friction_velocity)") \
  X(154, "friction_velocity", Model, friction_velocity, Real, "m/s", kMinSlipSpeed, kMaxSlipSpeed, kPositive, Fixed, \
    Both, "Regularisation speed v_s of the Coulomb friction (> 0)") \
  X(155, "rho_min", Model, rho_min, Real, "m", -kMaxLength, kMaxLength, kInRange, Fixed, Both, \
    "Lower end of each slider's travel (end stop)") \
  X(156, "rho_max", Model, rho_max, Real, "m", -kMaxLength, kMaxLength, kInRange, Fixed, Both, \
    "Upper end of each slider's travel (end stop), above rho_min") \
  X(157, "payload_mass", Model, payload_mass, Real, "kg", 0.0, kMaxMass, kNonNegative, Tunable, Both, \
    "Mass of a payload fixed to the platform; tunable: a grasp or a release during a run keeps the platform's " \
    "velocity and books the jump of kinetic and potential energy into actuator_work") \
  X(158, "payload_com[1]", Model, payload_com[0], Real, "m", -kMaxLength, kMaxLength, kInRange, Tunable, Both, \
    "Payload centre of mass in the platform frame relative to P, x") \
  X(159, "payload_com[2]", Model, payload_com[1], Real, "m", -kMaxLength, kMaxLength, kInRange, Tunable, Both, \
    "Payload centre of mass in the platform frame relative to P, y") \
  X(160, "payload_Izz", Model, payload_Izz, Real, "kg.m2", 0.0, kMaxInertia, kNonNegative, Tunable, Both, \
    "Payload inertia about the vertical axis through its own centre of mass") \
  X(161, "work_budget", Solver, work_budget, Real, "", kMinWorkBudget, kMaxWorkBudget, kInRange, Fixed, Plant, \
    "Fixed-step solvers: inner steps (grid steps, stiff sub-steps, rejected steps, bisection trials locating " \
    "end-stop events) allowed per grid step, summed over a communication step and at most 1e5 per step " \
    "whatever its length; a step that needs more returns Discard with the reason") \
  X(162, "energy_tolerance", Solver, energy_tolerance, Real, "J", 0.0, kMaxEnergyTolerance, kNonNegative, Fixed, \
    Plant, "Energy audit as a run-time check: a communication step whose audit residual (change of " \
    "kinetic + potential - actuator_work + dissipated_energy) exceeds this returns Discard with the " \
    "figures; 0 = off")
// clang-format on

// The rows of one target (PKM_PARAMETER_ONLY_<target>, above).
#define PKM_PARAMETER_ONLY_Model(vr, name, target, ...) PKM_PARAMETER_PICK_Model_##target(vr, name, target, __VA_ARGS__)
#define PKM_PARAMETER_ONLY_Guard(vr, name, target, ...) PKM_PARAMETER_PICK_Guard_##target(vr, name, target, __VA_ARGS__)
#define PKM_PARAMETER_ONLY_Solver(vr, name, target, ...) PKM_PARAMETER_PICK_Solver_##target(vr, name, target, __VA_ARGS__)
#define PKM_PARAMETER_ONLY_Initial(vr, name, target, ...) PKM_PARAMETER_PICK_Initial_##target(vr, name, target, __VA_ARGS__)
#define PKM_PARAMETER_PICK_Model_Model(...) PKM_PARAMETER_ROW(__VA_ARGS__)
#define PKM_PARAMETER_PICK_Model_Guard(...)
#define PKM_PARAMETER_PICK_Model_Solver(...)
#define PKM_PARAMETER_PICK_Model_Initial(...)
#define PKM_PARAMETER_PICK_Guard_Model(...)
#define PKM_PARAMETER_PICK_Guard_Guard(...) PKM_PARAMETER_ROW(__VA_ARGS__)
#define PKM_PARAMETER_PICK_Guard_Solver(...)
#define PKM_PARAMETER_PICK_Guard_Initial(...)
#define PKM_PARAMETER_PICK_Solver_Model(...)
#define PKM_PARAMETER_PICK_Solver_Guard(...)
#define PKM_PARAMETER_PICK_Solver_Solver(...) PKM_PARAMETER_ROW(__VA_ARGS__)
#define PKM_PARAMETER_PICK_Solver_Initial(...)
#define PKM_PARAMETER_PICK_Initial_Model(...)
#define PKM_PARAMETER_PICK_Initial_Guard(...)
#define PKM_PARAMETER_PICK_Initial_Solver(...)
#define PKM_PARAMETER_PICK_Initial_Initial(...) PKM_PARAMETER_ROW(__VA_ARGS__)
