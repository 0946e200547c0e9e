// SPDX-License-Identifier: BSD-2-Clause
// The FMU binaries and archives as files: the shared libraries they need,
// the functions they export, and fmpy's validation and simulation of the
// packaged .fmu files when fmpy is available. Host programs only (ldd, nm,
// fmpy): a cross build (PKM_TEST_ON_TARGET) leaves them out; the host build
// checks the cross-built binaries' imports and exports.
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmi/fmi_functions.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"

namespace {

using namespace pkm_test;

#ifndef PKM_TEST_ON_TARGET
using pkm_test::capture;
using pkm_test::have_fmpy;

TEST(FmuBinaries, NeedOnlyTheSystemRuntime) {
  // SUNDIALS and the C++ runtime are linked statically (-static-libstdc++
  // -static-libgcc): only libc, libm and the loader remain.
  const std::set<std::string> allowed = {"linux-vdso.so.1", "libc.so.6", "libm.so.6", "libstdc++.so.6",
                                         "libgcc_s.so.1", "ld-linux-x86-64.so.2"};
  for (const char* so : {PKM_FMU_PLANT_SO, PKM_FMU_INVERSE_SO}) {
    std::vector<std::string> lines;
    std::string out;
    ASSERT_TRUE(tool_lines("ldd", so, lines, &out)) << out;
    int n = 0;
    for (const std::string& line : lines) {
      std::istringstream words(line);
      std::string lib;
      words >> lib;
      if (lib.empty()) continue;
      const std::string base = lib.substr(lib.rfind('/') + 1);
      EXPECT_TRUE(allowed.count(base)) << so << " needs " << line;
      EXPECT_EQ(line.find("not found"), std::string::npos) << line;
      ++n;
    }
    EXPECT_GT(n, 0) << out;
  }
}

TEST(FmuBinaries, ExportExactlyTheListedFmiFunctions) {
  std::set<std::string> listed;
#define PKM_TEST_NAME(name) listed.insert(#name);
  PKM_FMI2_FUNCTIONS(PKM_TEST_NAME)
  PKM_FMI3_FUNCTIONS(PKM_TEST_NAME)
#undef PKM_TEST_NAME
  for (const char* so : {PKM_FMU_PLANT_SO, PKM_FMU_INVERSE_SO}) {
    std::vector<std::string> lines;
    std::string out;
    if (!tool_lines("nm -D --defined-only", so, lines, &out)) GTEST_SKIP() << "nm not available: " << out;
    std::set<std::string> exported;
    for (const std::string& line : lines) exported.insert(line.substr(line.rfind(' ') + 1));
    EXPECT_EQ(exported, listed) << so;  // src/fmi/fmi_functions.h: 44 of FMI 2.0, 75 of FMI 3.0
    EXPECT_EQ(exported.size(), 119u);
  }
}

TEST(FmuArchives, FmpyValidatesThem) {
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  for (const char* fmu : {PKM_FMU_PLANT_FMU, PKM_FMU_INVERSE_FMU}) {
    int status = 0;
    const std::string out = capture(std::string("'") + PKM_FMU_PYTHON + "' -m fmpy.cli validate '" + fmu + "' 2>&1",
                                    &status);
    EXPECT_EQ(status, 0) << fmu << "\n" << out;
    EXPECT_NE(out.find("No problems found"), std::string::npos) << fmu << "\n" << out;
  }
}

TEST(FmuArchives, FmpySimulatesTheHomePose) {
  if (!have_fmpy()) GTEST_SKIP() << "no Python with fmpy (PKM_FMU_PYTHON)";
  const std::string script =
      "import fmpy\n"
      "F = 2.655616050\n"
      "r = fmpy.simulate_fmu('" PKM_FMU_PLANT_FMU "', stop_time=0.1, step_size=1e-3,\n"
      "    start_values={'F[1]': F, 'F[2]': F, 'F[3]': F, 'F[4]': F})\n"
      "dev = max(abs(r['x']).max(), abs(r['y']).max(), abs(r['z'] - 0.05).max(), abs(r['phi']).max())\n"
      "i = fmpy.simulate_fmu('" PKM_FMU_INVERSE_FMU "', stop_time=0.01, step_size=1e-3)\n"
      "ferr = max(abs(i['F[%d]' % k] - F).max() for k in range(1, 5))\n"
      "print('RESULT', r['time'][-1], dev, ferr)\n";
  int status = 0;
  const std::string out = pkm_test::run_python(script, &status);
  ASSERT_EQ(status, 0) << out;
  const std::size_t at = out.find("RESULT");
  ASSERT_NE(at, std::string::npos) << out;
  double t_end = 0, dev = 1, ferr = 1;
  ASSERT_EQ(std::sscanf(out.c_str() + at, "RESULT %lf %lf %lf", &t_end, &dev, &ferr), 3) << out;
  EXPECT_NEAR(t_end, 0.1, 1e-12);
  EXPECT_LE(dev, 1e-9);
  EXPECT_LE(ferr, 1e-9);
}

#endif  // PKM_TEST_ON_TARGET

}  // namespace
