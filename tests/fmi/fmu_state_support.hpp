// SPDX-License-Identifier: BSD-2-Clause
// What the tests of FMU states (fmu_states_restored.cpp,
// fmu_states_refused.cpp) share: their fixture, and the runs both FMI
// versions make alike -- a drop onto the end stops with each solver and
// machine, stepped, and the first difference of two such runs.
#pragma once

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "any_version.hpp"
#include "fmu_fixture.hpp"
#include "models/models.hpp"
#include "pkm4puu/model/params.hpp"

namespace pkm_test {

/// The FmuState tests' fixture: both binaries loaded.
class FmuState : public FmuTest {};

/// The machines of the runs: the default, the stiffest end stops
/// the parameters declare, and strong viscous friction (a stiff term out of
/// contact).
struct Setting {
  const char* name;
  double value;
};
struct Machine {
  const char* name;
  std::vector<Setting> settings;
};
inline const std::vector<Machine>& machines() {
  static const std::vector<Machine> m = {
      {"default", {}},
      {"stiffest_stops", {{"stop_stiffness", pkm::kMaxStiffness}, {"stop_damping", pkm::kMaxDamping}}},
      {"viscous_friction", {{"friction_viscous", 1000.0}}},
  };
  return m;
}

constexpr int kCvode = 0, kRk4 = 1, kRos2 = 2;
inline const char* solver_name(int solver) { return solver == kCvode ? "CVODE" : solver == kRk4 ? "RK4" : "ROS2"; }

/// Initialised for a drop onto the lower end stops (F = 0: nothing holds
/// the platform; it falls from the home pose and bounces) with `solver`
/// and the machine's settings.
inline void start_drop(Any& a, int solver, const Machine& m) {
  ASSERT_NE(a.c, nullptr);
  ASSERT_EQ(a.set_int("solver", solver), fmi2OK) << a.log.dump();
  for (const Setting& s : m.settings) ASSERT_EQ(a.set(s.name, s.value), fmi2OK) << s.name << a.log.dump();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(a.set(force_name(i).c_str(), 0.0), fmi2OK);
  ASSERT_EQ(a.enter(), fmi2OK) << a.log.dump();
  ASSERT_EQ(a.exit(), fmi2OK) << a.log.dump();
}

constexpr double kH = 1e-3;  // the communication step (s)

/// Steps k0 .. k1-1 of kH from t = k kH: every Real after each, in one vector.
inline std::vector<double> steps(Any& a, int k0, int k1) {
  std::vector<double> trace;
  for (int k = k0; k < k1; ++k) {
    EXPECT_EQ(a.step(k * kH, kH), fmi2OK) << "step " << k << "\n" << a.log.dump();
    const std::vector<double> r = a.reals();
    trace.insert(trace.end(), r.begin(), r.end());
  }
  return trace;
}

/// Where two traces of steps() first differ ("" if bit-identical).
inline std::string first_difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return "the traces differ in length";
  const std::size_t n = plant().n_variables;
  std::vector<const char*> names;
  for (std::size_t k = 0; k < n; ++k)
    if (plant().variables[k].type == pkm_fmi::VarType::Real) names.push_back(plant().variables[k].name);
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(double)) == 0) continue;
    char buf[200];
    std::snprintf(buf, sizeof buf, "first difference after step %lu of the run, %s: %.17g vs %.17g",
                  static_cast<unsigned long>(i / names.size()), names[i % names.size()], a[i], b[i]);
    return buf;
  }
  return "";
}

}  // namespace pkm_test
