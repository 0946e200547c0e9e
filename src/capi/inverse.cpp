// SPDX-License-Identifier: BSD-2-Clause
// pkm.h: inverse dynamics, its derivatives and the calibration regressor,
// each refusing poses beyond the singularity guards as the inverse FMU does.
#include <cstdio>

#include "capi/capi_model.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_capi {
namespace {

/// Ok if the pose lies within the model's singularity guards (the solver
/// settings' max_jacobian_condition and min_leg_measure), else Singular (or
/// Unreachable) with the guard's sentence in *why.
pkm::Status within_guards(const pkm_model* m, const pkm::Pose& pose, std::string* why) {
  const pkm::GuardLimits limits = m->config.solver.limits();
  pkm::GuardReport report;
  const pkm::Status s = pkm::check_configuration(m->plant->model(), pose, limits, &report);
  if (s != pkm::Status::Ok) *why = describe_configuration_failure(m->plant->model(), pose, limits, report);
  return s;
}

/// The failure of `what`: the core's status, with the guard's sentence if it was the guard's.
pkm_status refused(const pkm_model* m, pkm::Status s, const std::string& what, const std::string& why) {
  return fail(m, to_c(s), what, why.empty() ? pkm::status_name(s) : std::string(pkm::status_name(s)) + ": " + why);
}

/// PKM_OK if the core answered fn (its status s) and the pose lies within
/// the guards; else fn's failure at the pose, recorded (the core's status
/// first).
pkm_status answered(const pkm_model* m, pkm::Status s, const char* fn, const double* pose) {
  std::string why;
  if (s == pkm::Status::Ok) s = within_guards(m, vec4(pose), &why);
  return s == pkm::Status::Ok ? PKM_OK : refused(m, s, at_pose(fn, pose), why);
}

// The ABI 1.0 struct's size (fields appended later are written when a caller's size reaches them).
constexpr std::size_t kInverseResultSize = PKM_CAPI_SIZE_THROUGH(pkm_inverse_result, beyond_stops);

using RowRegressor = Eigen::Matrix<double, 4, pkm::kParams, Eigen::RowMajor>;

pkm_status sample_failure(const pkm_model* m, pkm::Status s, const char* fn, size_t k, size_t n, const double* at,
                          const char* at_name, const std::string& why) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "sample %zu of %zu (%s %.9g, %.9g, %.9g, %.9g)", k, n, at_name, at[0], at[1], at[2],
                at[3]);
  return refused(m, s, std::string(fn) + ": " + buf, why);
}

}  // namespace
}  // namespace pkm_capi

using namespace pkm_capi;

static_assert(static_cast<int>(PKM_REGRESSOR_PARAMS) == static_cast<int>(pkm::kParams), "pkm.h's parameter count is the core's");

extern "C" {

pkm_status pkm_inverse_dynamics(pkm_model* m, const double pose[4], const double velocity[4],
                                const double acceleration[4], const double wrench[4], pkm_inverse_result* out) {
  const char* fn = "pkm_inverse_dynamics";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  pkm_status a = first_null(m, fn, {{"pose", pose}, {"velocity", velocity}, {"acceleration", acceleration}});
  if (a == PKM_OK) a = struct_argument(m, fn, "out", "pkm_inverse_result", out, kInverseResultSize);
  if (a != PKM_OK) return a;
  pkm::InverseDynamicsResult r;
  const pkm::Status s = pkm::inverse_dynamics(m->plant->model(), vec4(pose), vec4(velocity), vec4(acceleration),
                                              vec4(wrench), r);
  const pkm_status v = answered(m, s, fn, pose);
  if (v != PKM_OK) return v;
  pkm_inverse_result o{};
  copy<4>(r.F, o.F);
  copy<4>(r.tau, o.tau);
  copy<12>(r.lambda, o.lambda);
  copy<16>(r.q, o.q);
  copy<16>(r.qd, o.qd);
  copy<16>(r.qdd, o.qdd);
  o.beyond_stops = r.beyond_stops;
  deliver(out, o);
  return PKM_OK;
}

pkm_status pkm_inverse_derivatives(pkm_model* m, const double pose[4], const double velocity[4],
                                   const double acceleration[4], const double wrench[4], double F[4], double dF[64]) {
  const char* fn = "pkm_inverse_derivatives";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a = first_null(
      m, fn, {{"pose", pose}, {"velocity", velocity}, {"acceleration", acceleration}, {"F", F}, {"dF", dF}});
  if (a != PKM_OK) return a;
  pkm::InverseDynamicsPartials d;
  const pkm::Status s = pkm::inverse_dynamics_derivatives(m->plant->model(), vec4(pose), vec4(velocity),
                                                          vec4(acceleration), vec4(wrench), d);
  const pkm_status v = answered(m, s, fn, pose);
  if (v != PKM_OK) return v;
  copy<4>(d.F, F);
  Eigen::Map<Eigen::Matrix<double, 4, 16, Eigen::RowMajor>> J(dF);
  J << d.dp, d.dpd, d.dpdd, d.dwe;
  return PKM_OK;
}

const char* pkm_regressor_param_name(int j) { return pkm::regressor_param_info(j).name; }

const char* pkm_regressor_param_unit(int j) { return pkm::regressor_param_info(j).unit; }

pkm_status pkm_regressor_params(pkm_model* m, double pi[PKM_REGRESSOR_PARAMS]) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!pi) return null_argument(m, "pkm_regressor_params", "pi");
  copy<pkm::kParams>(pkm::parameter_vector(m->plant->model().p), pi);
  return PKM_OK;
}

