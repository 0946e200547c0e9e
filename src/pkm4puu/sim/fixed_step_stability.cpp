// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/fixed_step_stability.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace pkm {

StiffRates stiff_rates(const Model& m) {
  const Params& p = m.p;
  StiffRates r;
  r.mass = p.m_slider + m.reflected_mass;
  const double c = p.friction_viscous + (p.friction_coulomb != 0.0 ? p.friction_coulomb / p.friction_velocity : 0.0);
  r.friction = c / r.mass;
  r.contact = std::sqrt(p.stop_stiffness / r.mass) + (p.stop_damping + c) / r.mass;
  // omega^2 = k x - d^2 x^2 / 4 with x = 1 / m' over the masses m' >= m: its
  // maximum at x = 2 k / d^2 (k / d) if that mass is heavier than m.
  const double k = p.stop_stiffness, d = p.stop_damping, x = 1.0 / r.mass;
  const double w2 = (d > 0.0 && 2.0 * k / (d * d) <= x) ? (k / d) * (k / d) : k * x - 0.25 * d * d * x * x;
  r.ringing = w2 > 0.0 ? std::sqrt(w2) : 0.0;
  return r;
}

SubSteps fixed_sub_steps(const Model& m, Solver solver) {
  const StiffRates r = stiff_rates(m);
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto step = [inf](double fraction, double rate) { return rate > 0.0 ? fraction / rate : inf; };
  if (solver == Solver::Rosenbrock)
    return {inf, step(kRosenbrockRingFraction, r.ringing), step(kRk4StiffFraction, r.friction),
            step(kRk4StiffFraction, r.contact)};
  return {step(kRk4StiffFraction, r.friction), step(kRk4StiffFraction, r.contact), inf, inf};
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

std::string work_budget_message(const Model& m, const SolverSettings& s, double t, long budget, bool contact) {
  const StiffRates r = stiff_rates(m);
  const SubSteps h = fixed_sub_steps(m, s.solver);
  const Params& p = m.p;
  char buf[720];
  if (contact) {
    const bool rk4 = s.solver == Solver::Rk4;
    std::snprintf(buf, sizeof buf,
                  "at t = %.17g s the work budget of %ld inner steps (work_budget = %g per grid step) ran out in an "
                  "end-stop contact: stop_stiffness = %g N/m and stop_damping = %g N.s/m against m_slider + reflected "
                  "mass = %g kg bound the contact's rate at %.4g 1/s, which needs %s sub-steps of at most %.3g s: "
                  "%s, a larger work_budget, or softer stops",
                  t, budget, s.work_budget, p.stop_stiffness, p.stop_damping, r.mass,
                  rk4 ? r.contact : r.ringing, rk4 ? "RK4" : "Rosenbrock", h.contact,
                  rk4 ? "use solver = 2 (Rosenbrock)" : "use solver = 0 (CVODE)");
  } else {
    std::snprintf(buf, sizeof buf,
                  "at t = %.17g s the work budget of %ld inner steps (work_budget = %g per grid step) ran out "
                  "(contact events located by bisection, or sub-steps of at most %.3g s for the friction's bound "
                  "%.4g 1/s): a larger work_budget, a smaller rk4_step, or solver = 0 (CVODE)",
                  t, budget, s.work_budget, h.free, r.friction);
  }
  return buf;
}

}  // namespace pkm
