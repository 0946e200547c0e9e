// SPDX-License-Identifier: BSD-2-Clause
// Hardening, singularities: the plant FMU driven by large constant forces
// until it really runs into a leg singularity (a rod turning vertical or
// horizontal) or a parallel singularity (actuator Jacobian condition number
// above max_jacobian_condition). The step that ends beyond a limit must
// return fmi2Discard with the last good state kept (bit-identical),
// reported by fmi2GetRealStatus(fmi2LastSuccessfulTime), paired with
// fmi2GetBooleanStatus(fmi2Terminated) = fmi2True, finite outputs within
// the limits, a message naming the leg or the condition number, and the
// instance recoverable through a saved FMU state. fmpy, as a master, then
// stops at the last successful time. The inverse FMU, asked for a pose
// beyond the same guards, answers fmi2Discard with its last good outputs.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_loader.hpp"
#include "hardening_table.hpp"
#include "reference_model.hpp"

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

// ---------------------------------------------------------------- the inverse FMU

/// The guards' quantities of a pose from docs/model.md's closed-form leg
/// inverse kinematics alone: with d = p + Rz(phi) r_Qi - B_i and
/// A^2 = d_x^2 + d_y^2 - h'^2 (invariant to Rz(beta_i)), cos theta2 = A / l
/// and rho = z - h + sqrt(l^2 - A^2) (elbow-down), so
/// d rho / du = -(d A^2 / du) / (2 sqrt(l^2 - A^2)).
struct SpecGuards {
  double leg_measure_min = 1.0;  // min |cos theta2 sin theta2|
  int leg = -1;                  // where (1-based)
  double condition = 0.0;        // of d rho / d(x, y, z, phi / 0.1 m)
};

SpecGuards spec_guards(double x, double y, double phi) {
  const ref::RefParams p;
  SpecGuards g;
  Eigen::Matrix4d J;
  for (int i = 0; i < 4; ++i) {
    const double ax = p.r_Q * std::cos(p.beta[i] + p.gamma[i] + phi), ay = p.r_Q * std::sin(p.beta[i] + p.gamma[i] + phi);
    const double dx = x + ax - p.r_b * std::cos(p.beta[i]), dy = y + ay - p.r_b * std::sin(p.beta[i]);
    const double A2 = dx * dx + dy * dy - p.h_prime * p.h_prime;
    const double c2 = std::sqrt(A2) / p.l, s2 = std::sqrt(1.0 - c2 * c2);
    if (c2 * s2 < g.leg_measure_min) {
      g.leg_measure_min = c2 * s2;
      g.leg = i + 1;
    }
    const double r = std::sqrt(p.l * p.l - A2);
    J.row(i) << -dx / r, -dy / r, 1.0, -(dy * ax - dx * ay) / r / 0.1;
  }
  const Eigen::Vector4d sv = Eigen::JacobiSVD<Eigen::Matrix4d>(J).singularValues();
  g.condition = sv[0] / sv[3];
  return g;
}

