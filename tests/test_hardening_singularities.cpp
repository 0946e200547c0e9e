// Hardening, singularities: the plant FMU driven by large constant forces
// until it really runs into a leg singularity (a rod turning vertical or
// horizontal) or a parallel singularity (actuator Jacobian condition number
// above max_jacobian_condition). The step that ends beyond a limit must
// return fmi2Discard with the last good state kept (bit-identical),
// reported by fmi2GetRealStatus(fmi2LastSuccessfulTime), paired with
// fmi2GetBooleanStatus(fmi2Terminated) = fmi2True, finite outputs within
// the limits, a message naming the leg or the condition number, and the
// instance recoverable through a saved FMU state. fmpy, as a master, then
// stops at the last successful time.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_loader.hpp"
#include "hardening_table.hpp"

namespace {

using namespace pkm_test;

struct Drive {
  const char* name;
  double F[4];
  double wrench[4];
  std::vector<std::pair<const char*, double>> params;
  double step;            // communication step, s
  const char* expected;   // in the discard message
  double t_min, t_max;    // the discard happens within [t_min, t_max]
};

const double kGamma65 = 65.0 * kPi / 180.0;
const double Fs = kStaticForce;

// Found by driving the plant (see the test's table rows): each reaches its
// singularity within a fraction of a second.
const Drive kDrives[] = {
    {"leg singularity, rod vertical: F[1] = Fs + 1 N, F[3] = Fs - 1 N",
     {Fs + 1.0, Fs, Fs - 1.0, Fs}, {0, 0, 0, 0}, {}, 1e-3, "leg 4 is at a leg singularity", 0.15, 0.25},
    // On the way leg 2's slider passes its lower end stop, which would hold
    // it: the stops are moved out of the way (this case is about the guard).
    {"leg singularity, rod horizontal: Fe[1] = 5 N, F = Fs (end stops out of the way)",
     {Fs, Fs, Fs, Fs}, {5.0, 0, 0, 0}, {{"rho_min", -1.0}}, 1e-3, "leg 2 is at a leg singularity", 0.12, 0.2},
    {"parallel singularity, identical legs (gamma[1..4] = 65 deg) from x0 = 15 mm, F = Fs",
     {Fs, Fs, Fs, Fs}, {0, 0, 0, 0}, {{"gamma[2]", kGamma65}, {"gamma[4]", kGamma65}, {"x0", 0.015}}, 1e-3,
     "parallel singularity: the condition number", 0.02, 0.08},
    {"parallel-singularity guard lowered to max_jacobian_condition = 30: F[1] = Fs + 1 N, F[3] = Fs - 1 N",
     {Fs + 1.0, Fs, Fs - 1.0, Fs}, {0, 0, 0, 0}, {{"max_jacobian_condition", 30.0}}, 1e-3,
     "exceeds max_jacobian_condition = 30", 0.1, 0.2},
};

double min_leg_measure_of(PlantFmu& p) {
  double m = 1.0;
  for (int i = 1; i <= 4; ++i) {
    const double th2 = p.get("theta2[" + std::to_string(i) + "]");
    m = std::min(m, std::fabs(std::cos(th2) * std::sin(th2)));
  }
  return m;
}

struct Outcome {
  double t_fail = -1;        // start of the discarded step
  double last = -1;          // fmi2LastSuccessfulTime
  double condition = 0, leg_measure = 0;
  std::string message;
};

/// Drives until the first status other than fmi2OK; checks everything the
/// issue asks of a discarded step.
void run_into_singularity(const Drive& d, int solver, double rk4_step, Outcome& out) {
  PlantFmu p;
  ASSERT_NE(p.c, nullptr);
  ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
  ASSERT_EQ(p.set("rk4_step", rk4_step), fmi2OK);
  for (const auto& [name, value] : d.params) ASSERT_EQ(p.set(name, value), fmi2OK);
  p.initialize();
  for (int i = 0; i < 4; ++i) ASSERT_EQ(p.set(force_name(i + 1), d.F[i]), fmi2OK);
  const char* wrench[4] = {"Fe[1]", "Fe[2]", "Fe[3]", "Me_z"};
  for (int i = 0; i < 4; ++i) ASSERT_EQ(p.set(wrench[i], d.wrench[i]), fmi2OK);

  double max_condition = 1e3;
  for (const auto& [name, value] : d.params)
    if (std::string(name) == "max_jacobian_condition") max_condition = value;

  double t = 0.0;
  fmi2Status st = fmi2OK;
  std::vector<double> before;
  fmi2FMUstate home = nullptr, good = nullptr;
  ASSERT_EQ(p.lib.fmi2GetFMUstate(p.c, &home), fmi2OK);
  for (int k = 0; k < 2000; ++k) {
    before = p.outputs();
    ASSERT_TRUE(all_finite(before)) << "a NaN or Inf output at t = " << t;
    ASSERT_EQ(p.lib.fmi2GetFMUstate(p.c, &good), fmi2OK);
    st = p.step(t, d.step);
    if (st != fmi2OK) break;
    t = (k + 1) * d.step;
  }
  ASSERT_EQ(st, fmi2Discard) << "no singularity reached by t = " << t << "\n" << p.log.dump();
  out.t_fail = t;
  out.message = p.log.last();
  EXPECT_EQ(p.log.messages.back().status, fmi2Discard);
  EXPECT_EQ(p.log.messages.back().category, "logStatusDiscard");
  EXPECT_GE(t, d.t_min);
  EXPECT_LE(t, d.t_max);

  // The pairing that makes a master stop: Terminated, at the last successful time.
  EXPECT_TRUE(p.terminated());
  out.last = p.last_successful_time();
  EXPECT_GE(out.last, t);
  EXPECT_LT(out.last, t + d.step);
  if (rk4_step >= d.step || solver == 0) {
    EXPECT_EQ(out.last, t) << "the state of the step start is kept";
  }

  // The kept state: finite, within the limits, and (at the step start) bit-identical.
  const std::vector<double> kept = p.outputs();
  EXPECT_TRUE(all_finite(kept));
  if (out.last == t) {
    EXPECT_TRUE(bit_identical(kept, before)) << "the last good state was changed";
  }
  out.condition = p.get("jacobian_condition");
  out.leg_measure = min_leg_measure_of(p);
  EXPECT_LE(out.condition, max_condition);
  EXPECT_GE(out.leg_measure, 1e-2);
  EXPECT_LT(p.get("constraint_residual"), 1e-12);

  // Step failed: no further step; get, terminate and FMU states are allowed.
  EXPECT_EQ(p.step(out.last, d.step), fmi2Error);
  fmi2FMUstate failed = nullptr;
  ASSERT_EQ(p.lib.fmi2GetFMUstate(p.c, &failed), fmi2OK);
  // Back to the state saved before the failing step: the instance goes on
  // (a shorter step still fits before the limit) ...
  ASSERT_EQ(p.lib.fmi2SetFMUstate(p.c, good), fmi2OK) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.outputs(), before));
  EXPECT_FALSE(p.terminated());
  EXPECT_EQ(p.step(t, 1e-6), fmi2OK) << p.log.dump();
  EXPECT_TRUE(all_finite(p.outputs()));
  // ... and back to the start, with the static forces, it stays at rest.
  ASSERT_EQ(p.lib.fmi2SetFMUstate(p.c, home), fmi2OK) << p.log.dump();
  for (int i = 0; i < 4; ++i) ASSERT_EQ(p.set(force_name(i + 1), Fs), fmi2OK);
  for (const char* w : wrench) ASSERT_EQ(p.set(w, 0.0), fmi2OK);
  for (int k = 0; k < 10; ++k) ASSERT_EQ(p.step(k * d.step, d.step), fmi2OK) << p.log.dump();
  EXPECT_TRUE(all_finite(p.outputs()));
  // The failed state can be restored too (Terminated again) and terminated.
  ASSERT_EQ(p.lib.fmi2SetFMUstate(p.c, failed), fmi2OK);
  EXPECT_TRUE(p.terminated());
  EXPECT_EQ(p.lib.fmi2Terminate(p.c), fmi2OK);
  p.lib.fmi2FreeFMUstate(p.c, &home);
  p.lib.fmi2FreeFMUstate(p.c, &good);
  p.lib.fmi2FreeFMUstate(p.c, &failed);
}

