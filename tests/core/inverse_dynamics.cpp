// SPDX-License-Identifier: BSD-2-Clause
// The reduced inverse dynamics (inverse_dynamics: closed-form leg inverse
// kinematics, the leg-partitioned reduced system, lambda leg by leg)
// against the general path (inverse_dynamics_general: Newton on the servo
// constraints, the 16x16 Phi_q, Eqs. 10-11 with the full M and C_q), an
// independent computation of the same quantities, with the machine on.
#include "apps/autotest.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

/// The two paths agree to 1e-12 relative in every output; returns the
/// largest relative difference of F.
double expect_paths_agree(const Model& m, const Pose& p, const Pose& v, const Pose& a, const Wrench& we) {
  InverseDynamicsResult r, g;
  EXPECT_EQ(inverse_dynamics(m, p, v, a, we, r), Status::Ok);
  EXPECT_EQ(inverse_dynamics_general(m, p, v, a, we, g), Status::Ok);
  const double dF = rel_diff(r.F, g.F);
  EXPECT_LT(dF, 1e-12) << r.F.transpose() << " vs " << g.F.transpose();
  EXPECT_LT(rel_diff(r.tau, g.tau), 1e-12);
  EXPECT_LT(rel_diff(r.lambda, g.lambda), 1e-12) << r.lambda.transpose() << "\nvs " << g.lambda.transpose();
  EXPECT_LT(rel_diff(r.q, g.q), 1e-12);
  EXPECT_LT(rel_diff(r.qd, g.qd), 1e-12);
  EXPECT_LT(rel_diff(r.qdd, g.qdd), 1e-12);
  EXPECT_EQ(r.beyond_stops, g.beyond_stops);
  // The angles (a rational atan in lanes against libm's atan2 and acos
  // through Newton): to a few units in the last place of pi.
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    EXPECT_LT(std::fabs(r.q[o + 1] - g.q[o + 1]), 1e-15) << "theta1 of leg " << i + 1;
    EXPECT_LT(std::fabs(r.q[o + 2] - g.q[o + 2]), 1e-15) << "theta2 of leg " << i + 1;
  }
  // The actuators-only entry point: the same kernel, the same bits.
  InverseActuators act;
  EXPECT_EQ(inverse_actuators(m, p, v, a, we, act), Status::Ok);
  EXPECT_EQ(act.F, r.F);
  EXPECT_EQ(act.tau, r.tau);
  double measure = 0.5;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    EXPECT_EQ(act.rho[i], r.q[o]);
    EXPECT_EQ(act.rhod[i], r.qd[o]);
    measure = std::min(measure, std::fabs(std::cos(g.q[o + 2]) * std::sin(g.q[o + 2])));
  }
  EXPECT_NEAR(act.leg_measure_min, measure, 1e-14);
  EXPECT_EQ(act.beyond_stops, g.beyond_stops);
  return dF;
}

}  // namespace

TEST(InverseDynamics, ReducedMatchesGeneralAtRandomReachableStates) {
  for (const Params& params : {Params{}, every_machine_term()}) {
    const Model m = model_of(params);
    double worst = 0.0;
    for (unsigned seed = 1; seed <= 200; ++seed) {
      SCOPED_TRACE(seed);
      const RandomState s = random_state(m, seed);
      const Pose acc = random_vec<4>(1000 + seed, 3.0);
      const Wrench we = random_vec<4>(2000 + seed, 0.5);
      worst = std::max(worst, expect_paths_agree(m, s.pose, s.vel, acc, we));
    }
    std::printf("random states: largest relative difference of F %.2e (bound 1e-12)\n", worst);
  }
}

TEST(InverseDynamics, ReducedMatchesGeneralAlongTheAutotestPath) {
  for (const Params& params : {Params{}, every_machine_term()}) {
    const Model m = model_of(params);
    const RestToRest path;
    double worst = 0.0;
    for (int k = 0; k <= 200; ++k) {
      const double t = path.duration * k / 200.0;
      SCOPED_TRACE(t);
      Pose p, pd, pdd;
      path.eval(t, p, pd, pdd);
      worst = std::max(worst, expect_paths_agree(m, p, pd, pdd, Wrench::Zero()));
    }
    std::printf("auto-test path: largest relative difference of F %.2e (bound 1e-12)\n", worst);
  }
}

TEST(InverseDynamics, ReducedMatchesGeneralBeyondAnEndStop) {
  // The highest slider's upper stop 1 mm below its joint, the lowest
  // slider's lower stop 1 mm above its: both stops' forces enter F, on
  // both paths.
  const RandomState s = random_state(model_of(every_machine_term()), 7);
  Vec4 rho;
  ASSERT_EQ(actuator_positions(model_of(every_machine_term()), s.pose, rho), Status::Ok);
  int hi = 0, lo = 0;
  rho.maxCoeff(&hi);
  rho.minCoeff(&lo);
  Params p = every_machine_term();
  p.rho_max = rho[hi] - 1e-3;
  p.rho_min = rho[lo] + 1e-3;
  ASSERT_LT(p.rho_min, p.rho_max);
  const Model m = model_of(p);
  ASSERT_NE(stop_force(m.p, rho[hi], 0.0), 0.0);
  ASSERT_NE(stop_force(m.p, rho[lo], 0.0), 0.0);
  const Pose acc(0.3, -0.2, 0.5, 2.0);
  InverseDynamicsResult r;
  ASSERT_EQ(inverse_dynamics(m, s.pose, s.vel, acc, Wrench::Zero(), r), Status::Ok);
  EXPECT_EQ(r.beyond_stops, (1u << (4 + hi)) | (1u << lo));
  expect_paths_agree(m, s.pose, s.vel, acc, Wrench(0.1, 0.2, -0.3, 0.01));
}

TEST(InverseDynamics, ReducedGivesTheGeneralPathsStatuses) {
  const Model m = model_of(every_machine_term());
  const Pose z = Pose::Zero();
  InverseDynamicsResult r, g;
  InverseActuators act;
  struct Bad { const char* what; Pose p, v; Status expected; };
  const double nan = std::nan("");
  const Bad bad[] = {
      {"far to the other side", Pose(0, -1.0, 0.05, 0), z, Status::Unreachable},
      {"far to the side", Pose(1.0, 0, 0.05, 0), z, Status::Unreachable},
      {"NaN pose", Pose(nan, 0, 0.05, 0), z, Status::NonFinite},
      {"infinite rate", Pose(0, 0, 0.05, 0), Pose(0, INFINITY, 0, 0), Status::NonFinite},
  };
  for (const Bad& b : bad) {
    SCOPED_TRACE(b.what);
    EXPECT_EQ(inverse_dynamics_general(m, b.p, b.v, z, Wrench::Zero(), g), b.expected);
    EXPECT_EQ(inverse_dynamics(m, b.p, b.v, z, Wrench::Zero(), r), b.expected);
    EXPECT_EQ(inverse_actuators(m, b.p, b.v, z, Wrench::Zero(), act), b.expected);
  }
}

