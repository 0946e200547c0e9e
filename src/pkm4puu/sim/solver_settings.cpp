// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/solver_settings.hpp"

#include <cmath>

#include "pkm4puu/model/parameter_table.hpp"

namespace pkm {

double rk4_steps_for(double span, double rk4_step) { return std::ceil(span / rk4_step - 1e-9); }

std::string validate(const SolverSettings& s) {
  // Each setting against its row (parameter_table.hpp): the FMUs and the C
  // API pass their values through unchecked.
#define PKM_PARAMETER_ROW(...) PKM_PARAMETER_CHECK(s, __VA_ARGS__)
  PKM_PARAMETER_TABLE(PKM_PARAMETER_ONLY_Solver)
#undef PKM_PARAMETER_ROW
  if (s.solver == Solver::Cvode && !cvode_available())
    return "parameter solver = 0 (CVODE) is not in this build (a source-code FMU compiled without SUNDIALS): set "
           "solver = 1 (RK4)";
  return validate(s.limits());
}

}  // namespace pkm
