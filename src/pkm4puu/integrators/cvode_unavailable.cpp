// SPDX-License-Identifier: BSD-2-Clause
// CvodeIntegrator without SUNDIALS: what the source-code FMUs compile in
// place of cvode_integrator.cpp, so that they build with nothing but a
// C++17 compiler. cvode_available() is false, so the solver settings refuse
// solver = 0 before anything is integrated (plant.cpp, validate); should
// anything call in regardless, every call fails with that reason.
#include "pkm4puu/integrators/cvode_integrator.hpp"

namespace pkm {

namespace {
const char kNoCvode[] = "this build has no CVODE (a source-code FMU compiled without SUNDIALS): use solver = 1 (RK4)";
}

bool cvode_available() { return false; }

CvodeIntegrator::~CvodeIntegrator() = default;

Status CvodeIntegrator::init(CvodeMethod, double, const Vec10&, Rhs, void*, int, RootFn, JacFn, double) {
  error_ = kNoCvode;
  return Status::SolverFailure;
}

Status CvodeIntegrator::reset(double, const Vec10&) {
  error_ = kNoCvode;
  return Status::SolverFailure;
}

Status CvodeIntegrator::advance(double, Vec10&, double&, bool&, int*) {
  error_ = kNoCvode;
  return Status::SolverFailure;
}

long CvodeIntegrator::steps() const { return 0; }

}  // namespace pkm
