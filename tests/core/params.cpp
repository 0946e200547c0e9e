// SPDX-License-Identifier: BSD-2-Clause
// Parameters: the spec's defaults in SI, validation messages that name
// the offending parameter, and the parameter table's descriptions against
// the constants they quote.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/model/model.hpp"
#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/parameters.hpp"
#include "pkm4puu/sim/solver_settings.hpp"

using namespace pkm;

TEST(Params, DefaultsAreTheSpecTablesInSI) {
  const Params p;
  EXPECT_DOUBLE_EQ(p.h, 66.34e-3);
  EXPECT_DOUBLE_EQ(p.l, 80e-3);
  EXPECT_DOUBLE_EQ(p.h_prime, 75e-3);
  EXPECT_DOUBLE_EQ(p.r_b, 92.73e-3);
  EXPECT_DOUBLE_EQ(p.r_Q, 75e-3);
  EXPECT_DOUBLE_EQ(p.m_slider, 93.31e-3);
  EXPECT_DOUBLE_EQ(p.m_rod, 63.71e-3);
  EXPECT_DOUBLE_EQ(p.m_platform, 454.74e-3);
  EXPECT_DOUBLE_EQ(p.Izz_platform, 2874.21 * 1e-6);  // kg mm^2 -> kg m^2
  EXPECT_DOUBLE_EQ(p.I_rod[1], 49.86e-6);
  EXPECT_DOUBLE_EQ(p.gamma[0], 65.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(p.gamma[1], -65.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(p.beta[3], 1.5 * kPi);
  EXPECT_TRUE(validate(p).empty());
}

TEST(Params, PlacementFollowsTheSpec) {
  Model m;
  ASSERT_EQ(make_model(Params{}, m), Status::Ok);
  EXPECT_NEAR(m.B[1].x(), 0.0, 1e-17);
  EXPECT_NEAR(m.B[1].y(), 0.09273, 1e-17);
  // r_Q1 at angle beta_1 + gamma_1 = 65 deg.
  EXPECT_NEAR(std::atan2(m.r_Q[0].y(), m.r_Q[0].x()), 65.0 * kPi / 180.0, 1e-15);
  EXPECT_NEAR(m.r_Q[3].norm(), 0.075, 1e-17);
}

TEST(Params, ValidationNamesTheOffendingParameter) {
  struct Case { const char* name; void (*spoil)(Params&); };
  const Case cases[] = {
      {"parameter l ", [](Params& p) { p.l = -0.08; }},
      {"parameter h_prime ", [](Params& p) { p.h_prime = 0.0; }},
      {"parameter r_Q ", [](Params& p) { p.r_Q = NAN; }},
      {"parameter m_rod ", [](Params& p) { p.m_rod = -1; }},
      {"parameter I_rod[2] ", [](Params& p) { p.I_rod[1] = INFINITY; }},
      {"parameter Izz_platform ", [](Params& p) { p.Izz_platform = 0; }},
      {"parameter gamma[3] ", [](Params& p) { p.gamma[2] = NAN; }},
      {"parameter g ", [](Params& p) { p.g = INFINITY; }},
      // The machine around the mechanism (docs/model.md).
      {"parameter screw_lead ", [](Params& p) { p.screw_lead = 0.0; }},
      {"parameter rotor_inertia ", [](Params& p) { p.rotor_inertia = -1e-6; }},
      {"parameter friction_viscous ", [](Params& p) { p.friction_viscous = NAN; }},
      {"parameter friction_coulomb ", [](Params& p) { p.friction_coulomb = -0.1; }},
      {"parameter friction_velocity ", [](Params& p) { p.friction_velocity = 0.0; }},
      {"parameter rho_max ", [](Params& p) { p.rho_max = -0.01; }},
      {"parameter rho_min ", [](Params& p) { p.rho_min = INFINITY; }},
      {"parameter stop_stiffness ", [](Params& p) { p.stop_stiffness = -1.0; }},
      {"parameter stop_damping ", [](Params& p) { p.stop_damping = -1.0; }},
      {"parameter payload_mass ", [](Params& p) { p.payload_mass = -0.1; }},
      {"parameter payload_com[2] ", [](Params& p) { p.payload_com[1] = NAN; }},
      {"parameter payload_Izz ", [](Params& p) { p.payload_Izz = -1.0; }},
  };
  for (const Case& c : cases) {
    Params p;
    c.spoil(p);
    Model m;
    std::string why;
    EXPECT_EQ(make_model(p, m, &why), Status::InvalidParameter) << c.name;
    EXPECT_NE(why.find(c.name), std::string::npos) << "message: " << why;
  }
}

TEST(Params, ZeroGravityIsAllowed) {
  Params p;
  p.g = 0.0;
  EXPECT_TRUE(validate(p).empty());
}

namespace {

/// How the descriptions write a number: "1eN" for a power of ten, else %g.
std::string as_written(double x) {
  const long n = std::lround(std::log10(std::fabs(x)));
  if (x > 0.0 && std::pow(10.0, static_cast<double>(n)) == x) return "1e" + std::to_string(n);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

std::string description_of(const char* name) {
  const Parameter* row = find_parameter(name);
  return row ? row->description : "";
}

}  // namespace

// The descriptions that quote a limit of the code say the constant's value:
// Adams gives way to BDF above kAdamsMaxDampingRate (cvode_method_for), and
// a fixed-step advance takes at most kMaxInnerStepsPerCall inner steps.
TEST(ParameterTable, DescriptionsQuoteTheConstantsOfTheCode) {
  const std::string method = description_of("cvode_method");
  EXPECT_NE(method.find("exceeds " + as_written(kAdamsMaxDampingRate) + " 1/s"), std::string::npos) << method;
  const std::string budget = description_of("work_budget");
  EXPECT_NE(budget.find("at most " + as_written(kMaxInnerStepsPerCall) + " per step"), std::string::npos) << budget;
}

// A row's range is its lo and hi (the model descriptions' min and max): the
// tolerances' descriptions do not spell it a second time.
TEST(ParameterTable, TheTolerancesDescriptionsLeaveTheirRangeToMinAndMax) {
  for (const char* name : {"rtol", "atol"}) {
    const Parameter* row = find_parameter(name);
    ASSERT_NE(row, nullptr) << name;
    const std::string text = row->description;
    for (double bound : {row->lo, row->hi})
      EXPECT_EQ(text.find(as_written(bound)), std::string::npos) << name << " quotes " << as_written(bound) << ": " << text;
  }
}
