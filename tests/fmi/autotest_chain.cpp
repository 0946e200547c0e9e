// SPDX-License-Identifier: BSD-2-Clause
// The paper's auto-test (docs/model.md "The paper's two tests") through both FMU binaries,
// as python_checks/fmu_autotest.py runs it with the midpoint input: the
// inverse FMU turns the prescribed motion p(t) (pkm::RestToRest) into F1..F4
// at each 1-ms step's midpoint, and the plant FMU, driven open loop by them
// from rest at P0, must follow p(t) to the same bounds (5e-8 m, 5e-8 rad)
// with CVODE and with RK4.
//
// Built for every platform (cmake/Platforms.cmake runs it under wine and
// qemu-user), it also compares platforms: with PKM_TRACE_OUT set it writes
// the plant's pose after every step to PKM_TRACE_OUT/autotest_chain_<solver>.txt
// (hex floats, exact); with PKM_TRACE_REFERENCE set it reads the file of the
// same name there (the linux64 run's) and compares every pose coordinate,
// relative to that coordinate's largest magnitude over the run:
//  - RK4 (fixed steps, the same operations everywhere): to 1e-12; what
//    differs is only the math library's last bit (sin, cos, atan2: glibc on
//    Linux, mingw-w64's x87-based ones on Windows). Measured: 1.2e-15 under
//    wine, bit-identical under qemu (aarch64 built without FMA).
//  - CVODE: to its own tolerance rtol. Its discrete decisions (step size and
//    order, nonlinear iterations) react to those last bits; Windows takes a
//    different, equally valid step sequence in the last 45 ms of the motion
//    and differs there by 1.3e-12 (1e-15 before). Bit-identical on aarch64.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmu_loader.hpp"
#include "apps/trajectory.hpp"

