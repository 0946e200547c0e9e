// SPDX-License-Identifier: BSD-2-Clause
// Hardening, bad input: non-finite inputs and parameters, out-of-range
// parameters, geometry for which the initial pose cannot be assembled, an
// initial pose outside the elbow-down working mode or beyond the
// singularity guards. Each must give fmi2Error with a logged message that
// names the variable, change nothing it should not (inputs rejected: the
// state continues bit-identically), and after fmi2Reset the instance works
// again. Through the built PKM4PUU.so / PKM4PUU_Inverse.so (dlopen).
// Every case prints a row of the hardening table ("| tried | answer | kept |").
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_fixture.hpp"

namespace {

using namespace pkm_test;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string text(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// A plant with `solver`, initialised and stepped 20 times (1 ms), inputs set
/// for the next step.
void prepare(PlantFmu& p, int solver, double& t) {
  ASSERT_EQ(p.set_int("solver", solver), fmi2OK);
  prepare(p, t, 20);
}

/// After an error: fmi2Reset, then the default parameters initialise and step.
void expect_usable_after_reset(PlantFmu& p) {
  ASSERT_EQ(p.lib.fmi2Reset(p.c), fmi2OK) << p.log.dump();
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), kStaticForce), fmi2OK);
  for (int k = 0; k < 10; ++k) ASSERT_EQ(p.step(k * 1e-3, 1e-3), fmi2OK) << p.log.dump();
  const std::vector<double> out = p.outputs();
  EXPECT_TRUE(all_finite(out));
  EXPECT_NEAR(p.get("z"), 0.05, 1e-9);
}

class HardeningInputs : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    ASSERT_TRUE(plant_library().missing.empty()) << plant_library().missing;
    ASSERT_TRUE(inverse_library().missing.empty()) << inverse_library().missing;
  }
};

// ---------------------------------------------------------------- non-finite inputs

TEST_P(HardeningInputs, NonFiniteInputsAreRejectedAndTheStateContinuesUnchanged) {
  const int solver = GetParam();
  const char* inputs[] = {"F[1]", "F[2]", "F[3]", "F[4]", "Fe[1]", "Fe[2]", "Fe[3]", "Me_z"};
  for (const char* name : inputs) {
    for (double bad : {kNaN, kInf, -kInf}) {
      SCOPED_TRACE(std::string(name) + " = " + text(bad));
      PlantFmu p("bad"), twin("twin");
      double t = 0.0, t2 = 0.0;
      prepare(p, solver, t);
      prepare(twin, solver, t2);
      const std::vector<double> before = p.all_reals();
      // fmi2SetReal of the value.
      EXPECT_EQ(p.set(name, bad), fmi2Error);
      EXPECT_EQ(p.log.messages.back().status, fmi2Error);
      EXPECT_TRUE(p.log.contains(name)) << p.log.dump();
      // fmi2SetRealInputDerivatives of its slope.
      EXPECT_EQ(p.set_derivative(name, bad), fmi2Error);
      EXPECT_TRUE(p.log.last().find(name) != std::string::npos) << p.log.dump();
      // In a vector call with good values: nothing of it is applied.
      const fmi2ValueReference vrs[2] = {p.vr("F[1]"), p.vr(name)};
      const double values[2] = {1.0, bad};
      EXPECT_EQ(p.lib.fmi2SetReal(p.c, vrs, 2, values), fmi2Error);
      EXPECT_TRUE(bit_identical(p.all_reals(), before)) << "a rejected value changed the instance";
      // The same step as an instance that never saw the bad values.
      ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
      ASSERT_EQ(twin.step(t2, 1e-3), fmi2OK);
      EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs()));
      expect_usable_after_reset(p);
      if (solver == 0 && std::string(name) != "F[2]" && std::string(name) != "F[3]" && std::string(name) != "F[4]" &&
          std::string(name) != "Fe[2]" && std::string(name) != "Fe[3]")
        table_row(std::string("fmi2SetReal / fmi2SetRealInputDerivatives: ") + name + " = " + text(bad),
                  "fmi2Error, \"" + std::string(name) + " = ... is not finite; value rejected\"",
                  "yes: all variables bit-identical, next step bit-identical to an untouched twin");
    }
  }
}

