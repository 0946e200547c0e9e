// SPDX-License-Identifier: BSD-2-Clause
// What the solvers know before a step: a bound on the stiff terms'
// eigenvalues from the parameters (friction, end stops against the least
// mass behind a slider), the sub-step that keeps each fixed-step solver
// right, CVODE's method and smallest step, and the messages that name the
// parameter, the bound and the remedy.
#pragma once

#include <string>

#include "pkm4puu/integrators/located_step.hpp"
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
  double damping = 0;   // (d + b + F_c / v_s) / m: the real, dissipative part of `contact`
};
StiffRates stiff_rates(const Model& m);

/// CVODE's method: the settings' one, except that Adams gives way to BDF on
/// a machine whose damping rate (StiffRates::damping) exceeds
/// kAdamsMaxDampingRate: Adams' fixed-point corrector converges only for
/// steps h < 1 / rate, below 10 us there, far below the steps its accuracy
/// needs on this machine (docs/solvers.md "CVODE").
constexpr double kAdamsMaxDampingRate = 1e5;
CvodeMethod cvode_method_for(const Model& m, const SolverSettings& s);

/// CVODE's absolute tolerance per component: atol, except on the
/// velocities where Coulomb friction acts: at most friction_velocity / 10
/// (dphi: over 0.1 m). A coarser tolerance does not resolve the friction
/// law's slope, and a stuck machine (creeping at a fraction of
/// friction_velocity) then makes no progress (docs/solvers.md "CVODE").
Vec10 cvode_atol(const Model& m, const SolverSettings& s);

/// CVODE's smallest step (s): kMinStep on a machine whose fastest rate
/// (StiffRates::contact, a bound on the Jacobian's eigenvalues) is at most
/// 1e3 1/s; on a stiffer one 1e-9 / rate, a billion times below its fastest
/// time constant (fixed_step_stability.cpp says why).
constexpr double kMinStep = 1e-12;
double cvode_min_step(const Model& m);

/// RK4's sub-steps keep h |lambda| <= 0.1: its error per step
/// (h lambda)^5 / 120 <= 1e-7 of the fast motion, inside its stability
/// interval [-2.78, 0]. ROS2 starts there after a switch of the contact mode
/// (a new fast transient), and its error estimate takes it on from there.
constexpr double kRk4StiffFraction = 0.1;

/// ROS2's error control (docs/solvers.md "ROS2's error estimate"): every
/// accepted step's estimate of each velocity error (dphi times 0.1 m) is at
/// most kRosenbrockTolerance times the advance's speed (the largest |dx|,
/// |dy|, |dz|, 0.1 m |dphi| at its start and its accepted steps) plus a
/// floor: kRosenbrockSpeedFloor per grid step (a step of h: h / grid step
/// of it), at least kRosenbrockStepFloor. A velocity error made in a contact
/// shifts the next impact in time (a flight lasts 2 v / g) and the next
/// contact's deceleration magnifies it: the tolerance is relative to the
/// speed for that, and tight; the floor per grid step lets a smooth motion
/// take whole 1 ms steps, and the one per step bounds a contact's cost where
/// the speed passes through zero (a rebound).
constexpr double kRosenbrockTolerance = 3e-6;
constexpr double kRosenbrockSpeedFloor = 1e-5;  // m/s per grid step
constexpr double kRosenbrockStepFloor = 1e-6;   // m/s
/// The estimate is filtered (located_rosenbrock.hpp) with H at least this
/// fraction of the grid step: a mode with |lambda| H = 1 decays by e^-10
/// over the grid step, its error with it.
constexpr double kRosenbrockFilterFraction = 0.1;

/// The longest inner step (s) of `solver` out of contact and in contact
/// (+inf where nothing limits it).
struct SubSteps {
  double free = 0, contact = 0;
  // ROS2's first step after a switch of the contact mode, h |lambda| <= 0.1
  // on the bound, out of contact and in contact (RK4: +inf, its steps
  // resolve the stiff terms throughout).
  double first_free = 0, first_contact = 0;
};
SubSteps fixed_sub_steps(const Model& m, Solver solver);

/// "" if the fixed-step solver can take a step of rk4_step out of contact
/// within the work budget; otherwise why not (the parameter, the bound,
/// the remedy): such settings are refused before any step.
std::string fixed_step_refusal(const Model& m, const SolverSettings& s);

/// The message of an advance of `grid_steps` grid steps that ran out of its
/// work budget at t (RK4: the stiffness bound that asked for the sub-steps;
/// ROS2: its last error estimate).
std::string work_budget_message(const Model& m, const SolverSettings& s, double t, const WorkBudget& budget,
                                long grid_steps);

}  // namespace pkm
