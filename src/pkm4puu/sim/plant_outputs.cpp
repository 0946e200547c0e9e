// SPDX-License-Identifier: BSD-2-Clause
// The Plant's outputs at the current state: the joint coordinates, the
// machine's forces and energies, the health measures. Reading changes
// nothing but the caches (theta1's references, the actuator positions).
#include <limits>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/machine/friction.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace pkm {

Status Plant::mechanism(const InputSignal& inputs, MechanismState& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  Vec8 ydot;
  const Status s = state_derivative(model_, settings_.formulation, y_, generalized_forces(model_, F, tau, we),
                                    ydot, &out, nullptr, stops_);
  if (s != Status::Ok) return s;
  theta1_ref();  // brought up to date
  theta1_.unwrap(out.q);
  return Status::Ok;
}

Status Plant::coordinates(Vec16& q, Vec16& qd) const {
  if (!initialized_) return Status::NotInitialized;
  const Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  if (theta1_stale_) follow_theta1(q);  // the closed form theta1_ref() would evaluate again
  theta1_.unwrap(q);
  return Status::Ok;
}

Status Plant::machine_outputs(const InputSignal& inputs, MachineOutputs& out) const {
  if (!initialized_) return Status::NotInitialized;
  Vec16 q, qd;
  Status s = expand_state(model_, y_, q, qd);
  if (s != Status::Ok) return s;
  Vec4 F, tau;
  Wrench we;
  read_inputs(inputs, t_, F, we, tau);
  const Params& p = model_.p;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    out.rho[i] = q[o];
    out.rhod[i] = qd[o];
    out.stop_force[i] = stop_contact(p, i, stops_, q[o], qd[o]).force;
    out.friction_force[i] = friction_force(p, qd[o]);
  }
  s = holding_forces(model_, q, we, out.F_hold);
  if (s != Status::Ok) return s;
  out.kinetic_energy = kinetic_energy(model_, q, qd);
  out.potential_energy = potential_energy(model_, q);
  settle_energy();
  out.actuator_work = energy_.actuator_work;
  out.dissipated_energy = energy_.dissipated;
  energy_rates(p, stops_, F + model_.drive_ratio * tau, we, y_.tail<4>(), out.rho, out.rhod,
               out.actuator_power, out.dissipation_rate);
  double z[kContactIndicators];
  pkm::contact_indicators(p, out.rho, out.rhod, stops_, z);
  for (int k = 0; k < kStopIndicators; ++k) out.stop_indicators[k] = z[k];
  for (int i = 0; i < kLegs; ++i) out.clamp_indicators[i] = z[kStopIndicators + i];
  return Status::Ok;
}

double Plant::constraint_residual() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::quiet_NaN();
  return constraints(model_, q).norm();
}

double Plant::jacobian_condition() const {
  Vec16 q, qd;
  if (expand_state(model_, y_, q, qd) != Status::Ok) return std::numeric_limits<double>::infinity();
  return actuator_jacobian_condition(model_, q);
}

}  // namespace pkm
