// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/model/params.hpp"

#include <cmath>
#include <cstdio>

#include "pkm4puu/model/parameter_table.hpp"

namespace pkm {
namespace {

std::string describe(const char* name, double value, const char* why) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "parameter %s = %.17g %s", name, value, why);
  return buf;
}

}  // namespace

std::string check_parameter(const char* name, double value, double lo, double hi, const char* unit,
                            const ParameterRule& rule, bool integer) {
  const bool inside = value >= lo && value <= hi;
  if (inside && (!integer || value == std::floor(value))) return {};
  if (!std::isfinite(value)) return describe(name, value, "is not finite");
  const char* space = *unit ? " " : "";
  char why[160];
  if (rule.kind == ParameterRule::Says && !inside) {
    return describe(name, value, rule.text);
  } else if (!inside && value < lo && rule.kind == ParameterRule::Positive) {
    std::snprintf(why, sizeof why, "must be positive: at least %g%s%s", lo, space, unit);
  } else if (!inside && value < lo && rule.kind == ParameterRule::NonNegative) {
    std::snprintf(why, sizeof why, "must be zero or positive%s%s%s", *unit ? " (" : "", unit, *unit ? ")" : "");
  } else if (!inside) {
    std::snprintf(why, sizeof why, "lies outside its range [%.17g, %.17g]%s%s", lo, hi, space, unit);
  } else {
    std::snprintf(why, sizeof why, "must be a whole number");
  }
  return describe(name, value, why);
}

std::string validate(const Params& p) {
  // Each parameter against its row (parameter_table.hpp).
#define PKM_PARAMETER_ROW(...) PKM_PARAMETER_CHECK(p, __VA_ARGS__)
  PKM_PARAMETER_TABLE(PKM_PARAMETER_ONLY_Model)
#undef PKM_PARAMETER_ROW
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
