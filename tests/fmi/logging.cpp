// SPDX-License-Identifier: BSD-2-Clause
// The FMU binaries' logging through the raw FMI 2.0 functions: debug
// logging filtered by category (FMI 2.0 section 2.1.5), nothing written to
// stdout or stderr, and messages carrying format characters passed safely.
#ifndef _WIN32
#include <fcntl.h>
#include <unistd.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"

namespace {

using namespace pkm_test;

class Logging : public FmuTest {};

/// How many messages of each category the log holds.
std::map<std::string, int> per_category(const Log& log, std::size_t from = 0) {
  std::map<std::string, int> n;
  for (std::size_t k = from; k < log.messages.size(); ++k) ++n[log.messages[k].category];
  return n;
}

// FMI 2.0.4 section 2.1.5: "If loggingOn = fmi2True and nCategories > 0, then
// only debug messages according to the categories argument shall be output";
// the reason of an Error or a Fatal reaches the logger whatever the setting.
TEST_F(Logging, DebugLoggingIsFilteredByCategory) {
  PlantFmu p("plant", /*logging_on=*/false);
  p.initialize();
  ASSERT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2OK);
  EXPECT_TRUE(p.log.messages.empty()) << p.log.dump();
  const fmi2String events[] = {"logEvents"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, events), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(p.c), fmi2OK);
  ASSERT_EQ(p.log.messages.size(), 1u) << p.log.dump();
  EXPECT_EQ(p.log.messages[0].category, "logEvents");
  const fmi2String bogus[] = {"logNothing"};
  EXPECT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, bogus), fmi2Error);
  EXPECT_EQ(p.log.messages.back().category, "logStatusError");
  // Logging off, no category named: as loggingOn = false at instantiation,
  // the reasons of a status other than OK still come, events do not.
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2False, 0, nullptr), fmi2OK);
  std::size_t n = p.log.messages.size();
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(per_category(p.log, n), (std::map<std::string, int>{{"logStatusError", 1}})) << p.log.dump();
  // logStatusError switched off by name: the reason of an Error still comes.
  const fmi2String errors[] = {"logStatusError"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2False, 1, errors), fmi2OK);
  n = p.log.messages.size();
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2Error);
  EXPECT_EQ(per_category(p.log, n), (std::map<std::string, int>{{"logStatusError", 1}})) << p.log.dump();
  // Logging on, no category named: events (mode changes), but no call trace.
  PlantFmu q("plant", /*logging_on=*/true);
  q.initialize();
  EXPECT_TRUE(q.log.contains("fmi2ExitInitializationMode")) << q.log.dump();
  for (const auto& m : q.log.messages) EXPECT_NE(m.category, "logCalls") << q.log.dump();
  // logCalls, named with loggingOn = true: exactly that category, the events
  // it replaces are off: 20 steps give 20 calls, the Terminate no event.
  const fmi2String calls[] = {"logCalls"};
  ASSERT_EQ(lib.fmi2SetDebugLogging(q.c, fmi2True, 1, calls), fmi2OK);
  n = q.log.messages.size();
  for (int k = 0; k < 20; ++k) ASSERT_EQ(lib.fmi2DoStep(q.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(q.c), fmi2OK);
  EXPECT_EQ(per_category(q.log, n), (std::map<std::string, int>{{"logCalls", 20}})) << q.log.dump();
  // logEvents named after logCalls: the selection replaces, it does not add.
  ASSERT_EQ(lib.fmi2Reset(q.c), fmi2OK);
  ASSERT_EQ(lib.fmi2SetDebugLogging(q.c, fmi2True, 1, events), fmi2OK);
  n = q.log.messages.size();
  q.initialize();
  for (int k = 0; k < 20; ++k) ASSERT_EQ(lib.fmi2DoStep(q.c, k * 1e-3, 1e-3, fmi2True), fmi2OK);
  ASSERT_EQ(lib.fmi2Terminate(q.c), fmi2OK);
  // Events: entering and leaving initialisation mode, Terminate.
  EXPECT_EQ(per_category(q.log, n), (std::map<std::string, int>{{"logEvents", 3}})) << q.log.dump();
}

#ifndef _WIN32
TEST_F(Logging, NothingIsWrittenToStdoutOrStderr) {
  std::fflush(stdout);
  std::fflush(stderr);
  char path[] = "/tmp/pkm_fmi_stdout_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  const int saved_out = dup(1), saved_err = dup(2);
  dup2(fd, 1);
  dup2(fd, 2);
  {
    // With a logger and all categories, and without any logger.
    PlantFmu p("plant", /*logging_on=*/true);
    p.initialize();
    p.set("F[1]", std::nan(""));
    lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True);
    lib.fmi2DoStep(p.c, 5.0, 1e-3, fmi2True);
    const fmi2CallbackFunctions none{nullptr, nullptr, nullptr, nullptr, nullptr};
    fmi2Component c = lib.fmi2Instantiate("silent", fmi2CoSimulation, PKM_FMU_PLANT_GUID, "", &none, fmi2False,
                                          fmi2True);
    EXPECT_NE(c, nullptr);
    lib.fmi2DoStep(c, 0.0, 1e-3, fmi2True);  // an error with nobody to tell
    lib.fmi2FreeInstance(c);
    EXPECT_EQ(lib.fmi2Instantiate("silent", fmi2CoSimulation, "{wrong}", "", &none, fmi2False, fmi2True), nullptr);
    EXPECT_EQ(lib.fmi2Instantiate("silent", fmi2CoSimulation, "{wrong}", "", nullptr, fmi2False, fmi2True), nullptr);
  }
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(saved_out, 1);
  dup2(saved_err, 2);
  close(saved_out);
  close(saved_err);
  const off_t size = lseek(fd, 0, SEEK_END);
  close(fd);
  unlink(path);
  EXPECT_EQ(size, 0) << "the FMU wrote to stdout or stderr";
}
#endif  // _WIN32

TEST_F(Logging, LogMessagesWithFormatCharactersAreSafe) {
  on_stepping_instance(
      "fmi2SetDebugLogging with the category \"%s%s%n%x\", an unknown category, a NULL category",
      fmi2Error,
      "fmi2Error, \"unknown log category \\\"%s%s%n%x\\\"\" delivered with '%' escaped (the importer's printf "
      "prints it literally)",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        const fmi2String evil[1] = {"%s%s%n%x"};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, evil));
        EXPECT_TRUE(p.log.contains("\"%s%s%n%x\"")) << p.log.dump();
        const fmi2String unknown[1] = {"logNothing"};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, unknown));
        const fmi2String null_name[1] = {nullptr};
        s.push_back(lib.fmi2SetDebugLogging(p.c, fmi2True, 1, null_name));
        // A long list of known names is no misuse: accepted.
        std::vector<fmi2String> many(1000, "logEvents");
        EXPECT_EQ(lib.fmi2SetDebugLogging(p.c, fmi2True, many.size(), many.data()), fmi2OK);
        return s;
      });
}

}  // namespace
