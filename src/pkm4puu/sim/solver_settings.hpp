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

/// The range of CVODE's rtol: no tighter than the double's resolution
/// (2^-52: CVODE cannot meet a smaller one), no looser than one half (a step
/// error half the solution's size controls nothing); both ends accepted.
constexpr double kMinRtol = 0x1p-52, kMaxRtol = 0.5;
/// The range of atol: positive (a zero weight makes CVODE refuse a state
/// with a zero component), so the smallest normal double, up to 1.
constexpr double kMinAtol = 0x1p-1022, kMaxAtol = 1.0;

/// At most this many RK4 steps in one advance (a longer interval or a
/// smaller rk4_step is refused with Status::InvalidArgument before any work).
constexpr double kMaxRk4StepsPerAdvance = 1e7;
/// How many RK4 steps an advance over `span` takes (whole steps no longer
/// than rk4_step); compare with kMaxRk4StepsPerAdvance before any work.
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
