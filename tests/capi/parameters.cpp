// SPDX-License-Identifier: BSD-2-Clause
// The C API's parameters (pkm.h): set and read by name with their ranges
// and messages, several as one set, a parameter of the machine ending the
// run where a solver setting keeps it, the list of every parameter, and the
// step checks among the solver settings.
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "capi_support.hpp"
#include "pkm4puu/pkm.h"

using namespace pkm_test;

TEST(CApi, ParametersAreSetByNameWithTheirRangesAndMessages) {
  Handle h;
  double v = 0;
  ASSERT_EQ(pkm_get_parameter(h.m, "r_b", &v), PKM_OK);
  EXPECT_EQ(v, 0.09273);  // docs/model.md, Table II
  EXPECT_EQ(pkm_set_parameter(h.m, "r_b", -1.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "pkm_set_parameter: parameter r_b = -1 must be positive")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "payload_mas", 0.25), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(h.error(), "no parameter is called \"payload_mas\"")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "x0", 0.01), PKM_ERR_INVALID_ARGUMENT);  // pkm_init_pose takes the pose
  EXPECT_EQ(pkm_set_parameter(h.m, "solver", 1.5), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "solver = 1.5 must be a whole number")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "solver", 7), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "solver = 7 must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "rk4_step", -1e-3), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "rk4_step")) << h.error();
  ASSERT_EQ(pkm_get_parameter(h.m, "r_b", &v), PKM_OK);
  EXPECT_EQ(v, 0.09273) << "a refused value changes nothing";
  ASSERT_EQ(pkm_set_parameter(h.m, "payload_mass", 0.25), PKM_OK);
  ASSERT_EQ(pkm_get_parameter(h.m, "payload_mass", &v), PKM_OK);
  EXPECT_EQ(v, 0.25);
}

TEST(CApi, SeveralParametersChangeAsOneSet) {
  // The stops moved up past each other: one at a time the first change
  // leaves rho_min above rho_max; as one set they fit.
  Handle h;
  const char* names[] = {"rho_min", "rho_max"};
  const double values[] = {0.2, 0.3};
  EXPECT_EQ(pkm_set_parameter(h.m, "rho_min", 0.2), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "rho_max = 0.14999999999999999 must exceed rho_min = 0.20000000000000001"))
      << h.error();
  const double bad[] = {0.2, 20.0};
  EXPECT_EQ(pkm_set_parameters(h.m, 2, names, bad), PKM_ERR_INVALID_PARAMETER);
  double v = 0;
  ASSERT_EQ(pkm_get_parameter(h.m, "rho_min", &v), PKM_OK);
  EXPECT_EQ(v, 0.0) << "all or nothing";
  ASSERT_EQ(pkm_set_parameters(h.m, 2, names, values), PKM_OK) << h.error();
  ASSERT_EQ(pkm_get_parameter(h.m, "rho_max", &v), PKM_OK);
  EXPECT_EQ(v, 0.3);
}

TEST(CApi, AMachineParameterEndsTheRunAndASolverSettingKeepsIt) {
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_set_parameter(h.m, "solver", PKM_SOLVER_RK4), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_OK) << h.error();
  ASSERT_EQ(pkm_set_parameter(h.m, "g", 0.0), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.02, nullptr), PKM_ERR_NOT_INITIALIZED);
  EXPECT_TRUE(contains(h.error(), "a parameter of the machine changed since pkm_init_pose")) << h.error();
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_OK) << h.error();
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &out), PKM_OK);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(out.pose[k], kHome[k]) << "no gravity, no force: at rest";
}

TEST(CApi, ParameterInfoListsEveryParameterOnce) {
  const size_t n = pkm_parameter_count();
  ASSERT_GE(n, 44u);
  int seen_payload = 0;
  for (size_t i = 0; i < n; ++i) {
    pkm_parameter p = sized<pkm_parameter>();
    ASSERT_EQ(pkm_parameter_info(i, &p), PKM_OK);
    ASSERT_NE(p.name, nullptr);
    EXPECT_LE(p.min, p.start) << p.name;
    EXPECT_LE(p.start, p.max) << p.name;
    double v = 0;
    Handle h;
    ASSERT_EQ(pkm_get_parameter(h.m, p.name, &v), PKM_OK) << p.name;
    EXPECT_EQ(v, p.start) << p.name;
    if (std::strcmp(p.name, "payload_mass") == 0) {
      ++seen_payload;
      EXPECT_STREQ(p.unit, "kg");
      EXPECT_EQ(p.value_reference, 157u);
      EXPECT_EQ(p.fmus, 3u);  // both FMUs
      EXPECT_EQ(p.is_solver_setting, 0);
    }
  }
  EXPECT_EQ(seen_payload, 1);
  pkm_parameter p = sized<pkm_parameter>();
  EXPECT_EQ(pkm_parameter_info(n, &p), PKM_ERR_INVALID_ARGUMENT);
}

TEST(CApi, StepChecksAreSolverSettings) {
  Handle h;
  double budget = 0, tolerance = -1;
  ASSERT_EQ(pkm_get_parameter(h.m, "work_budget", &budget), PKM_OK);
  ASSERT_EQ(pkm_get_parameter(h.m, "energy_tolerance", &tolerance), PKM_OK);
  EXPECT_EQ(budget, 1000.0);
  EXPECT_EQ(tolerance, 0.0);
  EXPECT_EQ(pkm_set_parameter(h.m, "work_budget", 0.5), PKM_ERR_INVALID_PARAMETER);  // below 1 inner step
  EXPECT_TRUE(contains(h.error(), "work_budget")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "energy_tolerance", -1.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "energy_tolerance")) << h.error();
  const char* names[] = {"work_budget", "energy_tolerance", "solver"};
  const double values[] = {10.0, 1e-3, PKM_SOLVER_RK4};
  ASSERT_EQ(pkm_set_parameters(h.m, 3, names, values), PKM_OK);
  // F = 0 from the home pose: the fall reaches the stops at 95 ms, whose
  // located contact (about 30 bisection trials) does not fit 10 inner steps.
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_status st = PKM_OK;
  for (int k = 1; k <= 200 && st == PKM_OK; ++k) st = pkm_advance(h.m, k * 1e-3, nullptr);
  EXPECT_EQ(st, PKM_ERR_SOLVER);
  EXPECT_TRUE(contains(h.error(), "work budget")) << h.error();
}
