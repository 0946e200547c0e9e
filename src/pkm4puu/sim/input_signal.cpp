// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/input_signal.hpp"

namespace pkm {
namespace {

void eval_linear(void* user, double t, Vec4& F, Wrench& we) {
  const auto* in = static_cast<const LinearInputs*>(user);
  const double dt = t - in->t0;
  F = in->F0 + in->dF * dt;
  we = in->we0 + in->dwe * dt;
}

void eval_linear_tau(void* user, double t, Vec4& tau) {
  const auto* in = static_cast<const LinearInputs*>(user);
  tau = in->tau0 + in->dtau * (t - in->t0);
}

}  // namespace

InputSignal LinearInputs::signal() { return {&eval_linear, this, &eval_linear_tau}; }

void read_inputs(const InputSignal& in, double t, Vec4& F, Wrench& we, Vec4& tau) {
  if (in.eval) {
    in.eval(in.user, t, F, we);
  } else {
    F.setZero();
    we.setZero();
  }
  if (in.eval_tau) {
    in.eval_tau(in.user, t, tau);
  } else {
    tau.setZero();
  }
}

}  // namespace pkm
