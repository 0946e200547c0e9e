// SPDX-License-Identifier: BSD-2-Clause
// The plant's inputs over an interval, as functions of time.
#pragma once

#include "pkm4puu/base/types.hpp"

namespace pkm {

/// Actuator forces F (N) and the external platform wrench (N, N*m) at time
/// t; optionally the motor torques tau (N*m, zero when eval_tau is null),
/// called with the same user pointer.
struct InputSignal {
  void (*eval)(void* user, double t, Vec4& F, Wrench& we) = nullptr;
  void* user = nullptr;
  void (*eval_tau)(void* user, double t, Vec4& tau) = nullptr;
};

/// Inputs held constant, or varying linearly: F(t) = F0 + dF (t - t0).
struct LinearInputs {
  double t0 = 0;
  Vec4 F0 = Vec4::Zero(), dF = Vec4::Zero();
  Wrench we0 = Wrench::Zero(), dwe = Wrench::Zero();
  Vec4 tau0 = Vec4::Zero(), dtau = Vec4::Zero();
  InputSignal signal();
};

/// F, we and tau at t (zero where the signal has no function for them).
void read_inputs(const InputSignal& in, double t, Vec4& F, Wrench& we, Vec4& tau);

}  // namespace pkm
