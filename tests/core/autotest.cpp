// SPDX-License-Identifier: BSD-2-Clause
// The paper's auto-test round trip in process (docs/model.md "The paper's two tests"):
// forces from inverse dynamics at the integrator's own stage times, open
// loop over the full 2 s, reproduce the prescribed path.
#include <cmath>

#include "apps/autotest.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

AutotestResult run(Solver solver, Formulation form, CvodeMethod method = CvodeMethod::Adams) {
  AutotestOptions opt;
  opt.solver.solver = solver;
  opt.solver.formulation = form;
  opt.solver.cvode_method = method;
  opt.solver.rk4_step = 1e-3;
  opt.solver.rtol = 1e-12;
  opt.solver.atol = 1e-14;
  AutotestResult r;
  EXPECT_EQ(run_autotest(default_model(), opt, r), Status::Ok) << r.error;
  EXPECT_EQ(r.samples.size(), 2001u);
  std::printf("  %s, %s: max error %.2e m, %.2e rad, max ||C|| %.1e m, %ld evaluations\n",
              solver == Solver::Rk4 ? "RK4 1 ms" : (method == CvodeMethod::Adams ? "CVODE Adams" : "CVODE BDF"),
              formulation_name(form), r.max_position_error, r.max_angle_error, r.max_constraint_residual,
              r.rhs_evaluations);
  return r;
}

void expect_reproduced(const AutotestResult& r) {
  EXPECT_LE(r.max_position_error, kAutotestBounds.position);
  EXPECT_LE(r.max_angle_error, kAutotestBounds.angle);
  EXPECT_LE(r.max_constraint_residual, kAutotestBounds.constraint);
  // The path really moved: 20 mm up and 4 degrees.
  EXPECT_NEAR(r.samples.back().simulated[2] - r.samples.front().simulated[2], 0.02, 1e-9);
}

}  // namespace

TEST(Autotest, Rk4At1msReproducesThePath) { expect_reproduced(run(Solver::Rk4, Formulation::LegPartitioned)); }

TEST(Autotest, Rk4WithAugmentedSystemEq12) { expect_reproduced(run(Solver::Rk4, Formulation::Augmented)); }

TEST(Autotest, Rk4WithQrNullSpaceEq13) { expect_reproduced(run(Solver::Rk4, Formulation::NullSpaceQR)); }

TEST(Autotest, CvodeAdamsReproducesThePath) { expect_reproduced(run(Solver::Cvode, Formulation::LegPartitioned)); }

TEST(Autotest, CvodeBdfReproducesThePath) {
  expect_reproduced(run(Solver::Cvode, Formulation::LegPartitioned, CvodeMethod::BDF));
}

TEST(Autotest, ForcesAreMostlyStatic) {
  // docs/model.md "The paper's two tests": about 99 % of each force is static; the dynamic
  // part is ~0.013 N.
  AutotestOptions opt;
  opt.solver.solver = Solver::Rk4;
  AutotestResult r;
  ASSERT_EQ(run_autotest(default_model(), opt, r), Status::Ok);
  double min_force = 1e9;
  for (const auto& s : r.samples) min_force = std::min(min_force, s.F.minCoeff());
  EXPECT_NEAR(r.max_dynamic_force, 0.013, 0.001);
  EXPECT_LT(r.max_dynamic_force, 0.01 * min_force);
}

TEST(Autotest, ActuatorForcesBalanceWeightAndVerticalMomentum) {
  // The prismatic joints are vertical and frictionless, so the base can push
  // the mechanism only horizontally: sum F_i = M_total g + dP_z/dt, with the
  // vertical momentum P_z of all bodies (platform, sliders, rods) computed
  // here from the spec's body definitions and differentiated numerically.
  const Model m = default_model();
  const RestToRest path;
  auto momentum = [&](double t) {
    const Motion x = path_motion(path, t);
    const InverseDynamicsResult r = inverse_dynamics_of(m, x);
    double Pz = m.p.m_platform * x.vel[2];
    for (int i = 0; i < 4; ++i) {
      const int o = leg_offset(i);
      // slider: rhod; rod centre of mass: rhod + l/2 cos(theta2) theta2d
      Pz += m.p.m_slider * r.qd[o] + m.p.m_rod * (r.qd[o] + 0.5 * m.p.l * std::cos(r.q[o + 2]) * r.qd[o + 2]);
    }
    return Eigen::Matrix<double, 1, 1>(Pz);
  };
  for (double t : {0.2, 0.5, 0.9, 1.3, 1.8}) {
    const InverseDynamicsResult r = inverse_dynamics_of(m, path_motion(path, t));
    const double dPz = d_ds([&](double e) { return momentum(t + e); }, 1e-3)[0];
    EXPECT_NEAR(r.F.sum(), m.total_mass * m.p.g + dPz, 1e-10) << "t = " << t;
    EXPECT_GT(std::fabs(dPz), 1e-4);  // the dynamic term is really there
  }
}
