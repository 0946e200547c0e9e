// SPDX-License-Identifier: BSD-2-Clause
// What the tests of the FMU binaries share beyond fmu_loader.hpp: the
// fixture that checks both binaries loaded (and the state-machine tests' on
// it), two ways of driving the plant's inputs, and the check of a misuse on
// a stepping instance (the answer the error policy prescribes, a logged
// reason, every variable and the next step unchanged), and serialised FMU
// states, read and forged.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_loader.hpp"
#include "fmi/fnv1a.hpp"
#include "hardening_table.hpp"

namespace pkm_test {

/// Written into output buffers before a call that must not touch them.
constexpr double kCanary = -7.77e77;

/// Every test of the FMU binaries starts with both of them loaded.
class FmuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(plant_library().missing.empty()) << "PKM4PUU: " << plant_library().missing;
    ASSERT_TRUE(inverse_library().missing.empty()) << "PKM4PUU_Inverse: " << inverse_library().missing;
  }
  FmuLibrary& lib = plant_library();
};

/// The StateMachine tests' fixture (state_machine.cpp, bad_arguments.cpp).
class StateMachine : public FmuTest {};

/// Inputs that move the platform around: forces near the static ones plus
/// a slow variation, and their derivatives for interpolation.
inline void drive_with_derivatives(FmuInstance& p, double t) {
  for (int i = 1; i <= 4; ++i) {
    const std::string F = force_name(i);
    const double w = 2.0 * kPi * (1.0 + 0.3 * i);
    ASSERT_EQ(p.set(F, kStaticForce + 0.02 * std::sin(w * t)), fmi2OK);
    ASSERT_EQ(p.set_derivative(F, 0.02 * w * std::cos(w * t)), fmi2OK);
  }
  ASSERT_EQ(p.set("Me_z", 1e-3 * std::cos(3.0 * t)), fmi2OK);
}

/// n steps of h from t, driving the inputs; the outputs after each step.
inline std::vector<double> run_steps(FmuInstance& p, FmuLibrary& lib, double& t, int n, double h) {
  std::vector<double> trace;
  for (int k = 0; k < n; ++k) {
    drive_with_derivatives(p, t);
    EXPECT_EQ(lib.fmi2DoStep(p.c, t, h, fmi2True), fmi2OK) << p.log.dump();
    t += h;
    const std::vector<double> o = p.outputs();
    trace.insert(trace.end(), o.begin(), o.end());
  }
  return trace;
}

/// Forces near the static ones, no derivatives.
inline void drive_forces(FmuInstance& p, double t) {
  for (int i = 1; i <= 4; ++i)
    ASSERT_EQ(p.set(force_name(i), kStaticForce + 0.01 * std::sin(2.0 * kPi * (1.0 + 0.5 * i) * t)), fmi2OK);
}

/// Initialised and stepped `steps` times (1 ms), inputs set for the next step.
inline void prepare(PlantFmu& p, double& t, int steps = 5) {
  p.initialize();
  t = 0.0;
  for (int k = 0; k < steps; ++k) {
    drive_forces(p, t);
    ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
    t += 1e-3;
  }
  drive_forces(p, t);
}

/// RK4 at the smallest rk4_step its range allows (1e-6 s), initialised: a
/// 50 ms step takes 5e4 RK4 steps, about 0.1 s.
inline void slow_rk4(PlantFmu& p) {
  ASSERT_EQ(p.set_int("solver", 1), fmi2OK);
  ASSERT_EQ(p.set("rk4_step", 1e-6), fmi2OK);
  p.initialize();
}

/// A misuse on a stepping instance: `misuse` returns the statuses it got;
/// all must equal `expected`; then every variable must be as before and the
/// next step bit-identical to an untouched twin's.
inline void on_stepping_instance(const std::string& tried, fmi2Status expected, const std::string& answer,
                                 const std::function<std::vector<fmi2Status>(PlantFmu&, double)>& misuse,
                                 bool expect_message = true) {
  SCOPED_TRACE(tried);
  PlantFmu p("misused"), twin("twin");
  double t = 0.0, t2 = 0.0;
  prepare(p, t);
  prepare(twin, t2);
  const std::vector<double> before = p.all_reals();
  const std::size_t logged = p.log.messages.size();
  for (fmi2Status s : misuse(p, t)) EXPECT_EQ(s, expected) << p.log.dump();
  if (expect_message && expected != fmi2OK) {
    EXPECT_GT(p.log.messages.size(), logged) << "every fmi2Error comes with a logged reason";
    if (p.log.messages.size() > logged) {
      EXPECT_EQ(p.log.messages.back().status, expected) << p.log.dump();
    }
  }
  fmi2Status get_status = fmi2Error;
  EXPECT_TRUE(bit_identical(p.all_reals(&get_status), before)) << "the misuse changed a variable";
  EXPECT_EQ(get_status, fmi2OK);
  EXPECT_EQ(p.last_successful_time(), t);
  ASSERT_EQ(p.step(t, 1e-3), fmi2OK) << p.log.dump();
  ASSERT_EQ(twin.step(t2, 1e-3), fmi2OK);
  EXPECT_TRUE(bit_identical(p.outputs(), twin.outputs())) << "the next step differs from the twin's";
  table_row(tried, answer, "yes: every variable bit-identical, the next step bit-identical to an untouched twin");
}

/// The instance's current state, serialized.
inline std::vector<fmi2Byte> serialized_state(FmuInstance& p) {
  fmi2FMUstate st = nullptr;
  std::size_t size = 0;
  EXPECT_EQ(p.lib.fmi2GetFMUstate(p.c, &st), fmi2OK);
  EXPECT_EQ(p.lib.fmi2SerializedFMUstateSize(p.c, st, &size), fmi2OK);
  std::vector<fmi2Byte> bytes(size);
  EXPECT_EQ(p.lib.fmi2SerializeFMUstate(p.c, st, bytes.data(), size), fmi2OK);
  EXPECT_EQ(p.lib.fmi2FreeFMUstate(p.c, &st), fmi2OK);
  return bytes;
}

/// A serialized state with the n bytes at `at` replaced by those at `p` and
/// the checksum recomputed (fnv1a.hpp): a forgery that passes the header
/// checks. Byte: fmi2Byte or unsigned char.
template <class Byte>
std::vector<Byte> forge_bytes(std::vector<Byte> b, std::size_t at, const void* p, std::size_t n) {
  std::memcpy(b.data() + at, p, n);
  const std::uint64_t h = pkm_fmi::fnv1a(reinterpret_cast<const unsigned char*>(b.data()), b.size() - 8);
  for (int k = 0; k < 8; ++k) b[b.size() - 8 + k] = static_cast<Byte>((h >> (8 * k)) & 0xff);  // little-endian
  return b;
}

/// forge_bytes of a value: a double, or the low 4 bytes of an integer when
/// `u32` (little-endian, as the format and every platform of the FMUs).
template <class Byte>
std::vector<Byte> forge(std::vector<Byte> b, std::size_t at, double value, bool u32 = false) {
  std::uint64_t bits = static_cast<std::uint64_t>(value);
  if (!u32) std::memcpy(&bits, &value, 8);
  unsigned char le[8];
  for (int k = 0; k < 8; ++k) le[k] = static_cast<unsigned char>((bits >> (8 * k)) & 0xff);
  return forge_bytes(std::move(b), at, le, u32 ? 4 : 8);
}

}  // namespace pkm_test
