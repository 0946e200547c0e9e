// SPDX-License-Identifier: BSD-2-Clause
// The paper's auto-test (section 5.1, docs/model.md "The paper's two tests"): inverse
// dynamics along the rest-to-rest path gives F1..F4(t); forward dynamics
// driven open loop by those forces, evaluated at the integrator's own
// (stage) times, must reproduce the path.
#pragma once

#include <string>
#include <vector>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "apps/trajectory.hpp"

namespace pkm {

struct AutotestOptions {
  SolverSettings solver;
  RestToRest path;
  double sample_dt = 1e-3;  // s, spacing of the recorded samples
  /// Called now and then with the simulated time (for progress output).
  void (*progress)(void* user, double t, double t_end) = nullptr;
  void* progress_user = nullptr;
};

struct AutotestSample {
  double t;
  Pose desired;      // the prescribed path
  Pose simulated;    // forward dynamics
  Vec4 F;            // inverse-dynamics actuator forces, N
  Vec4 F_static;     // the forces that would hold the same pose at rest, N
  Vec4 rho;          // simulated actuator positions, m
  double constraint_residual;  // ||C(q)||, m
  double jacobian_condition;
};

struct AutotestResult {
  std::vector<AutotestSample> samples;
  double max_position_error = 0;  // m, over x, y, z
  double max_angle_error = 0;     // rad
  double max_constraint_residual = 0;
  double max_jacobian_condition = 0;
  double max_dynamic_force = 0;   // max |F - F_static|, N
  long rhs_evaluations = 0;
  std::string error;
};

/// What the round trip must reproduce the path to (docs/model.md "The paper's two tests"),
/// with RK4 at 1 ms and with CVODE at rtol 1e-12, atol 1e-14: the bounds of
/// the tests (tests/core/autotest.cpp) and of pkm_autotest's verdict.
struct AutotestBounds {
  double position = 1e-10;    // m, max |x, y, z error|
  double angle = 1e-10;       // rad, max |phi error|
  double constraint = 1e-12;  // m, max ||C(q)||
};
inline constexpr AutotestBounds kAutotestBounds{};

/// Runs the round trip. Status of the first failure (inverse or forward).
Status run_autotest(const Model& m, const AutotestOptions& opt, AutotestResult& out);

/// Inverse dynamics along a path as an InputSignal: forces at any time t.
struct PathForces {
  const Model* model = nullptr;
  RestToRest path;
  InverseDynamicsResult id;
  Status status = Status::Ok;
  InputSignal signal();
};

}  // namespace pkm
