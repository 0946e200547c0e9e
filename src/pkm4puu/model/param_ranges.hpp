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
  double lo;                         // lower bound (the modelDescription's min)
  bool lo_open;                      // lo itself refused
  double hi;                         // upper bound, closed (the modelDescription's max)
  const char* why;                   // message below lo; empty: the plain range message
};

// Lower bounds as the model needs them; upper bounds the physical ranges
// (params.hpp).
inline constexpr ParamRange kParamRanges[] = {
    {"h", [](const Params& p) { return p.h; }, 0.0, true, kMaxLength, "must be positive"},
    {"l", [](const Params& p) { return p.l; }, 0.0, true, kMaxLength, "must be positive"},
    {"h_prime", [](const Params& p) { return p.h_prime; }, 0.0, true, kMaxLength, "must be positive"},
    {"r_b", [](const Params& p) { return p.r_b; }, 0.0, true, kMaxLength, "must be positive"},
    {"r_Q", [](const Params& p) { return p.r_Q; }, 0.0, true, kMaxLength, "must be positive"},
    {"m_slider", [](const Params& p) { return p.m_slider; }, 0.0, true, kMaxMass, "must be positive"},
    {"m_rod", [](const Params& p) { return p.m_rod; }, 0.0, true, kMaxMass, "must be positive"},
    {"I_rod[1]", [](const Params& p) { return p.I_rod[0]; }, 0.0, true, kMaxInertia, "must be positive"},
    {"I_rod[2]", [](const Params& p) { return p.I_rod[1]; }, 0.0, true, kMaxInertia, "must be positive"},
    {"I_rod[3]", [](const Params& p) { return p.I_rod[2]; }, 0.0, true, kMaxInertia, "must be positive"},
    {"m_platform", [](const Params& p) { return p.m_platform; }, 0.0, true, kMaxMass, "must be positive"},
    {"Izz_platform", [](const Params& p) { return p.Izz_platform; }, 0.0, true, kMaxInertia, "must be positive"},
    {"beta[1]", [](const Params& p) { return p.beta[0]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"beta[2]", [](const Params& p) { return p.beta[1]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"beta[3]", [](const Params& p) { return p.beta[2]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"beta[4]", [](const Params& p) { return p.beta[3]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"gamma[1]", [](const Params& p) { return p.gamma[0]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"gamma[2]", [](const Params& p) { return p.gamma[1]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"gamma[3]", [](const Params& p) { return p.gamma[2]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"gamma[4]", [](const Params& p) { return p.gamma[3]; }, -kMaxAngle, false, kMaxAngle, ""},
    {"g", [](const Params& p) { return p.g; }, -kMaxGravity, false, kMaxGravity, ""},
    // The machine around the mechanism.
    {"screw_lead", [](const Params& p) { return p.screw_lead; }, 0.0, true, kMaxLength,
     "must be positive (m per revolution)"},
    {"rotor_inertia", [](const Params& p) { return p.rotor_inertia; }, 0.0, false, kMaxInertia,
     "must be zero or positive (kg*m^2)"},
    {"friction_viscous", [](const Params& p) { return p.friction_viscous; }, 0.0, false, kMaxDamping,
     "must be zero or positive (N*s/m)"},
    {"friction_coulomb", [](const Params& p) { return p.friction_coulomb; }, 0.0, false, kMaxForce,
     "must be zero or positive (N)"},
    {"friction_velocity", [](const Params& p) { return p.friction_velocity; }, 0.0, true, kMaxSlipSpeed,
     "must be positive (m/s)"},
    {"stop_stiffness", [](const Params& p) { return p.stop_stiffness; }, 0.0, false, kMaxStiffness,
     "must be zero or positive (N/m)"},
    {"stop_damping", [](const Params& p) { return p.stop_damping; }, 0.0, false, kMaxDamping,
     "must be zero or positive (N*s/m)"},
    {"payload_mass", [](const Params& p) { return p.payload_mass; }, 0.0, false, kMaxMass,
     "must be zero or positive (kg)"},
    {"payload_com[1]", [](const Params& p) { return p.payload_com[0]; }, -kMaxLength, false, kMaxLength, ""},
    {"payload_com[2]", [](const Params& p) { return p.payload_com[1]; }, -kMaxLength, false, kMaxLength, ""},
    {"payload_Izz", [](const Params& p) { return p.payload_Izz; }, 0.0, false, kMaxInertia,
     "must be zero or positive (kg*m^2)"},
    {"rho_min", [](const Params& p) { return p.rho_min; }, -kMaxLength, false, kMaxLength, ""},
    {"rho_max", [](const Params& p) { return p.rho_max; }, -kMaxLength, false, kMaxLength, ""},
};

/// The range of the parameter called name; used in a constant expression, a
/// name not in the table does not compile.
constexpr const ParamRange& param_range(std::string_view name) {
  for (const ParamRange& r : kParamRanges)
    if (name == r.name) return r;
  throw "no such parameter in kParamRanges";
}

}  // namespace pkm