TEST_P(HardeningInputs, InputsExtrapolatedToNonFiniteValuesFailTheStepWithTheStateKept) {
  PlantFmu p;
  double t = 0.0;
  prepare(p, GetParam(), t);
  ASSERT_EQ(p.set_derivative("F[1]", 1e308), fmi2OK);  // finite slope ...
  const std::vector<double> before = p.outputs();
  EXPECT_EQ(p.step(t, 10.0), fmi2Error);  // ... but F[1] = 1e309 at the step's end
  EXPECT_TRUE(p.log.last().find("F[1]") != std::string::npos) << p.log.dump();
  EXPECT_TRUE(p.log.last().find("not finite") != std::string::npos) << p.log.dump();
  EXPECT_TRUE(bit_identical(p.outputs(), before)) << "the call had no effect";
  EXPECT_EQ(p.last_successful_time(), t);
  // A shorter step with the same slope is fine.
  EXPECT_EQ(p.step(t, 1e-3), fmi2Discard) << "F[1] ramps at 1e308 N/s: the platform leaves the workspace";
  EXPECT_TRUE(all_finite(p.outputs()));
  expect_usable_after_reset(p);
  if (GetParam() == 0)
    table_row("fmi2SetRealInputDerivatives(F[1], 1e308), then fmi2DoStep(h = 10 s): input extrapolates to +Inf",
              "fmi2Error at fmi2DoStep (\"F[1] extrapolated ... is not finite; the call has no effect\")",
              "yes: outputs bit-identical, time unchanged, the instance steps on");
}

// ---------------------------------------------------------------- parameters

TEST(HardeningParameters, NonFiniteParametersAreRejectedBeforeInitialisation) {
  const pkm_fmi::ModelDefinition& d = pkm_fmi::pkm4puu_definition();
  int n = 0;
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    const pkm_fmi::Variable& v = d.variables[k];
    if (v.causality != pkm_fmi::Causality::Parameter || v.type != pkm_fmi::VarType::Real) continue;
    for (double bad : {kNaN, kInf, -kInf}) {
      SCOPED_TRACE(std::string(v.name) + " = " + text(bad));
      PlantFmu p;
      double start = 0.0;
      ASSERT_EQ(p.lib.fmi2GetReal(p.c, &v.vr, 1, &start), fmi2Error) << "outputs and parameters: not before init";
      EXPECT_EQ(p.set(v.name, bad), fmi2Error);
      EXPECT_TRUE(p.log.contains(v.name)) << p.log.dump();
      ASSERT_EQ(p.enter(), fmi2OK);
      EXPECT_EQ(p.get(v.name), v.start) << "the start value is kept";
      ASSERT_EQ(p.exit(), fmi2OK) << p.log.dump();
    }
    ++n;
  }
  // 21 of the mechanism, 8 of the initial state, rk4_step, rtol, atol, the
  // two guards, 11 of the machine (docs/model.md), the stops' stiffness and
  // damping, work_budget and energy_tolerance.
  EXPECT_EQ(n, 49);
  table_row("fmi2SetReal of any Real parameter (all " + std::to_string(n) + " of the plant) to NaN, +Inf, -Inf",
            "fmi2Error, \"<name> = nan is not finite; value rejected\"",
            "yes: start value kept, initialisation succeeds");
}

struct BadParameter {
  std::string name;
  double value;
  std::string message;  // expected in the log
  bool integer = false;
};

