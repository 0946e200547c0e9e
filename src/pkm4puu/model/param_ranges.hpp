// SPDX-License-Identifier: BSD-2-Clause
// The one table of the parameters' physical ranges: validate() checks and
// words its messages from it, and the FMUs' variable tables take each
// parameter's start, min and max from it (the modelDescription).
#pragma once

#include <string_view>

#include "pkm4puu/model/params.hpp"

namespace pkm {

struct ParamRange {
  const char* name;                  // the FMI variable name
  double (*value)(const Params&);    // the parameter in a Params
  double lo;                         // lower bound, closed (the modelDescription's min)
  double hi;                         // upper bound, closed (the modelDescription's max)
  const char* why;                   // message below lo; empty: the plain range message
};

// Lower bounds as the model needs them (a parameter that must be positive
// has a positive floor, params.hpp: FMI's min is inclusive); upper bounds the
// physical ranges (params.hpp). Both ends are accepted.
inline constexpr ParamRange kParamRanges[] = {
    {"h", [](const Params& p) { return p.h; }, kMinLength, kMaxLength, "must be positive: at least 1e-06 m"},
    {"l", [](const Params& p) { return p.l; }, kMinLength, kMaxLength, "must be positive: at least 1e-06 m"},
    {"h_prime", [](const Params& p) { return p.h_prime; }, kMinLength, kMaxLength, "must be positive: at least 1e-06 m"},
    {"r_b", [](const Params& p) { return p.r_b; }, kMinLength, kMaxLength, "must be positive: at least 1e-06 m"},
    {"r_Q", [](const Params& p) { return p.r_Q; }, kMinLength, kMaxLength, "must be positive: at least 1e-06 m"},
    {"m_slider", [](const Params& p) { return p.m_slider; }, kMinMass, kMaxMass, "must be positive: at least 1e-06 kg"},
    {"m_rod", [](const Params& p) { return p.m_rod; }, kMinMass, kMaxMass, "must be positive: at least 1e-06 kg"},
    {"I_rod[1]", [](const Params& p) { return p.I_rod[0]; }, kMinInertia, kMaxInertia, "must be positive: at least 1e-12 kg*m^2"},
    {"I_rod[2]", [](const Params& p) { return p.I_rod[1]; }, kMinInertia, kMaxInertia, "must be positive: at least 1e-12 kg*m^2"},
    {"I_rod[3]", [](const Params& p) { return p.I_rod[2]; }, kMinInertia, kMaxInertia, "must be positive: at least 1e-12 kg*m^2"},
    {"m_platform", [](const Params& p) { return p.m_platform; }, kMinMass, kMaxMass, "must be positive: at least 1e-06 kg"},
    {"Izz_platform", [](const Params& p) { return p.Izz_platform; }, kMinInertia, kMaxInertia, "must be positive: at least 1e-12 kg*m^2"},
    {"beta[1]", [](const Params& p) { return p.beta[0]; }, -kMaxAngle, kMaxAngle, ""},
    {"beta[2]", [](const Params& p) { return p.beta[1]; }, -kMaxAngle, kMaxAngle, ""},
    {"beta[3]", [](const Params& p) { return p.beta[2]; }, -kMaxAngle, kMaxAngle, ""},
    {"beta[4]", [](const Params& p) { return p.beta[3]; }, -kMaxAngle, kMaxAngle, ""},
    {"gamma[1]", [](const Params& p) { return p.gamma[0]; }, -kMaxAngle, kMaxAngle, ""},
    {"gamma[2]", [](const Params& p) { return p.gamma[1]; }, -kMaxAngle, kMaxAngle, ""},
    {"gamma[3]", [](const Params& p) { return p.gamma[2]; }, -kMaxAngle, kMaxAngle, ""},
    {"gamma[4]", [](const Params& p) { return p.gamma[3]; }, -kMaxAngle, kMaxAngle, ""},
    {"g", [](const Params& p) { return p.g; }, -kMaxGravity, kMaxGravity, ""},
    // The machine around the mechanism.
    {"screw_lead", [](const Params& p) { return p.screw_lead; }, kMinLength, kMaxLength,
     "must be positive: at least 1e-06 m per revolution"},
    {"rotor_inertia", [](const Params& p) { return p.rotor_inertia; }, 0.0, kMaxInertia,
     "must be zero or positive (kg*m^2)"},
    {"friction_viscous", [](const Params& p) { return p.friction_viscous; }, 0.0, kMaxDamping,
     "must be zero or positive (N*s/m)"},
    {"friction_coulomb", [](const Params& p) { return p.friction_coulomb; }, 0.0, kMaxForce,
     "must be zero or positive (N)"},
    {"friction_velocity", [](const Params& p) { return p.friction_velocity; }, kMinSlipSpeed, kMaxSlipSpeed,
     "must be positive: at least 1e-09 m/s"},
    {"stop_stiffness", [](const Params& p) { return p.stop_stiffness; }, 0.0, kMaxStiffness,
     "must be zero or positive (N/m)"},
    {"stop_damping", [](const Params& p) { return p.stop_damping; }, 0.0, kMaxDamping,
     "must be zero or positive (N*s/m)"},
    {"payload_mass", [](const Params& p) { return p.payload_mass; }, 0.0, kMaxMass,
     "must be zero or positive (kg)"},
    {"payload_com[1]", [](const Params& p) { return p.payload_com[0]; }, -kMaxLength, kMaxLength, ""},
    {"payload_com[2]", [](const Params& p) { return p.payload_com[1]; }, -kMaxLength, kMaxLength, ""},
    {"payload_Izz", [](const Params& p) { return p.payload_Izz; }, 0.0, kMaxInertia,
     "must be zero or positive (kg*m^2)"},
    {"rho_min", [](const Params& p) { return p.rho_min; }, -kMaxLength, kMaxLength, ""},
    {"rho_max", [](const Params& p) { return p.rho_max; }, -kMaxLength, kMaxLength, ""},
};

/// The range of the parameter called name; used in a constant expression, a
/// name not in the table does not compile.
constexpr const ParamRange& param_range(std::string_view name) {
  for (const ParamRange& r : kParamRanges)
    if (name == r.name) return r;
  throw "no such parameter in kParamRanges";
}

}  // namespace pkm