namespace {

using pkm_test::InverseFmu;
using pkm_test::PlantFmu;

constexpr double kH = 1e-3;           // s, the communication step
constexpr int kSteps = 2000;          // the 2-s motion
constexpr double kTolPos = 5e-8;      // m   (python_checks/fmu_autotest.py TOL_POS)
constexpr double kTolPhi = 5e-8;      // rad (python_checks/fmu_autotest.py TOL_PHI)
constexpr double kPlatformRtolRk4 = 1e-12;  // the cross-built binaries against linux64
const char* const kPose[4] = {"x", "y", "z", "phi"};

struct Solver {
  const char* name;
  int solver;
};

/// How closely another platform must reproduce the linux64 trace (see the top).
double platform_rtol(const Solver& s) {
  return s.solver == 1 ? kPlatformRtolRk4 : pkm_fmi::pkm4puu_definition().find("rtol")->start;
}

/// The plant's pose after each step (kSteps rows of x, y, z, phi) and the
/// largest deviations from p(t).
struct Trace {
  std::vector<double> pose;
  double max_pos = 0.0, max_phi = 0.0;
};

Trace run_chain(int solver) {
  Trace out;
  InverseFmu inv;
  PlantFmu plant;
  EXPECT_NE(inv.c, nullptr);
  EXPECT_NE(plant.c, nullptr);
  if (!inv.c || !plant.c) return out;
  EXPECT_EQ(plant.set_int("solver", solver), fmi2OK) << plant.log.dump();
  inv.initialize();
  plant.initialize();
  const char* motion[12] = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"};
  const pkm::RestToRest path;
  for (int k = 0; k < kSteps; ++k) {
    const double t = k * kH;
    pkm::Pose p, pd, pdd;
    path.eval(t + 0.5 * kH, p, pd, pdd);
    for (int j = 0; j < 4; ++j) {
      EXPECT_EQ(inv.set(motion[j], p[j]), fmi2OK);
      EXPECT_EQ(inv.set(motion[4 + j], pd[j]), fmi2OK);
      EXPECT_EQ(inv.set(motion[8 + j], pdd[j]), fmi2OK);
    }
    for (int i = 1; i <= 4; ++i)
      EXPECT_EQ(plant.set(pkm_test::force_name(i), inv.get(pkm_test::force_name(i))), fmi2OK);
    const fmi2Status s = plant.step(t, kH);
    EXPECT_EQ(s, fmi2OK) << "step " << k << "\n" << plant.log.dump();
    if (s != fmi2OK) return out;
    path.eval(t + kH, p, pd, pdd);
    double e2 = 0.0;
    for (int j = 0; j < 4; ++j) {
      const double v = plant.get(kPose[j]);
      out.pose.push_back(v);
      if (j < 3) e2 += (v - p[j]) * (v - p[j]);
    }
    out.max_pos = std::max(out.max_pos, std::sqrt(e2));
    out.max_phi = std::max(out.max_phi, std::fabs(out.pose.back() - p[3]));
  }
  return out;
}

std::string trace_file(const char* dir, const Solver& s) {
  return pkm_test::native_path(std::string(dir) + "/autotest_chain_" + s.name + ".txt");
}

void write_trace(const std::string& path, const Trace& t) {
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  for (std::size_t i = 0; i < t.pose.size(); i += 4)
    std::fprintf(f, "%a %a %a %a\n", t.pose[i], t.pose[i + 1], t.pose[i + 2], t.pose[i + 3]);
  std::fclose(f);
}

std::vector<double> read_trace(const std::string& path) {
  std::vector<double> v;
  FILE* f = std::fopen(path.c_str(), "r");
  if (!f) return v;
  double x = 0.0;
  while (std::fscanf(f, "%la", &x) == 1) v.push_back(x);
  std::fclose(f);
  return v;
}

class AutoTestChain : public ::testing::TestWithParam<Solver> {};

TEST_P(AutoTestChain, PlantFollowsThePrescribedMotion) {
  ASSERT_TRUE(pkm_test::plant_library().missing.empty()) << pkm_test::plant_library().missing;
  ASSERT_TRUE(pkm_test::inverse_library().missing.empty()) << pkm_test::inverse_library().missing;
  const Solver s = GetParam();
  const Trace t = run_chain(s.solver);
  ASSERT_EQ(t.pose.size(), 4u * kSteps);
  std::printf("  %s: max position error %.3e m, max phi error %.3e rad\n", s.name, t.max_pos, t.max_phi);
  EXPECT_LE(t.max_pos, kTolPos);
  EXPECT_LE(t.max_phi, kTolPhi);

  if (const char* dir = std::getenv("PKM_TRACE_OUT")) write_trace(trace_file(dir, s), t);
  if (const char* dir = std::getenv("PKM_TRACE_REFERENCE")) {
    const std::vector<double> ref = read_trace(trace_file(dir, s));
    ASSERT_EQ(ref.size(), t.pose.size()) << "reference trace " << trace_file(dir, s);
    int identical = 0;
    for (int j = 0; j < 4; ++j) {
      double scale = 0.0, diff = 0.0;
      for (std::size_t i = j; i < ref.size(); i += 4) {
        scale = std::max(scale, std::fabs(ref[i]));
        diff = std::max(diff, std::fabs(t.pose[i] - ref[i]));
        identical += t.pose[i] == ref[i];
      }
      std::printf("  %s %-3s: max |difference| / max |reference| = %.2e (bound %.0e)\n", s.name, kPose[j],
                  diff / scale, platform_rtol(s));
      EXPECT_LE(diff, platform_rtol(s) * scale) << kPose[j];
    }
    std::printf("  %s: %d of %zu values bit-identical to the reference\n", s.name, identical, ref.size());
  }
}

INSTANTIATE_TEST_SUITE_P(Solvers, AutoTestChain, ::testing::Values(Solver{"CVODE", 0}, Solver{"RK4", 1}),
                         [](const ::testing::TestParamInfo<Solver>& i) { return std::string(i.param.name); });

}  // namespace