TEST(HardeningParameters, OutOfRangeParametersFailInitialisationAndResetRecovers) {
  std::vector<BadParameter> cases;
  // Lengths, masses and the platform's inertia must be positive: zero and a
  // negative value are refused, "<name> = <value> must be positive".
  const std::pair<const char*, double> positive[] = {
      {"h", -0.0625}, {"l", -0.125},       {"h_prime", -1.0},   {"r_b", -1.0},
      {"r_Q", -0.5},  {"m_slider", -0.125}, {"m_rod", -1.0},     {"m_platform", -0.5},
      {"Izz_platform", -1e-3}};
  for (const auto& [name, negative] : positive)
    for (double value : {0.0, negative})
      cases.push_back({name, value, std::string(name) + " = " + text(value) + " must be positive"});
  const BadParameter others[] = {
      {"I_rod[1]", 0.0, "I_rod[1] = 0 must be positive"},
      {"I_rod[2]", -0.25, "I_rod[2] = -0.25 must be positive"},
      {"I_rod[3]", 0.0, "I_rod[3] = 0 must be positive"},
      {"I_rod[1]", 1e-3, "I_rod[1]"},  // violates the triangle inequality of principal moments
      {"rk4_step", 0.0, "rk4_step = 0 s must be positive"},
      {"rk4_step", -1e-3, "rk4_step = -0.001 s must be positive"},
      {"rtol", 0.0, "rtol = 0 must lie in (0, 1)"},
      {"rtol", 1.0, "rtol = 1 must lie in (0, 1)"},
      {"atol", 0.0, "atol = 0 must be positive"},
      {"atol", -1e-10, "atol = -1e-10 must be positive"},
      {"max_jacobian_condition", 1.0, "max_jacobian_condition = 1 must be greater than 1"},
      {"max_jacobian_condition", -5.0, "max_jacobian_condition = -5 must be greater than 1"},
      {"min_leg_measure", -0.25, "min_leg_measure = -0.25 must lie in [0, 0.5)"},
      {"min_leg_measure", 0.5, "min_leg_measure = 0.5 must lie in [0, 0.5)"},
      {"solver", 3, "solver = 3 must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)", true},
      {"solver", -1, "solver = -1 must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)", true},
      {"cvode_method", 7, "cvode_method = 7 must be 0 (Adams) or 1 (BDF)", true},
      {"formulation", 3, "formulation = 3 must be 0", true},
      {"formulation", -2, "formulation = -2 must be 0", true},
      // Values no step can use, refused when set.
      {"rk4_step", 1e-9, "rk4_step"},
      {"rk4_step", 1e-10, "rk4_step"},
      {"rk4_step", 1e-300, "rk4_step"},
      {"g", 1e300, "g"},
      {"g", -2e3, "g"},
      {"l", 20.0, "l"},
      {"m_platform", 1e30, "m_platform"},
      {"dx0", 1e200, "dx0"},
      {"dphi0", -1e5, "dphi0"},
      {"stop_stiffness", 1e12, "stop_stiffness"},
      {"work_budget", 0.5, "work_budget"},
      {"energy_tolerance", -1.0, "energy_tolerance"},
  };
  cases.insert(cases.end(), std::begin(others), std::end(others));
  ASSERT_EQ(cases.size(), 49u);
  int refused_when_set = 0;
  for (const BadParameter& c : cases) {
    SCOPED_TRACE(std::string(c.name) + " = " + text(c.value));
    PlantFmu p;
    // Outside the modelDescription's [min, max] (the table's): refused when
    // set, with the range in the message, and the start value kept.
    const pkm_fmi::Variable* v = p.def.find(c.name.c_str());
    ASSERT_NE(v, nullptr);
    if (!(c.value >= v->min && c.value <= v->max)) {
      ++refused_when_set;
      EXPECT_EQ(c.integer ? p.set_int(c.name, static_cast<int>(c.value)) : p.set(c.name, c.value), fmi2Error);
      EXPECT_TRUE(p.log.last().find(std::string(c.name) + " = ") != std::string::npos &&
                  p.log.last().find("lies outside its range") != std::string::npos)
          << p.log.dump();
      p.initialize();
      if (!c.integer) {
        EXPECT_EQ(p.get(c.name), v->start);
      }
      ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
      continue;
    }
    if (c.integer) {
      ASSERT_EQ(p.set_int(c.name, static_cast<int>(c.value)), fmi2OK);
    } else {
      ASSERT_EQ(p.set(c.name, c.value), fmi2OK);
    }
    ASSERT_EQ(p.setup(), fmi2OK);
    ASSERT_EQ(p.enter(), fmi2OK);
    // Outputs in initialisation mode: an error with the reason, nothing written.
    const fmi2ValueReference z = p.vr("z");
    double canary = 12345.0;
    EXPECT_EQ(p.lib.fmi2GetReal(p.c, &z, 1, &canary), fmi2Error);
    EXPECT_EQ(canary, 12345.0);
    EXPECT_EQ(p.exit(), fmi2Error);
    EXPECT_EQ(p.log.messages.back().status, fmi2Error);
    EXPECT_TRUE(p.log.last().find(c.message) != std::string::npos) << "expected \"" << c.message << "\" in\n"
                                                                    << p.log.dump();
    // Still in initialisation mode (the error policy): no step, no NaN
    // handed out; the parameter corrected, initialisation completes.
    EXPECT_EQ(p.step(0.0, 1e-3), fmi2Error);
    EXPECT_EQ(p.lib.fmi2GetReal(p.c, &z, 1, &canary), fmi2Error);
    EXPECT_EQ(canary, 12345.0);
    ASSERT_EQ(c.integer ? p.set_int(c.name, static_cast<int>(v->start)) : p.set(c.name, v->start), fmi2OK)
        << p.log.dump();
    ASSERT_EQ(p.exit(), fmi2OK) << p.log.dump();
    ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
  }
  EXPECT_GT(refused_when_set, 10);
  table_row("out-of-range parameter before initialisation: each of h, l, h_prime, r_b, r_Q, m_slider, m_rod, "
            "m_platform, Izz_platform, I_rod[1..3] = 0 or < 0; I_rod violating the triangle inequality; rk4_step, "
            "atol <= 0; rtol outside (0, 1); max_jacobian_condition <= 1; min_leg_measure outside [0, 0.5); "
            "solver, cvode_method, formulation out of range; rk4_step = 1e-9, 1e-10, 1e-300 s, g = 1e300 m/s2, "
            "dx0 = 1e200 m/s and other values beyond the physical ranges (" + std::to_string(std::size(cases)) +
                " cases)",
            "outside the modelDescription's min/max: fmi2SetReal/SetInteger fmi2Error \"<name> = <value> lies outside "
            "its range [min, max]\", start value kept; within it but invalid (e.g. 0 where positive is required): "
            "fmi2GetReal in initialisation mode and fmi2ExitInitializationMode: fmi2Error, \"parameter <name> = "
            "<value> must ...\"; still in initialisation mode (fmi2DoStep, fmi2GetReal: fmi2Error, nothing "
            "written)",
            "yes: the parameter corrected, fmi2ExitInitializationMode succeeds and steps work, no fmi2Reset needed");
}

