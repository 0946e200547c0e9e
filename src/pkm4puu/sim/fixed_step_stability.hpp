// SPDX-License-Identifier: BSD-2-Clause
// What the fixed-step solvers know before a step: a bound on the stiff
// terms' eigenvalues from the parameters (friction, end stops against the
// least mass behind a slider), the sub-step that keeps each solver right,
// and the messages that name the parameter, the bound and the remedy.
#pragma once

#include <string>

#include "pkm4puu/model/model.hpp"
#include "pkm4puu/sim/solver_settings.hpp"

namespace pkm {

/// Bounds (1/s) on |lambda| of the stiff part of the state derivative's
/// Jacobian. With M_r >= J_rho^T m I J_rho (the sliders' kinetic energy is
/// part of the total; m = m_slider + reflected mass), the generalised
/// eigenvalues of a joint damping c and stiffness k against M_r satisfy
/// |lambda| <= c / m + sqrt(k / m) (docs/solvers.md).
struct StiffRates {
  double mass = 0;      // m, kg
  double friction = 0;  // (b + F_c / v_s) / m: the friction's slope at rest, always acting
  double contact = 0;   // sqrt(k / m) + (d + b + F_c / v_s) / m: a held stop with the friction
  double ringing = 0;   // the highest damped frequency of a held stop (rad/s), 0 if none
};
StiffRates stiff_rates(const Model& m);

/// The sub-steps' fractions: RK4 keeps h |lambda| <= 0.1 (its error per step
/// (h lambda)^5 / 120 <= 1e-7 of the fast motion, inside its stability
/// interval [-2.78, 0]); ROS2 is L-stable and resolves a ringing stop with
/// h omega <= 0.05 (its error per step ~ (h omega)^3 / 6 <= 2e-5), omega
/// from the Jacobian's eigenvalues at each switch into contact
/// (plant_stepping.cpp) or, where that cannot be evaluated, the bound
/// StiffRates::ringing.
constexpr double kRk4StiffFraction = 0.1;
constexpr double kRosenbrockRingFraction = 0.05;

/// The longest inner step (s) of `solver` out of contact and in contact
/// (+inf where nothing limits it).
struct SubSteps {
  double free = 0, contact = 0;
  // ROS2's first step after a switch of the contact mode (or at the start),
  // h |lambda| <= 0.1 on the bound, out of contact and in contact; from
  // there the steps grow by kLayerGrowth (located_step.hpp). RK4: +inf (its
  // steps resolve the stiff terms throughout).
  double layer_free = 0, layer_contact = 0;
};
SubSteps fixed_sub_steps(const Model& m, Solver solver);

/// "" if the fixed-step solver can take a step of rk4_step out of contact
/// within the work budget; otherwise why not (the parameter, the bound,
/// the remedy): such settings are refused before any step.
std::string fixed_step_refusal(const Model& m, const SolverSettings& s);

/// The message of an advance that ran out of its work budget at t.
std::string work_budget_message(const Model& m, const SolverSettings& s, double t, long budget, bool contact);

}  // namespace pkm
