// SPDX-License-Identifier: BSD-2-Clause
// A failed call of the C API (pkm.h) writes and changes nothing and says
// why: an unreachable pose, a NULL argument, a non-finite force, an advance
// the integrator cannot take, a pose beyond the leg guard.
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "capi_support.hpp"
#include "pkm4puu/pkm.h"

using namespace pkm_test;

TEST(CApi, UnreachablePoseIsAnErrorWithAMessage) {
  Handle h;
  const double far[4] = {0.2, 0.0, 0.05, 0.0};
  EXPECT_EQ(pkm_init_pose(h.m, 0.0, far, nullptr), PKM_ERR_UNREACHABLE);
  EXPECT_TRUE(contains(h.error(), "unreachable")) << h.error();
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_ERR_NOT_INITIALIZED);
}

// After a failure with a message, a NULL argument names itself: the message
// is never the previous call's.
TEST(CApi, ANullArgumentReplacesThePreviousMessage) {
  Handle h;
  const double far[4] = {0.2, 0.0, 0.05, 0.0};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, far, nullptr), PKM_ERR_UNREACHABLE);
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance_fn(h.m, 0.1, nullptr, nullptr, 0), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_advance_fn: inputs is NULL");
  EXPECT_EQ(pkm_init_pose(h.m, 0.0, nullptr, nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_init_pose: pose is NULL");
  EXPECT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_inverse_dynamics: out is NULL");
  EXPECT_EQ(pkm_get_parameter(h.m, "g", nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_get_parameter: value is NULL");
  EXPECT_EQ(pkm_create(nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(pkm_last_error(nullptr), "NULL handle");
}

TEST(CApi, NonFiniteForceIsRejectedAndTheStateKept) {
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_state s0 = sized<pkm_state>(), s1 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s0), PKM_OK);
  double u[PKM_PLANT_INPUTS] = {1.0, NAN, 1.0, 1.0};
  EXPECT_EQ(pkm_advance(h.m, 0.01, u), PKM_ERR_NONFINITE);
  ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
  EXPECT_EQ(std::memcmp(&s0, &s1, sizeof s0), 0);
}

// An advance the integrator cannot take is refused before any work, with
// its reason, the state kept; the FMU's DoStep asks the same question
// (Plant::advance_refusal). CVODE over less than sqrt(DBL_MIN) = 2^-511 s:
// its first-step estimate squares the span; RK4 over more grid steps than one
// call may take (1e5: rk4_step 1e-6 s over 0.2 s is 2e5).
TEST(CApi, AnAdvanceTheIntegratorCannotTakeIsRefusedBeforeAnyWork) {
  const struct {
    int solver;
    double rk4_step, span;
    const char* why;
  } cases[] = {{PKM_SOLVER_CVODE, 1e-3, 1e-200, "shorter than CVODE can start with"},
               {PKM_SOLVER_CVODE, 1e-3, std::ldexp(1.0, -512), "shorter than CVODE can start with"},
               {PKM_SOLVER_RK4, 1e-6, 0.2, "more than the 100000 inner steps one call may take"}};
  const Inputs in(kZero);
  for (const auto& c : cases) {
    Handle h;
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", c.solver), PKM_OK);
    ASSERT_EQ(pkm_set_parameter(h.m, "rk4_step", c.rk4_step), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
    pkm_state s0 = sized<pkm_state>(), s1 = sized<pkm_state>();
    ASSERT_EQ(pkm_get_state(h.m, &s0), PKM_OK);
    EXPECT_EQ(pkm_advance(h.m, c.span, in.u), PKM_ERR_INVALID_ARGUMENT) << c.why;
    EXPECT_TRUE(contains(h.error(), c.why)) << h.error();
    ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
    EXPECT_EQ(std::memcmp(&s0, &s1, sizeof s0), 0) << c.why;
  }
  Handle h;  // at the bound CVODE starts
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, std::ldexp(1.0, -511), in.u), PKM_OK) << h.error();
}

// Near a leg singularity (leg 2's rod almost horizontal, theta2 -> 0, from
// docs/model.md's closed form) the inverse dynamics, its derivatives and the
// regressor refuse the pose by the guard min_leg_measure, as the inverse FMU
// does, and write nothing.
namespace {

// The pose (x, 0, 0.05, 0) with leg 2 (beta = 90 deg, gamma = -65 deg) at
// A = l (1 - eps): in its leg frame q~ = (r_Q sin 25 deg - r_b, -(x + r_Q cos
// 25 deg)), A^2 = |q~|^2 - h'^2, and its rod's |cos theta2 sin theta2| =
// (1 - eps) sqrt(1 - (1 - eps)^2).
void leg2_nearly_horizontal(double eps, double pose[4]) {
  const double l = 0.080, hp = 0.075, r_b = 0.09273, r_Q = 0.075, a = 25.0 * kPi / 180.0;
  const double qx = r_Q * std::sin(a) - r_b, A = l * (1.0 - eps);
  pose[0] = std::sqrt(A * A + hp * hp - qx * qx) - r_Q * std::cos(a);
  pose[1] = 0.0, pose[2] = 0.05, pose[3] = 0.0;
}

}  // namespace

TEST(CApi, PosesBeyondTheLegGuardAreRefusedAndNothingWritten) {
  Handle h;
  double pose[4];
  leg2_nearly_horizontal(1e-12, pose);  // measure 1.4e-6 < min_leg_measure = 1e-2
  const double v[4] = {0.01, 0.0, 0.0, 0.0};
  pkm_inverse_result r;
  std::memset(&r, 0x7f, sizeof r);
  r.size = sizeof r;
  const pkm_inverse_result before = r;
  EXPECT_EQ(pkm_inverse_dynamics(h.m, pose, v, kZero, nullptr, &r), PKM_ERR_SINGULAR);
  EXPECT_TRUE(contains(h.error(), "min_leg_measure")) << h.error();
  EXPECT_EQ(std::memcmp(&r, &before, sizeof r), 0);
  double Y[4 * PKM_REGRESSOR_PARAMS], F0[4] = {7, 7, 7, 7};
  for (double& y : Y) y = 7.0;
  EXPECT_EQ(pkm_regressor(h.m, pose, v, kZero, nullptr, Y, F0), PKM_ERR_SINGULAR);
  for (double y : Y) ASSERT_EQ(y, 7.0);
  for (double f : F0) ASSERT_EQ(f, 7.0);
  double F[4] = {7, 7, 7, 7}, dF[64];
  EXPECT_EQ(pkm_inverse_derivatives(h.m, pose, v, kZero, nullptr, F, dF), PKM_ERR_SINGULAR);
  for (double f : F) ASSERT_EQ(f, 7.0);
  size_t done = 99;
  EXPECT_EQ(pkm_regressor_poses(h.m, 1, pose, v, kZero, Y, nullptr, nullptr, nullptr, &done), PKM_ERR_SINGULAR);
  EXPECT_EQ(done, 0u);
  // Within the guard (a looser pose of the same leg) every call answers.
  leg2_nearly_horizontal(1e-3, pose);  // measure 0.045
  EXPECT_EQ(pkm_regressor(h.m, pose, v, kZero, nullptr, Y, F0), PKM_OK) << h.error();
  // The guards are the model's: switched off, the pose is computed (its
  // actuator Jacobian is as near singular as the leg: both guards).
  leg2_nearly_horizontal(1e-12, pose);
  const char* guards[] = {"min_leg_measure", "max_jacobian_condition"};
  const double off[] = {0.0, INFINITY};
  ASSERT_EQ(pkm_set_parameters(h.m, 2, guards, off), PKM_OK) << h.error();
  EXPECT_EQ(pkm_inverse_dynamics(h.m, pose, v, kZero, nullptr, &r), PKM_OK) << h.error();
  EXPECT_GT(std::fabs(r.F[1]), 1e6);  // what the guard keeps from a caller
}
