// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/model/params.hpp"

#include "pkm4puu/model/param_ranges.hpp"

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
  for (const ParamRange& e : kParamRanges) {
    const double value = e.value(p);
    if (!std::isfinite(value)) return describe(e.name, value, "is not finite");
    const bool above_lo = value >= e.lo;
    if (above_lo && value <= e.hi) continue;
    if (!above_lo && *e.why) return describe(e.name, value, e.why);
    char range[96];
    std::snprintf(range, sizeof range, "lies outside its physical range [%.17g, %.17g]", e.lo, e.hi);
    return describe(e.name, value, range);
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