// Leg 2's rod turns horizontal at x = ref::x_rod_horizontal(2) (0.0231 m;
// y = 0, z = 0.05 m, phi = 0); with dx = 0.01 m/s the inverse FMU used to
// answer fmi2OK with forces of -1.1e19 N. Approaching that pose along x,
// every answer must follow the guards as computed from the spec: OK with
// leg_measure_min and jacobian_condition equal to the spec's within the
// limits, fmi2Discard with the reason and the last good outputs beyond.
TEST(HardeningSingularities, InverseFmuDiscardsPosesBeyondTheGuardsWithTheLastGoodOutputs) {
  const double x_singular = ref::x_rod_horizontal(2);
  struct Case {
    double max_condition, min_measure;
  };
  // The defaults, and the parallel-singularity guard lowered so that it acts first.
  for (const Case& c : {Case{1e3, 1e-2}, Case{40.0, 1e-2}}) {
    SCOPED_TRACE("max_jacobian_condition = " + std::to_string(c.max_condition));
    InverseFmu inv;
    ASSERT_EQ(inv.set("max_jacobian_condition", c.max_condition), fmi2OK);
    ASSERT_EQ(inv.set("min_leg_measure", c.min_measure), fmi2OK);
    ASSERT_EQ(inv.set("rho_min", -1.0), fmi2OK);  // slider 2 passes its lower stop near x = 0.022 m
    inv.initialize();
    ASSERT_EQ(inv.set("dx", 0.01), fmi2OK);
    const std::vector<fmi2ValueReference> vrs = inv.reals(pkm_fmi::Causality::Output);
    const std::size_t i_measure = std::find(vrs.begin(), vrs.end(), inv.vr("leg_measure_min")) - vrs.begin();
    const std::size_t i_condition = std::find(vrs.begin(), vrs.end(), inv.vr("jacobian_condition")) - vrs.begin();
    std::vector<double> good;
    int ok = 0, discarded = 0;
    std::set<std::string> reasons;
    double worst_force = 0.0;
    for (int k = 0; k <= 28; ++k) {
      // x = x_singular (1 - 10^(-k/4)): from home to 1e-7 of the singular pose.
      const double x = k == 0 ? 0.0 : x_singular * (1.0 - std::pow(10.0, -k / 4.0));
      const SpecGuards g = spec_guards(x, 0.0, 0.0);
      const bool beyond = g.leg_measure_min < c.min_measure || g.condition > c.max_condition;
      if (std::fabs(g.leg_measure_min / c.min_measure - 1.0) < 1e-6 ||
          std::fabs(g.condition / c.max_condition - 1.0) < 1e-6)
        continue;  // on a limit: either answer is right
      ASSERT_EQ(inv.set("x", x), fmi2OK);
      std::vector<double> out(vrs.size(), 12345.0);
      const std::size_t logged = inv.log.messages.size();
      const fmi2Status st = inv.lib.fmi2GetReal(inv.c, vrs.data(), vrs.size(), out.data());
      if (!beyond) {
        ASSERT_EQ(st, fmi2OK) << "x = " << x << "\n" << inv.log.dump();
        EXPECT_NEAR(out[i_measure], g.leg_measure_min, 1e-12) << "x = " << x;
        EXPECT_NEAR(out[i_condition], g.condition, 1e-9 * g.condition) << "x = " << x;
        for (int i = 1; i <= 4; ++i) worst_force = std::max(worst_force, std::fabs(inv.get(force_name(i))));
        good = out;
        ++ok;
      } else {
        ASSERT_EQ(st, fmi2Discard) << "x = " << x << ": leg measure " << g.leg_measure_min << ", condition "
                                   << g.condition << "\n" << inv.log.dump();
        ASSERT_GT(inv.log.messages.size(), logged);
        EXPECT_EQ(inv.log.messages.back().category, "logStatusDiscard");
        // The leg guard is checked first.
        const std::string reason = g.leg_measure_min < c.min_measure
                                       ? "leg " + std::to_string(g.leg) + " is at a leg singularity"
                                       : "parallel singularity: the condition number";
        EXPECT_NE(inv.log.last().find(reason), std::string::npos) << inv.log.last();
        reasons.insert(reason);
        EXPECT_TRUE(bit_identical(out, good)) << "x = " << x << ": not the last good outputs";
        ++discarded;
      }
    }
    EXPECT_GT(ok, 3);
    EXPECT_GT(discarded, 3);
    // Usable again: at rest at home, the static forces.
    ASSERT_EQ(inv.set("x", 0.0), fmi2OK);
    ASSERT_EQ(inv.set("dx", 0.0), fmi2OK);
    for (int i = 1; i <= 4; ++i) EXPECT_NEAR(inv.get(force_name(i)), kStaticForce, 1e-9);
    ASSERT_EQ(inv.step(0.0, 1e-3), fmi2OK) << inv.log.dump();
    std::string said;
    for (const std::string& r : reasons) said += (said.empty() ? "\"" : "\" / \"") + r + " ...";
    char toward[120];
    std::snprintf(toward, sizeof toward, "inverse FMU, dx = 0.01 m/s, x -> %.16g m (leg 2's rod horizontal); ",
                  x_singular);
    table_row(std::string(toward) + "max_jacobian_condition = " + std::to_string(c.max_condition),
              std::to_string(ok) + " poses within the guards fmi2OK (|F| <= " + std::to_string(worst_force) +
                  " N), " + std::to_string(discarded) + " beyond fmi2Discard " + said + "\"",
              "yes: the last good outputs handed out again; back home the static forces");
  }
}

