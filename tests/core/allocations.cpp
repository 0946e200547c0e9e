// SPDX-License-Identifier: BSD-2-Clause
// No heap allocation inside a time step of the core: 1000 state derivatives
// (each formulation), inverse dynamics solves (warm and cold), the analytic
// derivatives, the regressor (from the platform motion and from the
// sliders), and 1000 one-ms RK4 Plant::advance calls after initialisation
// (the FMU's tick, tests/fmu_allocations.c, rests on these). Counted by the
// malloc interposer (tests/alloc_interposer.c: every malloc-family call of
// the process, operator new included).
#include <gtest/gtest.h>

#include <vector>

#include "alloc_interposer.h"
#include "apps/autotest.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "apps/trajectory.hpp"

namespace {

using pkm::Pose;
using pkm::Status;
using pkm::Vec4;
using pkm::Vec8;
using pkm::Wrench;

/// The auto-test's path and its state at t = 1 s (mid-motion).
struct AllocationsTest : ::testing::Test {
  void SetUp() override {
    ASSERT_EQ(pkm::make_model(pkm::Params{}, model), Status::Ok);
    path.eval(1.0, p, pd, pdd);
    ASSERT_EQ(pkm::inverse_dynamics(model, p, pd, pdd, Wrench::Zero(), id, false), Status::Ok);
    y << p, pd;
  }
  /// y with x moved by 1e-12 * (k % 1024): each call sees a new state.
  const Vec8& nudged(long k) {
    yk = y;
    yk[0] += 1e-12 * static_cast<double>(k & 1023);
    return yk;
  }
  pkm::Model model;
  pkm::RestToRest path;
  Pose p, pd, pdd;
  pkm::InverseDynamicsResult id;
  Vec8 y, yk;
};

TEST_F(AllocationsTest, CounterSeesOperatorNew) {
  const long before = alloc_count();
  std::vector<double> v(1000, 1.0);
  EXPECT_GT(alloc_count(), before);
  EXPECT_EQ(v.size(), 1000u);
}

TEST_F(AllocationsTest, StateDerivativeEachFormulation) {
  const pkm::Vec16 f = pkm::generalized_forces(id.F, Wrench::Zero());
  for (const pkm::Formulation form :
       {pkm::Formulation::LegPartitioned, pkm::Formulation::NullSpaceQR, pkm::Formulation::Augmented}) {
    Vec8 ydot;
    Status s = Status::Ok;
    const long before = alloc_count();
    for (long k = 0; k < 1000 && s == Status::Ok; ++k) s = pkm::state_derivative(model, form, nudged(k), f, ydot);
    EXPECT_EQ(alloc_count() - before, 0) << "formulation " << static_cast<int>(form);
    EXPECT_EQ(s, Status::Ok);
  }
}

TEST_F(AllocationsTest, InverseDynamicsWarmAndCold) {
  pkm::InverseDynamicsResult r;
  ASSERT_EQ(pkm::inverse_dynamics(model, p, pd, pdd, Wrench::Zero(), r, false), Status::Ok);
  for (const bool warm : {true, false}) {
    Status s = Status::Ok;
    const long before = alloc_count();
    for (long j = 1; j <= 1000 && s == Status::Ok; ++j) {
      Pose q, qd, qdd;
      path.eval(1.0 + 0.5e-3 * static_cast<double>(j % 100), q, qd, qdd);
      s = pkm::inverse_dynamics(model, q, qd, qdd, Wrench::Zero(), r, warm);
    }
    EXPECT_EQ(alloc_count() - before, 0) << (warm ? "warm" : "cold");
    EXPECT_EQ(s, Status::Ok);
  }
}

TEST_F(AllocationsTest, RegressorFromThePlatformAndFromTheSliders) {
  // The identification's per-sample calls: 1000 each along the path.
  pkm::RegressorSample from_pose, from_joints;
  from_joints.pose = p;
  Status s = Status::Ok, sj = Status::Ok;
  const long before = alloc_count();
  for (long j = 1; j <= 1000 && s == Status::Ok && sj == Status::Ok; ++j) {
    Pose q, qd, qdd;
    path.eval(1.0 + 0.5e-3 * static_cast<double>(j % 100), q, qd, qdd);
    s = pkm::regressor(model, q, qd, qdd, Wrench::Zero(), from_pose);
    sj = pkm::joint_regressor(model, from_pose.rho, from_pose.rhod, Vec4::Zero(), Wrench::Zero(), from_joints);
  }
  EXPECT_EQ(alloc_count() - before, 0);
  EXPECT_EQ(s, Status::Ok);
  EXPECT_EQ(sj, Status::Ok);
}

TEST_F(AllocationsTest, AnalyticDerivatives) {
  Vec8 ydot;
  pkm::Mat8 A;
  pkm::Mat8x12 B;
  pkm::InverseDynamicsPartials d;
  const long before = alloc_count();
  for (long k = 0; k < 1000; ++k) {
    pkm::state_derivative_jacobians(model, nudged(k), id.F, Vec4::Zero(), Wrench::Zero(), pkm::kStopsFromState, ydot,
                                    A, B);
    pkm::inverse_dynamics_derivatives(model, p, pd, pdd, Wrench::Zero(), d);
  }
  EXPECT_EQ(alloc_count() - before, 0);
}

class FixedStepAllocations : public AllocationsTest, public ::testing::WithParamInterface<pkm::Solver> {};

// RK4 and ROS2 (its Jacobian and the 8x8 LU are fixed-size).
TEST_P(FixedStepAllocations, AdvanceAfterInitialisation) {
  pkm::SolverSettings rk4;
  rk4.solver = GetParam();
  rk4.rk4_step = 1e-3;
  pkm::PathForces forces;
  forces.model = &model;
  forces.path = path;
  Pose p0, pd0, pdd0;
  path.eval(0.0, p0, pd0, pdd0);
  pkm::Plant plant(model);
  ASSERT_EQ(plant.set_solver(rk4), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, p0, pd0), Status::Ok);
  Status s = Status::Ok;
  const long before = alloc_count();
  for (long k = 1; k <= 1000 && s == Status::Ok; ++k)
    s = plant.advance(static_cast<double>(k) * 1e-3, forces.signal(), k > 1);
  EXPECT_EQ(alloc_count() - before, 0);
  EXPECT_EQ(s, Status::Ok);
}

// The drop onto the stops (F = 0 from the home pose, contact at 95 ms):
// located switches, RK4's contact sub-steps, ROS2's steps under its error
// estimate (rejected and retried, the filter's second factorisation).
TEST_P(FixedStepAllocations, DropOntoTheStops) {
  pkm::SolverSettings st;
  st.solver = GetParam();
  pkm::Plant plant(model);
  ASSERT_EQ(plant.set_solver(st), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, Pose(0, 0, 0.05, 0), Pose::Zero()), Status::Ok);
  Status s = Status::Ok;
  const long before = alloc_count();
  for (long k = 1; k <= 150 && s == Status::Ok; ++k) s = plant.advance(static_cast<double>(k) * 1e-3, pkm::InputSignal{});
  EXPECT_EQ(alloc_count() - before, 0);
  EXPECT_EQ(s, Status::Ok);
  EXPECT_GT(plant.contact_events(), 0) << "the stops were reached";
}

INSTANTIATE_TEST_SUITE_P(Solvers, FixedStepAllocations, ::testing::Values(pkm::Solver::Rk4, pkm::Solver::Rosenbrock));

}  // namespace