class HardeningSingularities : public ::testing::TestWithParam<std::tuple<int, int>> {
 protected:
  void SetUp() override { ASSERT_TRUE(plant_library().missing.empty()) << plant_library().missing; }
};

TEST_P(HardeningSingularities, DrivingIntoASingularityDiscardsTheStepAndKeepsTheLastGoodState) {
  const Drive& d = kDrives[std::get<0>(GetParam())];
  const int solver = std::get<1>(GetParam());
  SCOPED_TRACE(d.name);
  Outcome o;
  run_into_singularity(d, solver, 1e-3, o);
  if (HasFatalFailure()) return;
  EXPECT_NE(o.message.find(d.expected), std::string::npos) << o.message;
  const std::size_t from = std::min(o.message.find("failed ("), o.message.size());
  const std::string why = o.message.substr(from, 200);
  char row[600];
  std::snprintf(row, sizeof row, "fmi2Discard in the step %.3f..%.3f s, fmi2Terminated = true; \"%s...\"", o.t_fail,
                o.t_fail + d.step, why.c_str());
  char kept[300];
  std::snprintf(kept, sizeof kept,
                "yes: fmi2LastSuccessfulTime = %.3f s, outputs bit-identical to the step start, finite; "
                "cond %.4g, min |c2 s2| %.3g there",
                o.last, o.condition, o.leg_measure);
  table_row(std::string(solver == 0 ? "CVODE" : "RK4") + ", 1 ms steps: " + d.name, row, kept);
}

std::string drive_name(const ::testing::TestParamInfo<std::tuple<int, int>>& i) {
  static const char* const names[] = {"RodVertical", "RodHorizontal", "IdenticalLegs", "LoweredGuard"};
  return std::string(names[std::get<0>(i.param)]) + (std::get<1>(i.param) == 0 ? "_CVODE" : "_RK4");
}

