// SPDX-License-Identifier: BSD-2-Clause
// The plant's solver settings and their validation, in one place: the FMUs
// and the C API pass their values through unchecked.
#pragma once

#include <string>

#include "pkm4puu/dynamics/forward_dynamics.hpp"
#include "pkm4puu/integrators/cvode_integrator.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm {

/// Cvode: variable step (rtol, atol). Rk4: classical fixed step (rk4_step),
/// sub-stepped where the stiff terms need it. Rosenbrock: linearly implicit
/// fixed step (ROS2, L-stable, the analytic Jacobian; rk4_step too).
enum class Solver { Cvode = 0, Rk4 = 1, Rosenbrock = 2 };
/// The fixed-step solvers (rk4_step, the work budget).
inline bool fixed_step(Solver s) { return s == Solver::Rk4 || s == Solver::Rosenbrock; }

struct SolverSettings {
  Solver solver = Solver::Cvode;
  double rk4_step = 1e-3;  // s; an interval is split into whole steps no longer than this
  double rtol = 1e-8;      // CVODE
  double atol = 1e-10;     // CVODE
  CvodeMethod cvode_method = CvodeMethod::Adams;
  Formulation formulation = Formulation::LegPartitioned;
  // Singularity guards (workspace_guard.hpp), checked at the end of every
  // step: a step ending beyond either is undone and reported (Status::Singular).
  double max_jacobian_condition = GuardLimits{}.max_jacobian_condition;
  double min_leg_measure = GuardLimits{}.min_leg_measure;
  // The fixed-step solvers' work budget: inner steps (grid steps, stiff
  // sub-steps, bisection trials) per grid step, summed over one advance; an
  // advance that would exceed it stops there (Status::SolverFailure, a message).
  double work_budget = 1000.0;
  // The energy audit as a run-time check (J): an advance whose audit
  // residual (change of kinetic + potential - actuator_work +
  // dissipated_energy) exceeds it is undone (SolverFailure). 0: off.
  double energy_tolerance = 0.0;

  GuardLimits limits() const { return {max_jacobian_condition, min_leg_measure}; }
};

inline bool operator==(const SolverSettings& a, const SolverSettings& b) {
  return a.solver == b.solver && a.rk4_step == b.rk4_step && a.rtol == b.rtol && a.atol == b.atol &&
         a.cvode_method == b.cvode_method && a.formulation == b.formulation &&
         a.max_jacobian_condition == b.max_jacobian_condition && a.min_leg_measure == b.min_leg_measure &&
         a.work_budget == b.work_budget && a.energy_tolerance == b.energy_tolerance;
}

/// The range of rk4_step (s): a thousandth of the paper's 1 ms resolves the
/// stiffest default dynamics (the end stops ring at about 6 ms) many times
/// over; above 1 s RK4 says nothing about this machine.
constexpr double kMinRk4Step = 1e-6, kMaxRk4Step = 1.0;

/// The shortest interval CVODE is asked to integrate from rest (model time
/// 0): its first-step estimate squares the interval, which below
/// sqrt(DBL_MIN) = 2^-511 s is no longer a normal double (CVODE then fails,
/// measured from about 2^-540 s on). Shorter steps are refused before any work.
constexpr double kMinCvodeSpan = 0x1p-511;

/// The ranges of CVODE's rtol and atol: where every machine of the declared
/// parameter ranges runs (docs/solvers.md "CVODE"; both ends accepted).
/// rtol no tighter than the double's resolution (2^-52: CVODE cannot meet a
/// smaller one); rtol and atol no looser than 1e-2: looser, the impacts on
/// undamped 1e9 N/m stops run away (measured with rtol 0.1 and atol 0.1,
/// rtol 0.5 and atol 1e-4: the call's work cap, or the legs' singularity).
/// atol (m, rad, m/s, rad/s, J) at least 1e-14: below, BDF needs more than
/// the work cap of one call for a millisecond of the stiffest stops' impact
/// (measured with atol 1e-15); a zero weight, moreover, makes CVODE refuse a
/// state with a zero component.
constexpr double kMinRtol = 0x1p-52, kMaxRtol = 1e-2;
constexpr double kMinAtol = 1e-14, kMaxAtol = 1e-2;

/// The cap on one advance's work, whatever its length (docs/solvers.md "The
/// work budget"): the fixed-step solvers take at most this many inner steps
/// (1 to 3 us of RK4, 2 to 5 us of ROS2 each on a loaded 2-core development
/// machine), so an advance needing more grid steps is refused before any
/// work (Status::InvalidArgument) and one whose sub-steps need more stops
/// as soon as the rest cannot fit (Status::SolverFailure); CVODE evaluates
/// the state derivative at most kMaxCvodeEvaluationsPerCall times (up to 4
/// us each with BDF's linear algebra). Either ends any advance within half
/// a second there.
constexpr double kMaxInnerStepsPerCall = 1e5;
constexpr double kMaxCvodeEvaluationsPerCall = 1e5;
/// How many fixed grid steps an advance over `span` takes (whole steps no
/// longer than rk4_step); compare with kMaxInnerStepsPerCall before any work.
double rk4_steps_for(double span, double rk4_step);

/// The range of work_budget (inner steps per grid step): at least the grid
/// step itself; at most 1e6 (a million-fold the nominal cost is no budget).
constexpr double kMinWorkBudget = 1.0, kMaxWorkBudget = 1e6;
/// The range of energy_tolerance (J): 0 (off) up to 1e9 J.
constexpr double kMaxEnergyTolerance = 1e9;

/// Returns "" if the settings are usable, otherwise a message naming the
/// offending setting.
std::string validate(const SolverSettings& s);

}  // namespace pkm
