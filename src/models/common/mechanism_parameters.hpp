// SPDX-License-Identifier: BSD-2-Clause
// What both FMUs share: the mechanism's parameters (docs/model.md: Tables II
// and III, leg placement, gravity) as FMI variables, stored straight in a
// pkm::Params, and the singularity guards' limits in a pkm::GuardLimits,
// with the core's defaults as start values.
#pragma once

#include "fmi/model_data.hpp"
#include "fmi/variables.hpp"
#include "pkm4puu/model/param_ranges.hpp"
#include "pkm4puu/model/params.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_fmi {

/// Per-instance data of a model of the mechanism: its parameters.
struct MechanismData : ModelData {
  pkm::Params params{};
  pkm::GuardLimits limits{};
};

/// The core's defaults: the start values of the parameters.
inline constexpr pkm::Params kDefaultParams{};
inline constexpr pkm::GuardLimits kDefaultLimits{};

/// A parameter of pkm::Params as a fixed Real: its start (the core's
/// default), min and max come from the core's one table (param_ranges.hpp).
constexpr Variable mechanism_parameter(std::uint32_t vr, const char* name, const char* unit,
                                       const char* description, Ref value, int index) {
  const pkm::ParamRange& range = pkm::param_range(name);
  return real_parameter(vr, name, range.value(kDefaultParams), unit, description, value, index, range.lo,
                        range.hi);
}

}  // namespace pkm_fmi

#define PKM_FMI_PARAM(member)                                                                                         \
  [](::pkm_fmi::ModelData& d, int) -> void* { return &static_cast<::pkm_fmi::MechanismData&>(d).params.member; }
#define PKM_FMI_PARAM_ARRAY(member)                                                                                   \
  [](::pkm_fmi::ModelData& d, int i) -> void* {                                                                       \
    return &static_cast<::pkm_fmi::MechanismData&>(d).params.member[static_cast<std::size_t>(i)];                     \
  }

// Value references 100..120, identical in both FMUs.
#define PKM_FMI_MECHANISM_PARAMETERS                                                                                  \
  mechanism_parameter(100, "h", "m",                                                                                  \
                 "Height of the first revolute joint above the slider position: DH d1 = rho + h (Table II)",          \
                 PKM_FMI_PARAM(h), 0),                                                                                \
  mechanism_parameter(101, "l", "m", "Rod length, DH a3 (Table II)", PKM_FMI_PARAM(l), 0),                            \
  mechanism_parameter(102, "h_prime", "m",                                                                            \
                 "Offset of the platform joint Q along the third revolute axis, DH d4 (Table II)",                    \
                 PKM_FMI_PARAM(h_prime), 0),                                                                          \
  mechanism_parameter(103, "r_b", "m",                                                                                \
                 "Radius of the circle of the prismatic axes on the base (Table II)", PKM_FMI_PARAM(r_b), 0),         \
  mechanism_parameter(104, "r_Q", "m",                                                                                \
                 "Radius of the circle of the joints Q_i on the platform (Table II)", PKM_FMI_PARAM(r_Q), 0),         \
  mechanism_parameter(105, "beta[1]", "rad",                                                                          \
                 "Angle of leg 1 on the base: B_1 = r_b (cos beta_1, sin beta_1, 0), leg frame Rz(beta_1)",           \
                 PKM_FMI_PARAM_ARRAY(beta), 0),                                                                       \
  mechanism_parameter(106, "beta[2]", "rad", "Angle of leg 2 on the base",                                            \
                 PKM_FMI_PARAM_ARRAY(beta), 1),                                                                       \
  mechanism_parameter(107, "beta[3]", "rad", "Angle of leg 3 on the base",                                            \
                 PKM_FMI_PARAM_ARRAY(beta), 2),                                                                       \
  mechanism_parameter(108, "beta[4]", "rad", "Angle of leg 4 on the base",                                            \
                 PKM_FMI_PARAM_ARRAY(beta), 3),                                                                       \
  mechanism_parameter(109, "gamma[1]", "rad",                                                                         \
                 "Platform joint angle offset of leg 1: r_Q1 = r_Q (cos(beta_1 + gamma_1), sin(beta_1 + gamma_1), 0)", \
                 PKM_FMI_PARAM_ARRAY(gamma), 0),                                                                      \
  mechanism_parameter(110, "gamma[2]", "rad", "Platform joint angle offset of leg 2",                                 \
                 PKM_FMI_PARAM_ARRAY(gamma), 1),                                                                      \
  mechanism_parameter(111, "gamma[3]", "rad", "Platform joint angle offset of leg 3",                                 \
                 PKM_FMI_PARAM_ARRAY(gamma), 2),                                                                      \
  mechanism_parameter(112, "gamma[4]", "rad", "Platform joint angle offset of leg 4",                                 \
                 PKM_FMI_PARAM_ARRAY(gamma), 3),                                                                      \
  mechanism_parameter(113, "m_slider", "kg", "Mass of each slider, link 1 (Table III)",                               \
                 PKM_FMI_PARAM(m_slider), 0),                                                                         \
  mechanism_parameter(114, "m_rod", "kg", "Mass of each rod, link 3 (Table III)",                                     \
                 PKM_FMI_PARAM(m_rod), 0),                                                                            \
  mechanism_parameter(115, "I_rod[1]", "kg.m2",                                                                       \
                 "Rod inertia about its centre of mass, DH frame 3 axis x3 (along the rod) (Table III)",              \
                 PKM_FMI_PARAM_ARRAY(I_rod), 0),                                                                      \
  mechanism_parameter(116, "I_rod[2]", "kg.m2",                                                                       \
                 "Rod inertia about its centre of mass, DH frame 3 axis y3 (Table III)", PKM_FMI_PARAM_ARRAY(I_rod), 1), \
  mechanism_parameter(117, "I_rod[3]", "kg.m2",                                                                       \
                 "Rod inertia about its centre of mass, DH frame 3 axis z3 (Table III)", PKM_FMI_PARAM_ARRAY(I_rod), 2), \
  mechanism_parameter(118, "m_platform", "kg", "Mass of the moving platform (Table III)",                             \
                 PKM_FMI_PARAM(m_platform), 0),                                                                       \
  mechanism_parameter(119, "Izz_platform", "kg.m2",                                                                   \
                 "Platform inertia about the vertical axis through P (Table III)", PKM_FMI_PARAM(Izz_platform), 0),   \
  mechanism_parameter(120, "g", "m/s2",                                                                               \
                 "Gravitational acceleration, along -z of the base frame (0 switches gravity off)",                   \
                 PKM_FMI_PARAM(g), 0)

