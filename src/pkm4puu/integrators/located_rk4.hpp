// SPDX-License-Identifier: BSD-2-Clause
// One fixed RK4 grid step across the end stops' switches (located_step.hpp):
// split where the contact mode changes and sub-stepped where the friction or
// a held stop is stiff, so that RK4 resolves them.
#pragma once

#include "pkm4puu/integrators/located_step.hpp"
#include "pkm4puu/integrators/rk4.hpp"

namespace pkm {

/// located_fixed_step with RK4; `sys` also provides
///   Status rates(double t, const Vec10& x, Vec10& xdot)  under the held stops.
template <class System>
Status located_rk4_step(System& sys, double t0, double t1, const InnerSteps& inner, Vec10& x, unsigned& mode,
                        Vec4& rho, bool& rho_valid, long& switches, double& t, WorkBudget& budget) {
  auto f = [&sys](double tt, const Vec10& xx, Vec10& xdot) { return sys.rates(tt, xx, xdot); };
  auto step = [&f](double tt, double h, Vec10& xx, double&) { return rk4_step(f, tt, h, xx); };
  StepControl none;  // fixed steps: no estimate
  return located_fixed_step(sys, step, t0, t1, inner, none, x, mode, rho, rho_valid, switches, t, budget);
}

}  // namespace pkm
