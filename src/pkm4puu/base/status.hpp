// SPDX-License-Identifier: BSD-2-Clause
// Result codes of the core. Every fallible function returns one; none throws
// in a time step. The C API maps them one to one onto pkm_status.
#pragma once

namespace pkm {

enum class Status {
  Ok = 0,
  InvalidArgument,   // null pointer, wrong size, bad option
  InvalidParameter,  // a model parameter out of range or non-finite
  NonFinite,         // a non-finite input (force, pose, time)
  Unreachable,       // a pose outside the workspace of a leg
  Singular,          // leg or parallel singularity: a Jacobian lost rank
  NotConverged,      // Newton's method did not meet its stopping rule
  SolverFailure,     // the ODE integrator gave up
  NotInitialized,    // forward dynamics asked before a state was set
};

const char* status_name(Status s);

}  // namespace pkm
