// SPDX-License-Identifier: BSD-2-Clause
// Runs through the C API (pkm.h): the static forces holding the home pose
// with every solver, a saved state continued bit for bit, inputs from a
// callback, the energy among the outputs (reading them changes nothing),
// and the machine's forces and motor torques.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "capi_support.hpp"
#include "pkm4puu/pkm.h"

using namespace pkm_test;

TEST(CApi, StaticForcesHoldTheHomePose) {
  // Inverse dynamics at rest, fed forward for 0.5 s, keeps the platform put.
  Handle h;
  pkm_inverse_result inv = sized<pkm_inverse_result>();
  ASSERT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, &inv), PKM_OK);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(inv.F[i], 2.655616050, 1e-9);
  const Inputs in(inv.F);
  for (int solver : {PKM_SOLVER_CVODE, PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", solver), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.5, in.u), PKM_OK) << h.error();
    pkm_outputs out = sized<pkm_outputs>();
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &out), PKM_OK);
    EXPECT_DOUBLE_EQ(out.t, 0.5);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(out.pose[k], kHome[k], 1e-12) << "solver " << solver;
    for (int k = 0; k < 12; ++k) EXPECT_NEAR(out.lambda[k], inv.lambda[k], 1e-9);
    EXPECT_LT(out.constraint_residual, 1e-15);
    EXPECT_GT(out.jacobian_condition, 1.0);
    EXPECT_LT(out.jacobian_condition, 26.0);
  }
}

// A run saved and restored, in place and into a fresh model, continues bit
// for bit: the pose, the energy integrals and the contact mode.
TEST(CApi, SavedStateRestoresABitIdenticalContinuation) {
  for (int solver : {PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    Handle h, fresh;
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", solver), PKM_OK);
    ASSERT_EQ(pkm_set_parameter(fresh.m, "solver", solver), PKM_OK);
    const double v0[4] = {0.01, 0.0, 0.0, 0.05};
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
    const double F[4] = {2.7, 2.6, 2.65, 2.66};
    const Inputs in(F);
    ASSERT_EQ(pkm_advance(h.m, 0.2, in.u), PKM_OK);
    pkm_state saved = sized<pkm_state>();
    ASSERT_EQ(pkm_get_state(h.m, &saved), PKM_OK);
    EXPECT_NE(saved.actuator_work, 0.0);
    ASSERT_EQ(pkm_advance(h.m, 0.4, in.u), PKM_OK);
    pkm_outputs a = sized<pkm_outputs>(), b = sized<pkm_outputs>(), c = sized<pkm_outputs>();
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &a), PKM_OK);
    ASSERT_EQ(pkm_set_state(h.m, &saved), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.4, in.u), PKM_OK);
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &b), PKM_OK);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "solver " << solver;
    ASSERT_EQ(pkm_set_state(fresh.m, &saved), PKM_OK) << pkm_last_error(fresh.m);
    ASSERT_EQ(pkm_advance(fresh.m, 0.4, in.u), PKM_OK);
    ASSERT_EQ(pkm_get_outputs(fresh.m, in.u, &c), PKM_OK);
    EXPECT_EQ(std::memcmp(&a, &c, sizeof a), 0) << "solver " << solver << ", a fresh model";
    EXPECT_NE(a.pose[0], kHome[0]);  // it did move
  }
}

TEST(CApi, CallbackInputsMatchConstantInputs) {
  Handle h1, h2;
  const double F[4] = {2.7, 2.6, 2.65, 2.66}, tau[4] = {1e-4, -2e-4, 0.0, 3e-4};
  const Inputs in(F, tau);
  ASSERT_EQ(pkm_init_pose(h1.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_init_pose(h2.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_advance(h1.m, 0.3, in.u), PKM_OK);
  auto cb = [](void* user, double, double u[PKM_PLANT_INPUTS]) {
    std::memcpy(u, user, PKM_PLANT_INPUTS * sizeof(double));
  };
  ASSERT_EQ(pkm_advance_fn(h2.m, 0.3, cb, const_cast<double*>(in.u), 0), PKM_OK);
  pkm_state s1 = sized<pkm_state>(), s2 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h1.m, &s1), PKM_OK);
  ASSERT_EQ(pkm_get_state(h2.m, &s2), PKM_OK);
  EXPECT_EQ(std::memcmp(s1.y, s2.y, sizeof s1.y), 0);
}

TEST(CApi, EnergyIsAnOutput) {
  Handle h;
  const double v0[4] = {0.0, 0.0, 0.1, 0.0};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &out), PKM_OK);
  // Pure vertical motion: every body moves at 0.1 m/s, nothing rotates.
  EXPECT_NEAR(out.kinetic_energy, 0.5 * (0.45474 + 4 * (0.09331 + 0.06371)) * 0.01, 1e-15);
}

TEST(CApi, ReadingOutputsChangesNothing) {
  Handle h;
  const double v0[4] = {0.01, -0.01, 0.0, 0.1};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  const double F[4] = {2.7, 2.6, 2.65, 2.66};
  const Inputs in(F);
  ASSERT_EQ(pkm_advance(h.m, 0.1, in.u), PKM_OK);
  pkm_state s1 = sized<pkm_state>(), s2 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, in.u, &out), PKM_OK);
  ASSERT_EQ(pkm_get_state(h.m, &s2), PKM_OK);
  EXPECT_EQ(std::memcmp(&s1, &s2, sizeof s1), 0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out.theta1[i], s1.theta1_ref[i]);
}

// The machine: the holding forces with a payload (docs/model.md's check
// plus its weight), held half by forces and half by motor torques.
TEST(CApi, MachineInputsAndOutputs) {
  Handle h;
  EXPECT_EQ(pkm_set_parameter(h.m, "friction_velocity", 0.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "parameter friction_velocity ")) << h.error();
  ASSERT_EQ(pkm_set_parameter(h.m, "payload_mass", 0.1), PKM_OK);
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_outputs o = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &o), PKM_OK);
  // The spec's check with 0.1 kg more on the platform: (10.622464200 + 0.981) / 4 N each.
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(o.F_hold[i], (10.622464200 + 0.1 * 9.81) / 4, 1e-9);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(o.stop_indicators[i], 0.0443193423, 1e-10);
  pkm_inverse_result inv = sized<pkm_inverse_result>();
  ASSERT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, &inv), PKM_OK);
  double F[4], tau[4];
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(inv.F[i], o.F_hold[i], 1e-12);
    EXPECT_NEAR(inv.tau[i], inv.F[i] * 0.004 / (2 * kPi), 1e-15);
    F[i] = 0.5 * inv.F[i];
    tau[i] = 0.5 * inv.tau[i];
  }
  EXPECT_EQ(inv.beyond_stops, 0u);
  const Inputs in(F, tau);
  ASSERT_EQ(pkm_advance(h.m, 0.5, in.u), PKM_OK) << h.error();
  pkm_state s = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s), PKM_OK);
  EXPECT_LT(std::fabs(s.y[2] - 0.05), 1e-12);
}