pkm_status pkm_regressor(pkm_model* m, const double pose[4], const double velocity[4], const double acceleration[4],
                         const double wrench[4], double* Y, double F0[4]) {
  const char* fn = "pkm_regressor";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a =
      first_null(m, fn, {{"pose", pose}, {"velocity", velocity}, {"acceleration", acceleration}, {"Y", Y}});
  if (a != PKM_OK) return a;
  pkm::RegressorSample r;
  const pkm::Status s =
      pkm::regressor(m->plant->model(), vec4(pose), vec4(velocity), vec4(acceleration), vec4(wrench), r);
  const pkm_status v = answered(m, s, fn, pose);
  if (v != PKM_OK) return v;
  Eigen::Map<RowRegressor> Y_out(Y);
  Y_out = r.Y;
  if (F0) copy<4>(r.F0, F0);
  return PKM_OK;
}

pkm_status pkm_regressor_poses(pkm_model* m, size_t n, const double* pose, const double* velocity,
                               const double* acceleration, double* Y, double* F0, double* rho, double* drho,
                               size_t* done) {
  const char* fn = "pkm_regressor_poses";
  if (done) *done = 0;
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (n > 0) {
    const pkm_status a =
        first_null(m, fn, {{"pose", pose}, {"velocity", velocity}, {"acceleration", acceleration}, {"Y", Y}});
    if (a != PKM_OK) return a;
  }
  pkm::RegressorSample r;
  for (size_t k = 0; k < n; ++k) {
    const pkm::Pose p = vec4(pose + 4 * k);
    std::string why;
    pkm::Status s =
        pkm::regressor(m->plant->model(), p, vec4(velocity + 4 * k), vec4(acceleration + 4 * k), pkm::Wrench::Zero(), r);
    if (s == pkm::Status::Ok) s = within_guards(m, p, &why);
    if (s != pkm::Status::Ok) return sample_failure(m, s, fn, k, n, pose + 4 * k, "pose", why);
    Eigen::Map<RowRegressor> Y_k(Y + 4 * pkm::kParams * k);
    Y_k = r.Y;
    if (F0) copy<4>(r.F0, F0 + 4 * k);
    if (rho) copy<4>(r.rho, rho + 4 * k);
    if (drho) copy<4>(r.rhod, drho + 4 * k);
    if (done) *done = k + 1;
  }
  return PKM_OK;
}

pkm_status pkm_regressor_joints(pkm_model* m, size_t n, const double* rho, const double* drho, const double* ddrho,
                                const double guess[4], double* Y, double* F0, double* pose, size_t* done) {
  const char* fn = "pkm_regressor_joints";
  if (done) *done = 0;
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (n > 0) {
    const pkm_status a = first_null(m, fn, {{"rho", rho}, {"drho", drho}, {"ddrho", ddrho}, {"Y", Y}});
    if (a != PKM_OK) return a;
  }
  pkm::RegressorSample r;
  r.pose = guess ? vec4(guess) : pkm::Pose(0.0, 0.0, 0.05, 0.0);
  for (size_t k = 0; k < n; ++k) {
    std::string why;
    pkm::Status s = pkm::joint_regressor(m->plant->model(), vec4(rho + 4 * k), vec4(drho + 4 * k),
                                         vec4(ddrho + 4 * k), pkm::Wrench::Zero(), r);
    if (s == pkm::Status::Ok) s = within_guards(m, r.pose, &why);
    if (s != pkm::Status::Ok) return sample_failure(m, s, fn, k, n, rho + 4 * k, "rho", why);
    Eigen::Map<RowRegressor> Y_k(Y + 4 * pkm::kParams * k);
    Y_k = r.Y;
    if (F0) copy<4>(r.F0, F0 + 4 * k);
    if (pose) copy<4>(r.pose, pose + 4 * k);
    if (done) *done = k + 1;
  }
  return PKM_OK;
}

}  // extern "C"
