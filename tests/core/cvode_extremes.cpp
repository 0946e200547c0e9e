// SPDX-License-Identifier: BSD-2-Clause
// CVODE, the default solver, at the declared extremes (docs/solvers.md
// "CVODE"): the stiffest stops' impact with every method and tolerance
// that failed before, stuck friction, and the corners of the declared
// rtol and atol ranges on the stiffest machines. Each run is the drop from
// the home pose (F = 0, the stops reached at 95 ms), 1 ms steps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

const Pose kHome(0.0, 0.0, 0.05, 0.0);

SolverSettings cvode(CvodeMethod method, double rtol, double atol) {
  SolverSettings s;
  s.cvode_method = method;
  s.rtol = rtol;
  s.atol = atol;
  return s;
}

/// dz after each of `steps` steps; fails the test at a step not answered.
std::vector<double> drop(const Params& p, const SolverSettings& s, int steps) {
  std::vector<double> dz;
  Plant plant(model_of(p));
  EXPECT_EQ(plant.set_solver(s), Status::Ok);
  EXPECT_EQ(plant.initialize(0.0, kHome, Pose::Zero()), Status::Ok);
  for (int k = 1; k <= steps; ++k) {
    const Status st = plant.advance(k * 1e-3, InputSignal{});
    EXPECT_EQ(st, Status::Ok) << "step " << k << ": " << plant.last_error();
    if (st != Status::Ok) break;
    dz.push_back(plant.state()[6]);
  }
  return dz;
}

/// The largest |dz - dz_ref| relative to max |dz_ref| (at least 1 um/s).
double relative_error(const std::vector<double>& dz, const std::vector<double>& ref) {
  double worst = 0.0, scale = 1e-6;
  for (double v : ref) scale = std::max(scale, std::fabs(v));
  for (size_t k = 0; k < std::min(dz.size(), ref.size()); ++k) worst = std::max(worst, std::fabs(dz[k] - ref[k]));
  return worst / scale;
}

Params stiffest_stops(double m_slider, double damping = 1e6) {
  Params p;
  p.stop_stiffness = 1e9;
  p.stop_damping = damping;
  p.m_slider = m_slider;
  return p;
}

}  // namespace

TEST(CvodeExtremes, TheStiffestStopsAnswerEveryStepWithEveryMethodAndTolerance) {
  // Before: 13 of these 28 settings failed at the impact ("the error test
  // failed repeatedly or with |h| = hmin" at h = 1e-12 s, t = 0.0950555 s)
  // whenever atol <= 1e-12: CVODE's floor of 1 ps lay above the steps that
  // resolve the impact's deceleration. Each answers every step now, within
  // 1e-4 of the top speed of the reference (BDF, rtol 1e-10, atol 1e-12):
  // CVODE's own rtol, at most 1e-8, and the impact's magnification of it.
  const std::pair<double, double> tolerances[] = {{1e-8, 1e-10}, {1e-8, 1e-12}, {1e-8, 1e-14}, {1e-10, 1e-12},
                                                   {1e-10, 1e-14}, {1e-12, 1e-12}, {1e-12, 1e-14}};
  int settings = 0;
  for (double m_slider : {Params{}.m_slider, 1e-6}) {
    const Params p = stiffest_stops(m_slider);
    const std::vector<double> ref = drop(p, cvode(CvodeMethod::BDF, 1e-10, 1e-12), 200);
    ASSERT_EQ(ref.size(), 200u);
    for (CvodeMethod method : {CvodeMethod::Adams, CvodeMethod::BDF}) {
      for (const auto& [rtol, atol] : tolerances) {
        SCOPED_TRACE("m_slider " + std::to_string(m_slider) + (method == CvodeMethod::BDF ? ", BDF" : ", Adams") +
                     ", rtol " + std::to_string(rtol) + ", atol " + std::to_string(atol));
        const std::vector<double> dz = drop(p, cvode(method, rtol, atol), 200);
        EXPECT_EQ(dz.size(), 200u);
        EXPECT_LE(relative_error(dz, ref), 1e-4);
        ++settings;
      }
    }
  }
  EXPECT_EQ(settings, 28);
}

TEST(CvodeExtremes, StuckFrictionAnswersEveryStep) {
  // Before, at the defaults (Adams, rtol 1e-8, atol 1e-10): 1e6 N of
  // Coulomb friction with friction_velocity 1e-9 m/s answered Discard at the
  // first step, 10 N on a 1 mg slider after 167 ms. Adams gives way to BDF
  // on such a machine, BDF has the analytic Jacobian, and the velocities'
  // atol follows friction_velocity: every step answered, the machine held
  // (its creep is a fraction of friction_velocity).
  Params a;
  a.friction_coulomb = 1e6;
  a.friction_velocity = 1e-9;
  Params b;
  b.friction_coulomb = 10.0;
  b.m_slider = 1e-6;
  for (const Params& p : {a, b}) {
    Model m = model_of(p);
    EXPECT_EQ(cvode_method_for(m, SolverSettings{}), CvodeMethod::BDF);
    const std::vector<double> dz = drop(p, SolverSettings{}, 300);
    ASSERT_EQ(dz.size(), 300u);
    for (double v : dz) EXPECT_LE(std::fabs(v), p.friction_velocity);
  }
}

TEST(CvodeExtremes, TheCornersOfTheDeclaredTolerancesRunTheStiffestMachines) {
  // The declared ranges are where every machine of the declared parameter
  // ranges runs: rtol in [2^-52, 1e-2], atol in [1e-14, 1e-2]. Their
  // corners, both methods, on the stiffest stops (damped and undamped, the
  // lightest slider) and the stiffest stuck friction: every step answered.
  Params stuck;
  stuck.friction_coulomb = 10.0;
  stuck.friction_velocity = 1e-9;
  stuck.m_slider = 1e-6;
  const Params machines[] = {stiffest_stops(1e-6), stiffest_stops(Params{}.m_slider, 0.0), stuck};
  for (const Params& p : machines) {
    for (CvodeMethod method : {CvodeMethod::Adams, CvodeMethod::BDF}) {
      for (double rtol : {kMinRtol, kMaxRtol}) {
        for (double atol : {kMinAtol, kMaxAtol}) {
          SCOPED_TRACE("stop_damping " + std::to_string(p.stop_damping) + ", friction_coulomb " +
                       std::to_string(p.friction_coulomb) + (method == CvodeMethod::BDF ? ", BDF" : ", Adams") +
                       ", rtol " + std::to_string(rtol) + ", atol " + std::to_string(atol));
          EXPECT_EQ(drop(p, cvode(method, rtol, atol), 150).size(), 150u);
        }
      }
    }
  }
}
