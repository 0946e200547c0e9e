// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/fixed_step_stability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pkm4puu/kinematics/constraints.hpp"

namespace pkm {

StiffRates stiff_rates(const Model& m) {
  const Params& p = m.p;
  StiffRates r;
  r.mass = p.m_slider + m.reflected_mass;
  const double c = p.friction_viscous + (p.friction_coulomb != 0.0 ? p.friction_coulomb / p.friction_velocity : 0.0);
  r.friction = c / r.mass;
  r.damping = (p.stop_damping + c) / r.mass;
  r.contact = std::sqrt(p.stop_stiffness / r.mass) + r.damping;
  return r;
}

Vec10 cvode_atol(const Model& m, const SolverSettings& s) {
  Vec10 atol = Vec10::Constant(s.atol);
  if (m.p.friction_coulomb > 0.0) {
    const double v = 0.1 * m.p.friction_velocity;
    atol.segment<3>(4) = atol.segment<3>(4).cwiseMin(v);
    atol[7] = std::min(atol[7], v / kConditionLength);
  }
  return atol;
}

// The floor must lie below every step that a converging run needs. The
// mechanism's own motions take milliseconds, and 1 ps (kMinStep) is far
// below them; but a stiff contact or stuck friction has transients of time
// constant 1 / rate, down to 1e-16 s at the declared extremes (friction
// velocity 1e-9 m/s on a 1 mg slider), and BDF resolves their start with
// steps of sqrt(atol) / rate and below. A fixed 1 ps made every run with
// atol <= 1e-12 fail at the stiffest stops' impact (the error test at
// hmin); 1e-9 / rate lies a billion times below the fastest time constant.
double cvode_min_step(const Model& m) {
  const double fastest_rate = stiff_rates(m).contact;
  return fastest_rate > 0.0 ? std::min(kMinStep, 1e-9 / fastest_rate) : kMinStep;
}

CvodeMethod cvode_method_for(const Model& m, const SolverSettings& s) {
  if (s.cvode_method == CvodeMethod::Adams && stiff_rates(m).damping > kAdamsMaxDampingRate) return CvodeMethod::BDF;
  return s.cvode_method;
}

SubSteps fixed_sub_steps(const Model& m, Solver solver) {
  const StiffRates r = stiff_rates(m);
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto step = [inf](double rate) { return rate > 0.0 ? kRk4StiffFraction / rate : inf; };
  if (solver == Solver::Rosenbrock) return {inf, inf, step(r.friction), step(r.contact)};
  return {step(r.friction), step(r.contact), inf, inf};
}

std::string fixed_step_refusal(const Model& m, const SolverSettings& s) {
  if (s.solver != Solver::Rk4) return "";  // ROS2 takes whole steps out of contact
  const StiffRates r = stiff_rates(m);
  const double h_sub = fixed_sub_steps(m, s.solver).free;
  const double n = std::ceil(s.rk4_step / h_sub - 1e-9);
  if (!(n > s.work_budget)) return "";
  const Params& p = m.p;
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "solver = 1 (RK4) is unstable at every step with friction_viscous = %g N.s/m, friction_coulomb = %g N "
                "and friction_velocity = %g m/s: their stiffness bound (b + F_c/v_s)/(m_slider + reflected mass) = "
                "%.4g 1/s needs RK4 steps of at most %.3g s (h lambda <= %g), %.3g sub-steps per rk4_step = %g s, "
                "more than work_budget = %g: use solver = 2 (Rosenbrock), rk4_step <= %.3g s, or a larger "
                "work_budget",
                p.friction_viscous, p.friction_coulomb, p.friction_velocity, r.friction, h_sub, kRk4StiffFraction, n,
                s.rk4_step, s.work_budget, h_sub * s.work_budget);
  return buf;
}

std::string work_budget_message(const Model& m, const SolverSettings& s, double t, const WorkBudget& budget,
                                long grid_steps) {
  const StiffRates r = stiff_rates(m);
  const SubSteps h = fixed_sub_steps(m, s.solver);
  const Params& p = m.p;
  char head[400];
  const int n = std::snprintf(head, sizeof head,
                              "at t = %.17g s the work budget of this call, %ld inner steps (work_budget = %g per grid "
                              "step times %ld grid steps, at most %.0f per call), ran out",
                              t, budget.limit, s.work_budget, grid_steps, kMaxInnerStepsPerCall);
  if (budget.reserve > 0 && n > 0 && n < static_cast<int>(sizeof head))
    std::snprintf(head + n, sizeof head - static_cast<size_t>(n),
                  " (%ld used, the rest kept for the %ld grid steps still to take)", budget.used, budget.reserve);
  char buf[1024];
  if (s.solver == Solver::Rosenbrock) {
    std::snprintf(buf, sizeof buf,
                  "%s%s: the last Rosenbrock step tried, %.3g s, had an error estimate %.3g times its tolerance "
                  "(%g of the speed plus %g m/s per grid step, at least %g m/s; %s, stop_stiffness = %g N/m, "
                  "stop_damping = %g N.s/m, friction_coulomb = %g N, friction_velocity = %g m/s): use solver = 0 "
                  "(CVODE), a larger work_budget or shorter communication steps",
                  head, budget.in_contact ? " in an end-stop contact" : "", budget.step, budget.estimate,
                  kRosenbrockTolerance, kRosenbrockSpeedFloor, kRosenbrockStepFloor,
                  budget.in_contact ? "held stops" : "no stop held",
                  p.stop_stiffness, p.stop_damping, p.friction_coulomb, p.friction_velocity);
  } else if (budget.in_contact) {
    std::snprintf(buf, sizeof buf,
                  "%s in an end-stop contact: stop_stiffness = %g N/m and stop_damping = %g N.s/m against m_slider + "
                  "reflected mass = %g kg bound the contact's rate at %.4g 1/s, which needs RK4 sub-steps of at most "
                  "%.3g s: use solver = 2 (Rosenbrock), a larger work_budget, or softer stops",
                  head, p.stop_stiffness, p.stop_damping, r.mass, r.contact, h.contact);
  } else {
    char friction[160] = "";
    if (std::isfinite(h.free))
      std::snprintf(friction, sizeof friction, ", and sub-steps of at most %.3g s for the friction's bound %.4g 1/s",
                    h.free, r.friction);
    std::snprintf(buf, sizeof buf,
                  "%s, locating contact events by bisection%s: a larger work_budget, shorter communication steps, a "
                  "smaller rk4_step, or solver = 0 (CVODE)",
                  head, friction);
  }
  return buf;
}

}  // namespace pkm