TEST(HardeningSingularities, FmpyStopsAtTheLastSuccessfulTime) {
  // kDrives[0] through fmpy.simulate_fmu (stop_time 1 s) and through this
  // file's own drive, which reads fmi2LastSuccessfulTime from the FMU at
  // the default rk4_step. fmpy must end its result there: one row at
  // t = 0, one per successful step, the last successful time once more.
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  const Drive& d = kDrives[0];
  const double rk4_step = pkm_fmi::pkm4puu_definition().find("rk4_step")->start;
  char drive[300];
  std::snprintf(drive, sizeof drive,
                "step_size=%.17g, start_values={'F[1]': %.17g, 'F[2]': %.17g, 'F[3]': %.17g, 'F[4]': %.17g, ",
                d.step, d.F[0], d.F[1], d.F[2], d.F[3]);
  const std::string script =
      "import math, fmpy\n"
      "for solver in (0, 1):\n"
      "    r = fmpy.simulate_fmu('" PKM_FMU_PLANT_FMU "', stop_time=1.0, " + std::string(drive) + "'solver': solver},\n"
      "        output=['x', 'y', 'z', 'phi', 'rho[4]', 'theta2[4]', 'jacobian_condition'])\n"
      "    finite = all(math.isfinite(v) for row in r for v in row)\n"
      "    print('RESULT', solver, len(r), repr(float(r['time'][-1])), int(finite))\n";
  int status = 0;
  const std::string out = pkm_test::run_python(script, &status);
  ASSERT_EQ(status, 0) << out;
  std::string ends;
  for (int solver : {0, 1}) {
    SCOPED_TRACE(solver == 0 ? "CVODE" : "RK4");
    Outcome o;
    run_into_singularity(d, solver, rk4_step, o);
    if (HasFatalFailure()) return;
    const std::string key = "RESULT " + std::to_string(solver) + " ";
    const std::size_t at = out.find(key);
    ASSERT_NE(at, std::string::npos) << out;
    int rows = 0, finite = 0;
    double t_end = 0;
    ASSERT_EQ(std::sscanf(out.c_str() + at + key.size(), "%d %lf %d", &rows, &t_end, &finite), 3) << out;
    // fmpy's communication points are k * step_size, the drive's sums of
    // steps: equal within the FMU's own time tolerance (1e-9 s near t = 0).
    EXPECT_NEAR(t_end, o.last, 1e-9) << "fmpy did not stop at fmi2LastSuccessfulTime\n" << out;
    EXPECT_LT(t_end, 1.0) << "fmpy ran to stop_time";
    EXPECT_EQ(finite, 1) << "no NaN in fmpy's result";
    EXPECT_EQ(rows, std::lround(o.last / d.step) + 2) << "t = 0, one row per successful step, the last successful "
                                                         "time once more";
    char said[80];
    std::snprintf(said, sizeof said, "%s%s %.3f s (%d rows)", ends.empty() ? "" : ", ", solver == 0 ? "CVODE" : "RK4",
                  t_end, rows);
    ends += said;
  }
  table_row(std::string("fmpy.simulate_fmu, stop_time 1 s: ") + d.name + " (CVODE and RK4)",
            "fmpy reads fmi2Terminated = true after the fmi2Discard and ends the run (no exception, no retry loop)",
            "yes: result ends at fmi2LastSuccessfulTime (" + ends + "), every value finite");
}

}  // namespace
