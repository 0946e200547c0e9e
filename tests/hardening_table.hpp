// SPDX-License-Identifier: BSD-2-Clause
// Records one row of the hardening table (bad input or FMI misuse tried,
// what the FMU answered, whether the state was kept) and prints it as a
// Markdown table row prefixed "| " so that `ctest -V -R Hardening` or the
// test binary itself shows the whole table.
#pragma once

#include <cstdio>
#include <mutex>
#include <string>

namespace pkm_test {

inline void table_row(const std::string& tried, const std::string& answer, const std::string& kept) {
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  std::printf("| %s | %s | %s |\n", tried.c_str(), answer.c_str(), kept.c_str());
  std::fflush(stdout);
}

}  // namespace pkm_test
