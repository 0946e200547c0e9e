// SPDX-License-Identifier: BSD-2-Clause
// What the C API's files share (pkm.h's implementation: model.cpp,
// forward.cpp, inverse.cpp): the handle, its error reporting, the growable
// structs' size rule and the conversions. No mathematics of its own.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>

#include "pkm4puu/pkm.h"
#include "pkm4puu/sim/parameters.hpp"
#include "pkm4puu/sim/plant.hpp"

struct pkm_model {
  // The parameters' values; `plant` is made from them and kept in step.
  pkm::Configuration config;
  std::unique_ptr<pkm::Plant> plant;
  // Why forward dynamics has no run, when a parameter change ended it.
  std::string run_ended;
  mutable std::string error;
};

namespace pkm_capi {

inline pkm_status to_c(pkm::Status s) { return static_cast<pkm_status>(static_cast<int>(s)); }

/// Whether each of pkm.h's C constants has the value of the core's
/// enumerator paired with it: to_c and the integer parameters (solver,
/// cvode_method, formulation) pass the values through.
template <class Core, std::size_t N>
constexpr bool same_values(const std::pair<int, Core> (&pairs)[N]) {
  for (const auto& p : pairs)
    if (p.first != static_cast<int>(p.second)) return false;
  return true;
}
static_assert(same_values<pkm::Status>({{PKM_OK, pkm::Status::Ok},
                                        {PKM_ERR_INVALID_ARGUMENT, pkm::Status::InvalidArgument},
                                        {PKM_ERR_INVALID_PARAMETER, pkm::Status::InvalidParameter},
                                        {PKM_ERR_NONFINITE, pkm::Status::NonFinite},
                                        {PKM_ERR_UNREACHABLE, pkm::Status::Unreachable},
                                        {PKM_ERR_SINGULAR, pkm::Status::Singular},
                                        {PKM_ERR_NOT_CONVERGED, pkm::Status::NotConverged},
                                        {PKM_ERR_SOLVER, pkm::Status::SolverFailure},
                                        {PKM_ERR_NOT_INITIALIZED, pkm::Status::NotInitialized}}),
              "pkm_status is pkm::Status");
// The C API's own status, after the core's last.
static_assert(PKM_ERR_OUT_OF_MEMORY == PKM_ERR_NOT_INITIALIZED + 1, "PKM_ERR_OUT_OF_MEMORY follows the core's statuses");
static_assert(same_values<pkm::Solver>({{PKM_SOLVER_CVODE, pkm::Solver::Cvode},
                                        {PKM_SOLVER_RK4, pkm::Solver::Rk4},
                                        {PKM_SOLVER_ROSENBROCK, pkm::Solver::Rosenbrock}}),
              "PKM_SOLVER_* are pkm::Solver");
static_assert(same_values<pkm::CvodeMethod>(
                  {{PKM_CVODE_ADAMS, pkm::CvodeMethod::Adams}, {PKM_CVODE_BDF, pkm::CvodeMethod::BDF}}),
              "PKM_CVODE_* are pkm::CvodeMethod");
static_assert(same_values<pkm::Formulation>({{PKM_FORM_AUGMENTED, pkm::Formulation::Augmented},
                                             {PKM_FORM_NULLSPACE_QR, pkm::Formulation::NullSpaceQR},
                                             {PKM_FORM_LEG_PARTITIONED, pkm::Formulation::LegPartitioned}}),
              "PKM_FORM_* are pkm::Formulation");

/// Records why `function` failed on the handle and returns the status.
pkm_status fail(const pkm_model* m, pkm_status s, const std::string& function, const std::string& why);
/// The same for a core status, with the plant's own message when it has one.
pkm_status fail(const pkm_model* m, pkm::Status s, const std::string& function);
/// A NULL argument: PKM_ERR_INVALID_ARGUMENT, recorded when the handle is there.
pkm_status null_argument(const pkm_model* m, const char* function, const char* argument);

/// The size of a struct at ABI 1.0, through its last field then: a caller's
/// `size` must reach it; fields appended later are written when it reaches them.
#define PKM_CAPI_SIZE_THROUGH(type, last) (offsetof(type, last) + sizeof(static_cast<type*>(nullptr)->last))

/// The first of `args` (name, pointer) that is NULL, as null_argument; PKM_OK if none is.
pkm_status first_null(const pkm_model* m, const char* function,
                      std::initializer_list<std::pair<const char*, const void*>> args);

/// Whether out->size holds at least the ABI 1.0 struct (`first_size`).
template <class T>
bool size_ok(const T* out, std::size_t first_size) {
  return out->size >= first_size;
}
/// Copies `value` into *out as far as out->size reaches (its size kept).
template <class T>
void deliver(T* out, T value) {
  value.size = out->size;
  std::memcpy(static_cast<void*>(out), &value, std::min(out->size, sizeof(T)));
}
/// A struct size below the ABI 1.0 struct's: recorded, PKM_ERR_INVALID_ARGUMENT.
pkm_status bad_size(const pkm_model* m, const char* function, const char* type, std::size_t size,
                    std::size_t first_size);
/// A struct argument `name` of type `type`: not NULL, its size at least `first_size`.
template <class T>
pkm_status struct_argument(const pkm_model* m, const char* function, const char* name, const char* type, const T* p,
                           std::size_t first_size) {
  if (!p) return null_argument(m, function, name);
  return size_ok(p, first_size) ? PKM_OK : bad_size(m, function, type, p->size, first_size);
}

inline pkm::Vec4 vec4(const double* a) { return a ? pkm::Vec4(a[0], a[1], a[2], a[3]) : pkm::Vec4::Zero(); }
template <int N>
void copy(const Eigen::Matrix<double, N, 1>& v, double* out) {
  for (int i = 0; i < N; ++i) out[i] = v[i];
}

/// "name(x=..., y=..., z=..., phi=...)" for messages about a pose.
std::string at_pose(const char* function, const double* pose);

}  // namespace pkm_capi
