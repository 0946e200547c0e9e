// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/base/status.hpp"

namespace pkm {

const char* status_name(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::InvalidArgument: return "invalid argument";
    case Status::InvalidParameter: return "invalid parameter";
    case Status::NonFinite: return "non-finite input";
    case Status::Unreachable: return "pose unreachable";
    case Status::Singular: return "singular configuration";
    case Status::NotConverged: return "Newton iteration did not converge";
    case Status::SolverFailure: return "integrator failure";
    case Status::NotInitialized: return "not initialised";
  }
  return "unknown status";
}

}  // namespace pkm
