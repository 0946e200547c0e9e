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
  struct Positive { const char* name; double value; };
  const Positive positive[] = {
      {"h", p.h},
      {"l", p.l},
      {"h_prime", p.h_prime},
      {"r_b", p.r_b},
      {"r_Q", p.r_Q},
      {"m_slider", p.m_slider},
      {"m_rod", p.m_rod},
      {"I_rod[1]", p.I_rod[0]},
      {"I_rod[2]", p.I_rod[1]},
      {"I_rod[3]", p.I_rod[2]},
      {"m_platform", p.m_platform},
      {"Izz_platform", p.Izz_platform},
  };
  for (const auto& e : positive) {
    if (!std::isfinite(e.value)) return describe(e.name, e.value, "is not finite");
    if (!(e.value > 0.0)) return describe(e.name, e.value, "must be positive");
  }
  static const char* const beta_names[] = {"beta[1]", "beta[2]", "beta[3]", "beta[4]"};
  static const char* const gamma_names[] = {"gamma[1]", "gamma[2]", "gamma[3]", "gamma[4]"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(p.beta[i])) return describe(beta_names[i], p.beta[i], "is not finite");
    if (!std::isfinite(p.gamma[i])) return describe(gamma_names[i], p.gamma[i], "is not finite");
  }
  if (!std::isfinite(p.g)) return describe("g", p.g, "is not finite");
  // The rod's inertia about its own axis x3 is the smallest; a rigid body's
  // principal moments must satisfy the triangle inequalities.
  const double a = p.I_rod[0], b = p.I_rod[1], c = p.I_rod[2];
  if (a > b + c || b > a + c || c > a + b)
    return describe("I_rod[1]", a, "violates the triangle inequality of principal moments with I_rod[2], I_rod[3]");
  // The machine around the mechanism.
  struct Range { const char* name; double value; double lo; bool lo_open; const char* why; };
  const Range ranges[] = {
      {"screw_lead", p.screw_lead, 0.0, true, "must be positive (m per revolution)"},
      {"rotor_inertia", p.rotor_inertia, 0.0, false, "must be zero or positive (kg*m^2)"},
      {"friction_viscous", p.friction_viscous, 0.0, false, "must be zero or positive (N*s/m)"},
      {"friction_coulomb", p.friction_coulomb, 0.0, false, "must be zero or positive (N)"},
      {"friction_velocity", p.friction_velocity, 0.0, true, "must be positive (m/s)"},
      {"stop_stiffness", p.stop_stiffness, 0.0, false, "must be zero or positive (N/m)"},
      {"stop_damping", p.stop_damping, 0.0, false, "must be zero or positive (N*s/m)"},
      {"payload_mass", p.payload_mass, 0.0, false, "must be zero or positive (kg)"},
      {"payload_Izz", p.payload_Izz, 0.0, false, "must be zero or positive (kg*m^2)"},
  };
  for (const auto& e : ranges) {
    if (!std::isfinite(e.value)) return describe(e.name, e.value, "is not finite");
    if (e.lo_open ? !(e.value > e.lo) : !(e.value >= e.lo)) return describe(e.name, e.value, e.why);
  }
  if (!std::isfinite(p.payload_com[0])) return describe("payload_com[1]", p.payload_com[0], "is not finite");
  if (!std::isfinite(p.payload_com[1])) return describe("payload_com[2]", p.payload_com[1], "is not finite");
  if (!std::isfinite(p.rho_min)) return describe("rho_min", p.rho_min, "is not finite");
  if (!std::isfinite(p.rho_max)) return describe("rho_max", p.rho_max, "is not finite");
  if (!(p.rho_max > p.rho_min)) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "parameter rho_max = %.17g must exceed rho_min = %.17g (m)", p.rho_max,
                  p.rho_min);
    return buf;
  }
  return {};
}

}  // namespace pkm
