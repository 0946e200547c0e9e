// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/solver_settings.hpp"

#include <cmath>
#include <cstdio>

namespace pkm {

double rk4_steps_for(double span, double rk4_step) { return std::ceil(span / rk4_step - 1e-9); }

std::string validate(const SolverSettings& s) {
  char buf[160];
  // The choices first: the FMUs and the C API pass their integers through
  // unchecked, and this is the one place that words them.
  if (s.solver != Solver::Cvode && s.solver != Solver::Rk4 && s.solver != Solver::Rosenbrock) {
    std::snprintf(buf, sizeof buf, "solver = %d must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)",
                  static_cast<int>(s.solver));
    return buf;
  }
  if (s.cvode_method != CvodeMethod::Adams && s.cvode_method != CvodeMethod::BDF) {
    std::snprintf(buf, sizeof buf, "cvode_method = %d must be 0 (Adams) or 1 (BDF)", static_cast<int>(s.cvode_method));
    return buf;
  }
  if (s.formulation != Formulation::Augmented && s.formulation != Formulation::NullSpaceQR &&
      s.formulation != Formulation::LegPartitioned) {
    std::snprintf(buf, sizeof buf, "formulation = %d must be 0 (Eq. 12), 1 (Eq. 13, QR) or 2 (Eq. 13, leg-partitioned)",
                  static_cast<int>(s.formulation));
    return buf;
  }
  if (s.solver == Solver::Cvode && !cvode_available())
    return "solver = 0 (CVODE) is not in this build (a source-code FMU compiled without SUNDIALS): set solver = 1 (RK4)";
  if (!(s.rk4_step > 0.0) || !std::isfinite(s.rk4_step)) {
    std::snprintf(buf, sizeof buf, "rk4_step = %.17g s must be positive and finite", s.rk4_step);
    return buf;
  }
  if (!(s.rk4_step >= kMinRk4Step && s.rk4_step <= kMaxRk4Step)) {
    std::snprintf(buf, sizeof buf, "rk4_step = %.17g s lies outside its range [%g, %g] s", s.rk4_step, kMinRk4Step,
                  kMaxRk4Step);
    return buf;
  }
  if (!(s.rtol >= kMinRtol) || !(s.rtol <= kMaxRtol)) {
    std::snprintf(buf, sizeof buf, "rtol = %.17g must lie in [%g, %g]", s.rtol, kMinRtol, kMaxRtol);
    return buf;
  }
  if (!(s.atol >= kMinAtol) || !(s.atol <= kMaxAtol)) {
    std::snprintf(buf, sizeof buf, "atol = %.17g must lie in [%g, %g]", s.atol, kMinAtol, kMaxAtol);
    return buf;
  }
  if (!(s.work_budget >= kMinWorkBudget && s.work_budget <= kMaxWorkBudget)) {
    std::snprintf(buf, sizeof buf, "work_budget = %.17g must lie in [%g, %g] inner steps per grid step",
                  s.work_budget, kMinWorkBudget, kMaxWorkBudget);
    return buf;
  }
  if (!(s.energy_tolerance >= 0.0 && s.energy_tolerance <= kMaxEnergyTolerance)) {
    std::snprintf(buf, sizeof buf, "energy_tolerance = %.17g J must lie in [0, %g] J (0: off)", s.energy_tolerance,
                  kMaxEnergyTolerance);
    return buf;
  }
  return validate(s.limits());
}

}  // namespace pkm
