// SPDX-License-Identifier: BSD-2-Clause
// What the tests of the C API (tests/capi) share: a model handle with its
// last error, the home pose, and pkm.h's structs and plant inputs made ready
// for a call.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/pkm.h"

namespace pkm_test {

// A model of the default parameters (pkm_create), destroyed with the handle.
struct Handle {
  pkm_model* m = nullptr;
  Handle() { EXPECT_EQ(pkm_create(&m), PKM_OK); }
  ~Handle() { pkm_destroy(m); }
  std::string error() const { return pkm_last_error(m); }
};

// The home pose (x, y, z, phi) and a zero rate or acceleration.
const double kHome[4] = {0.0, 0.0, 0.05, 0.0};
const double kZero[4] = {0.0, 0.0, 0.0, 0.0};
constexpr double kPi = 3.14159265358979323846;

inline bool contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }

// A pkm.h struct zeroed with its size set (C: `pkm_outputs o = {.size = sizeof(pkm_outputs)};`).
template <class T>
T sized() {
  T v{};
  v.size = sizeof(T);
  return v;
}

// u[PKM_PLANT_INPUTS] with the forces F and the rest zero.
struct Inputs {
  double u[PKM_PLANT_INPUTS] = {};
  explicit Inputs(const double F[4], const double tau[4] = nullptr) {
    for (int i = 0; i < 4; ++i) {
      u[i] = F[i];
      u[8 + i] = tau ? tau[i] : 0.0;
    }
  }
};

}  // namespace pkm_test