INSTANTIATE_TEST_SUITE_P(Drives, HardeningSingularities,
                         ::testing::Combine(::testing::Range(0, static_cast<int>(std::size(kDrives))),
                                            ::testing::Values(0, 1)),
                         drive_name);

TEST(HardeningSingularities, Rk4KeepsTheLastGoodInternalStepInsideACommunicationStep) {
  // 1-ms communication steps of ten 0.1-ms RK4 steps: the guard fails an
  // internal step; the state of the previous internal step is kept.
  Outcome o;
  run_into_singularity(kDrives[1], 1, 1e-4, o);
  if (::testing::Test::HasFatalFailure()) return;
  EXPECT_GT(o.last, o.t_fail) << "some internal steps of the failing communication step were good";
  EXPECT_NE(o.message.find("rod nearly horizontal"), std::string::npos) << o.message;
  char row[200], kept[300];
  std::snprintf(row, sizeof row, "fmi2Discard in the step %.4f..%.4f s, fmi2Terminated = true", o.t_fail,
                o.t_fail + 1e-3);
  std::snprintf(kept, sizeof kept,
                "yes: fmi2LastSuccessfulTime = %.4f s (the last good internal step), outputs finite, cond %.4g, "
                "min |c2 s2| %.3g",
                o.last, o.condition, o.leg_measure);
  table_row("RK4, rk4_step 0.1 ms inside 1 ms steps: Fe[1] = 5 N (rod of leg 2 turning horizontal)", row, kept);
}

TEST(HardeningSingularities, AStepThatLeavesTheWorkspaceEntirelyIsDiscardedToo) {
  // 50 N sideways: an RK4 stage or CVODE's trial state leaves the reachable
  // set before any step end lands between the limit and the edge.
  for (int solver : {0, 1}) {
    PlantFmu p;
    ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
    p.initialize();
    ASSERT_EQ(p.set("Fe[1]", 50.0), fmi2OK);
    double t = 0.0;
    fmi2Status st = fmi2OK;
    std::vector<double> before;
    for (int k = 0; k < 200 && st == fmi2OK; ++k) {
      before = p.outputs();
      st = p.step(t, 1e-3);
      if (st == fmi2OK) t += 1e-3;
    }
    ASSERT_EQ(st, fmi2Discard) << p.log.dump();
    EXPECT_TRUE(p.terminated());
    EXPECT_EQ(p.last_successful_time(), t);
    EXPECT_TRUE(bit_identical(p.outputs(), before));
    table_row(std::string(solver == 0 ? "CVODE" : "RK4") + ", 1 ms steps: Fe[1] = 50 N (leaves the workspace within "
                                                         "one step)",
              "fmi2Discard at t = " + std::to_string(t) + " s, fmi2Terminated = true (\"" +
                  (solver == 0 ? std::string("CVODE ... corrector convergence test failed") :
                                 std::string("the RK4 step ... could not be evaluated: pose unreachable")) + "\")",
              "yes: outputs bit-identical to the step start, finite");
  }
}

TEST(HardeningSingularities, FmpyStopsAtTheLastSuccessfulTime) {
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  const std::string script =
      "import math, fmpy\n"
      "F = 2.655616050\n"
      "for solver in (0, 1):\n"
      "    r = fmpy.simulate_fmu('" PKM_FMU_PLANT_FMU "', stop_time=1.0, step_size=1e-3,\n"
      "        start_values={'F[1]': F + 1.0, 'F[2]': F, 'F[3]': F - 1.0, 'F[4]': F, 'solver': solver},\n"
      "        output=['x', 'y', 'z', 'phi', 'rho[4]', 'theta2[4]', 'jacobian_condition'])\n"
      "    finite = all(math.isfinite(v) for row in r for v in row)\n"
      "    print('RESULT', solver, len(r), r['time'][-1], int(finite))\n";
  int status = 0;
  const std::string out = pkm_test::run_python(script, &status);
  ASSERT_EQ(status, 0) << out;
  for (int solver : {0, 1}) {
    const std::string key = "RESULT " + std::to_string(solver) + " ";
    const std::size_t at = out.find(key);
    ASSERT_NE(at, std::string::npos) << out;
    int rows = 0, finite = 0;
    double t_end = 0;
    ASSERT_EQ(std::sscanf(out.c_str() + at + key.size(), "%d %lf %d", &rows, &t_end, &finite), 3) << out;
    EXPECT_NEAR(t_end, 0.193, 1e-9) << "fmpy stopped at fmi2LastSuccessfulTime, not at stop_time\n" << out;
    EXPECT_EQ(finite, 1) << "no NaN in fmpy's result";
    EXPECT_EQ(rows, 195) << "t = 0, 0.001, ..., 0.193, and the last successful time once more";
  }
  table_row("fmpy.simulate_fmu, stop_time 1 s, F[1] = Fs + 1 N, F[3] = Fs - 1 N (CVODE and RK4)",
            "fmpy reads fmi2Terminated = true after the fmi2Discard and ends the run (no exception, no retry loop)",
            "yes: result ends at t = 0.193 s = fmi2LastSuccessfulTime, every value finite");
}

}  // namespace
