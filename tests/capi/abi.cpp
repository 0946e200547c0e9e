// SPDX-License-Identifier: BSD-2-Clause
// What a program built against pkm.h relies on: one version in CMake's
// project(), the header and the library; the ABI version; and the growable
// structs, of which the library writes what their size field admits.
#include <cstddef>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "capi_support.hpp"
#include "pkm4puu/pkm.h"

using namespace pkm_test;

// One version: CMake's project() (PKM_PROJECT_VERSION, set by
// tests/CMakeLists.txt), the header's macros and the library's answer; the
// ABI version is the header's and the library's.
TEST(CApi, VersionIsTheProjectVersionInHeaderAndLibrary) {
  const std::string numbers = std::to_string(PKM_VERSION_MAJOR) + "." + std::to_string(PKM_VERSION_MINOR) + "." +
                              std::to_string(PKM_VERSION_PATCH);
  EXPECT_EQ(numbers, PKM_PROJECT_VERSION);
  EXPECT_STREQ(PKM_VERSION_STRING, PKM_PROJECT_VERSION);
  EXPECT_STREQ(pkm_version(), PKM_PROJECT_VERSION);
  EXPECT_EQ(pkm_abi_version(), PKM_ABI_VERSION);
}

// A caller built against a later pkm.h passes a larger struct: the library
// writes the fields it knows and leaves the rest; one whose size is smaller
// than the first version's struct is refused, nothing written.
TEST(CApi, StructsCarryTheirSizeAndOnlyThatMuchIsWritten) {
  struct Later {
    pkm_outputs known;
    double added;  // a field this library does not know
  } later;
  std::memset(&later, 0, sizeof later);
  later.known.size = sizeof later;
  later.added = 1234.5;
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &later.known), PKM_OK);
  EXPECT_EQ(later.known.size, sizeof later);
  EXPECT_EQ(later.known.pose[2], 0.05);
  EXPECT_EQ(later.added, 1234.5);
  pkm_outputs small;
  std::memset(&small, 0x7f, sizeof small);
  small.size = offsetof(pkm_outputs, stop_indicators);
  const pkm_outputs before = small;
  EXPECT_EQ(pkm_get_outputs(h.m, nullptr, &small), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(h.error(), "pkm_outputs.size")) << h.error();
  EXPECT_EQ(std::memcmp(&small, &before, sizeof small), 0);
}
