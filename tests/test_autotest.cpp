// The paper's auto-test round trip in process (MODEL_SPEC "Auto-test"):
// forces from inverse dynamics at the integrator's own stage times, open
// loop over the full 2 s, reproduce the prescribed path.
#include "autotest.hpp"
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
  EXPECT_LE(r.max_position_error, 1e-10);
  EXPECT_LE(r.max_angle_error, 1e-10);
  EXPECT_LE(r.max_constraint_residual, 1e-12);
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
  // MODEL_SPEC: about 99 % of each force is the weight's share; the dynamic
  // part is of order 0.01 N.
  AutotestOptions opt;
  opt.solver.solver = Solver::Rk4;
  AutotestResult r;
  ASSERT_EQ(run_autotest(default_model(), opt, r), Status::Ok);
  double total_min = 1e9, total_max = -1e9;
  for (const auto& s : r.samples) {
    total_min = std::min(total_min, s.F.sum());
    total_max = std::max(total_max, s.F.sum());
  }
  const double weight = (0.45474 + 4 * 0.09331 + 4 * 0.06371) * 9.81;
  EXPECT_NEAR(r.samples.front().F.sum(), weight, 1e-12);
  EXPECT_NEAR(r.samples.back().F.sum(), weight, 1e-12);
  EXPECT_GT(total_max - total_min, 1e-3);  // the motion does need dynamic force
  EXPECT_LT(total_max - total_min, 0.1);
}