struct BadStart {
  const char* what;
  std::vector<std::pair<const char*, double>> set;
  const char* status;   // pkm::status_name in the message
  const char* message;  // further text expected in the message
};

TEST(HardeningParameters, UnreachableOrSingularInitialPosesFailInitialisationAndResetRecovers) {
  const double g65 = 65.0 * kPi / 180.0;
  const BadStart cases[] = {
      {"r_Q = 0.3 m (joints beyond the rods' reach)", {{"r_Q", 0.3}}, "pose unreachable", "r_Q"},
      {"l = 0.01 m (rods too short)", {{"l", 0.01}}, "pose unreachable", "sqrt(l^2 + h_prime^2)"},
      {"h_prime = 0.2 m (offset larger than the joint's distance)", {{"h_prime", 0.2}}, "pose unreachable",
       "closer than h_prime"},
      {"r_b = 0.3 m (base too wide)", {{"r_b", 0.3}}, "pose unreachable", "r_b"},
      {"x0 = 0.03 m (outside the workspace)", {{"x0", 0.03}}, "pose unreachable", "cannot reach"},
      {"phi0 = 0.5 rad (outside the workspace)", {{"phi0", 0.5}}, "pose unreachable", "cannot reach"},
      {"x0 = 0.02313 m (rod of leg 2 within 0.3 deg of horizontal)",
       {{"x0", 0.02313}},
       "singular configuration",
       "leg 2 is at a leg singularity"},
      {"phi0 = 0.2301 rad (rods within 0.5 deg of vertical)",
       {{"phi0", 0.2301}},
       "singular configuration",
       "rod nearly vertical"},
      {"identical legs gamma[1..4] = 65 deg, centred pose (parallel singularity, cond ~ 1e16)",
       {{"gamma[2]", g65}, {"gamma[4]", g65}},
       "singular configuration",
       "exceeds max_jacobian_condition"},
  };
  for (const BadStart& c : cases) {
    SCOPED_TRACE(c.what);
    PlantFmu p;
    for (const auto& [name, value] : c.set) ASSERT_EQ(p.set(name, value), fmi2OK);
    ASSERT_EQ(p.setup(), fmi2OK);
    ASSERT_EQ(p.enter(), fmi2OK);
    EXPECT_EQ(p.exit(), fmi2Error);
    const std::string m = p.log.last();
    EXPECT_NE(m.find(c.status), std::string::npos) << p.log.dump();
    EXPECT_NE(m.find(c.message), std::string::npos) << p.log.dump();
    EXPECT_NE(m.find("x0 = "), std::string::npos) << "names the initial-state parameters\n" << p.log.dump();
    EXPECT_EQ(p.step(0.0, 1e-3), fmi2Error);
    // Still in initialisation mode: the parameters corrected, it completes.
    for (const auto& [name, value] : c.set) ASSERT_EQ(p.set(name, p.def.find(name)->start), fmi2OK);
    ASSERT_EQ(p.exit(), fmi2OK) << p.log.dump();
    ASSERT_EQ(p.step(0.0, 1e-3), fmi2OK) << p.log.dump();
    table_row(std::string("initial state: ") + c.what, std::string("fmi2ExitInitializationMode: fmi2Error, \"the "
                                                                   "initial state x0 = ... : ") +
                                                           c.status + ": " + c.message + " ...\"",
              "yes: still in initialisation mode; the parameters corrected, initialisation completes");
  }
}

