#include "params.hpp"

#include <cmath>
#include <cstdio>

namespace pkm {
namespace {

std::string describe(const char* name, double value, const char* why) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "parameter %s = %.17g %s", name, value, why);
  return buf;
}

}  // namespace

std::string validate(const Params& p) {
  // Lower bounds as the model needs them; upper bounds the physical ranges
  // (params.hpp), the same as the modelDescription's max.
  struct Range { const char* name; double value; double lo; bool lo_open; double hi; const char* why; };
  const Range ranges[] = {
      {"h", p.h, 0.0, true, kMaxLength, "must be positive"},
      {"l", p.l, 0.0, true, kMaxLength, "must be positive"},
      {"h_prime", p.h_prime, 0.0, true, kMaxLength, "must be positive"},
      {"r_b", p.r_b, 0.0, true, kMaxLength, "must be positive"},
      {"r_Q", p.r_Q, 0.0, true, kMaxLength, "must be positive"},
      {"m_slider", p.m_slider, 0.0, true, kMaxMass, "must be positive"},
      {"m_rod", p.m_rod, 0.0, true, kMaxMass, "must be positive"},
      {"I_rod[1]", p.I_rod[0], 0.0, true, kMaxInertia, "must be positive"},
      {"I_rod[2]", p.I_rod[1], 0.0, true, kMaxInertia, "must be positive"},
      {"I_rod[3]", p.I_rod[2], 0.0, true, kMaxInertia, "must be positive"},
      {"m_platform", p.m_platform, 0.0, true, kMaxMass, "must be positive"},
      {"Izz_platform", p.Izz_platform, 0.0, true, kMaxInertia, "must be positive"},
      {"beta[1]", p.beta[0], -kMaxAngle, false, kMaxAngle, ""},
      {"beta[2]", p.beta[1], -kMaxAngle, false, kMaxAngle, ""},
      {"beta[3]", p.beta[2], -kMaxAngle, false, kMaxAngle, ""},
      {"beta[4]", p.beta[3], -kMaxAngle, false, kMaxAngle, ""},
      {"gamma[1]", p.gamma[0], -kMaxAngle, false, kMaxAngle, ""},
      {"gamma[2]", p.gamma[1], -kMaxAngle, false, kMaxAngle, ""},
      {"gamma[3]", p.gamma[2], -kMaxAngle, false, kMaxAngle, ""},
      {"gamma[4]", p.gamma[3], -kMaxAngle, false, kMaxAngle, ""},
      {"g", p.g, -kMaxGravity, false, kMaxGravity, ""},
      // The machine around the mechanism.
      {"screw_lead", p.screw_lead, 0.0, true, kMaxLength, "must be positive (m per revolution)"},
      {"rotor_inertia", p.rotor_inertia, 0.0, false, kMaxInertia, "must be zero or positive (kg*m^2)"},
      {"friction_viscous", p.friction_viscous, 0.0, false, kMaxDamping, "must be zero or positive (N*s/m)"},
      {"friction_coulomb", p.friction_coulomb, 0.0, false, kMaxForce, "must be zero or positive (N)"},
      {"friction_velocity", p.friction_velocity, 0.0, true, kMaxSlipSpeed, "must be positive (m/s)"},
      {"stop_stiffness", p.stop_stiffness, 0.0, false, kMaxStiffness, "must be zero or positive (N/m)"},
      {"stop_damping", p.stop_damping, 0.0, false, kMaxDamping, "must be zero or positive (N*s/m)"},
      {"payload_mass", p.payload_mass, 0.0, false, kMaxMass, "must be zero or positive (kg)"},
      {"payload_com[1]", p.payload_com[0], -kMaxLength, false, kMaxLength, ""},
      {"payload_com[2]", p.payload_com[1], -kMaxLength, false, kMaxLength, ""},
      {"payload_Izz", p.payload_Izz, 0.0, false, kMaxInertia, "must be zero or positive (kg*m^2)"},
      {"rho_min", p.rho_min, -kMaxLength, false, kMaxLength, ""},
      {"rho_max", p.rho_max, -kMaxLength, false, kMaxLength, ""},
  };
  for (const auto& e : ranges) {
    if (!std::isfinite(e.value)) return describe(e.name, e.value, "is not finite");
    const bool above_lo = e.lo_open ? e.value > e.lo : e.value >= e.lo;
    if (above_lo && e.value <= e.hi) continue;
    if (!above_lo && *e.why) return describe(e.name, e.value, e.why);
    char range[96];
    std::snprintf(range, sizeof range, "lies outside its physical range %s%.17g, %.17g]", e.lo_open ? "(" : "[",
                  e.lo, e.hi);
    return describe(e.name, e.value, range);
  }
  // The rod's inertia about its own axis x3 is the smallest; a rigid body's
  // principal moments must satisfy the triangle inequalities.
  const double a = p.I_rod[0], b = p.I_rod[1], c = p.I_rod[2];
  if (a > b + c || b > a + c || c > a + b)
    return describe("I_rod[1]", a, "violates the triangle inequality of principal moments with I_rod[2], I_rod[3]");
  if (!(p.rho_max > p.rho_min)) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "parameter rho_max = %.17g must exceed rho_min = %.17g (m)", p.rho_max,
                  p.rho_min);
    return buf;
  }
  return {};
}

}  // namespace pkm