#define PKM_FMI_LIMIT(member)                                                                                         \
  [](::pkm_fmi::ModelData& d, int) -> void* { return &static_cast<::pkm_fmi::MechanismData&>(d).limits.member; }

// Value references 146..147, identical in both FMUs: the singularity guards
// (workspace_guard.hpp). The plant discards a step that ends beyond one; the
// inverse FMU answers Discard for a pose beyond one.
#define PKM_FMI_GUARD_PARAMETERS                                                                                      \
  real_parameter(146, "max_jacobian_condition", kDefaultLimits.max_jacobian_condition, "",                            \
                 "Parallel-singularity guard: largest admissible condition number of the actuator Jacobian (phi "     \
                 "column divided by 0.1 m); a pose beyond it is refused (plant: the step is discarded, state "        \
                 "kept, or in Model Exchange an event indicator ends the run; inverse: Discard, last good "           \
                 "outputs kept); > 1",                                                                                \
                 PKM_FMI_LIMIT(max_jacobian_condition), 0, pkm::kLeastConditionLimit),                                                      \
  real_parameter(147, "min_leg_measure", kDefaultLimits.min_leg_measure, "",                                          \
                 "Leg-singularity guard: smallest admissible |cos(theta2) sin(theta2)| of every leg (rod nearly "     \
                 "horizontal or vertical below it); a pose beyond it is refused as for max_jacobian_condition; "      \
                 "in [0, 0.5)",                                                                                       \
                 PKM_FMI_LIMIT(min_leg_measure), 0, 0.0, pkm::kGreatestLegMeasureLimit)

// Value references 150..160, identical in both FMUs: the machine around the
// mechanism (docs/model.md "The machine around the mechanism"). Every default
// leaves the paper's ideal machine unchanged.
#define PKM_FMI_MACHINE_PARAMETERS                                                                                    \
  mechanism_parameter(150, "screw_lead", "m",                                                                         \
                 "Lead p of each ball screw, per revolution: a motor torque tau acts as (2 pi/p) tau on its slider",  \
                 PKM_FMI_PARAM(screw_lead), 0),                                                                       \
  mechanism_parameter(151, "rotor_inertia", "kg.m2",                                                                  \
                 "Inertia J of each motor and screw: adds the reflected mass J (2 pi/p)^2 to its slider",             \
                 PKM_FMI_PARAM(rotor_inertia), 0),                                                                    \
  mechanism_parameter(152, "friction_viscous", "N.s/m",                                                               \
                 "Viscous friction b of each prismatic joint: -b drho",                                               \
                 PKM_FMI_PARAM(friction_viscous), 0),                                                                 \
  mechanism_parameter(153, "friction_coulomb", "N",                                                                   \
                 "Coulomb friction F_c of each prismatic joint, regularised: -F_c tanh(drho/friction_velocity)",      \
                 PKM_FMI_PARAM(friction_coulomb), 0),                                                                 \
  mechanism_parameter(154, "friction_velocity", "m/s",                                                                \
                 "Regularisation speed v_s of the Coulomb friction (> 0)", PKM_FMI_PARAM(friction_velocity), 0),      \
  mechanism_parameter(155, "rho_min", "m", "Lower end of each slider's travel (end stop)",                            \
                 PKM_FMI_PARAM(rho_min), 0),                                                                          \
  mechanism_parameter(156, "rho_max", "m",                                                                            \
                 "Upper end of each slider's travel (end stop), above rho_min", PKM_FMI_PARAM(rho_max), 0),           \
  mechanism_parameter(157, "payload_mass", "kg", "Mass of a payload fixed to the platform",                           \
                 PKM_FMI_PARAM(payload_mass), 0),                                                                     \
  mechanism_parameter(158, "payload_com[1]", "m",                                                                     \
                 "Payload centre of mass in the platform frame relative to P, x", PKM_FMI_PARAM_ARRAY(payload_com), 0), \
  mechanism_parameter(159, "payload_com[2]", "m",                                                                     \
                 "Payload centre of mass in the platform frame relative to P, y", PKM_FMI_PARAM_ARRAY(payload_com), 1), \
  mechanism_parameter(160, "payload_Izz", "kg.m2",                                                                    \
                 "Payload inertia about the vertical axis through its own centre of mass",                            \
                 PKM_FMI_PARAM(payload_Izz), 0)