TEST(HardeningParameters, InverseFmuRejectsNonFiniteInputsAndBadPoses) {
  InverseFmu inv;
  inv.initialize();
  const std::vector<double> before = inv.outputs();
  for (const char* name : {"x", "dphi", "ddz", "Fe[1]", "Me_z"}) {
    for (double bad : {kNaN, kInf, -kInf}) {
      EXPECT_EQ(inv.set(name, bad), fmi2Error);
      EXPECT_TRUE(inv.log.last().find(name) != std::string::npos) << inv.log.dump();
    }
  }
  EXPECT_TRUE(bit_identical(inv.outputs(), before));
  // A pose out of reach: fmi2Error, nothing written.
  const fmi2ValueReference F1 = inv.vr("F[1]");
  for (const char* name : {"x", "phi"}) {
    ASSERT_EQ(inv.set(name, std::string(name) == "x" ? 0.03 : 0.5), fmi2OK);
    double canary = 12345.0;
    EXPECT_EQ(inv.lib.fmi2GetReal(inv.c, &F1, 1, &canary), fmi2Error);
    EXPECT_EQ(canary, 12345.0);
    EXPECT_TRUE(inv.log.contains("unreachable")) << inv.log.dump();
    ASSERT_EQ(inv.set(name, 0.0), fmi2OK);
  }
  EXPECT_TRUE(bit_identical(inv.outputs(), before));
  table_row("inverse FMU: x, dphi, ddz, Fe[1], Me_z = NaN / +-Inf; then a pose out of reach (x = 0.03 m)",
            "fmi2SetReal: fmi2Error (named); fmi2GetReal: fmi2Error \"inverse dynamics ... failed: pose "
            "unreachable (outputs not written)\"",
            "yes: the output buffer untouched; back in reach the outputs are bit-identical");
}

INSTANTIATE_TEST_SUITE_P(CvodeAndRk4, HardeningInputs, ::testing::Values(0, 1),
                         [](const ::testing::TestParamInfo<int>& i) { return i.param == 0 ? "CVODE" : "RK4"; });

}  // namespace
