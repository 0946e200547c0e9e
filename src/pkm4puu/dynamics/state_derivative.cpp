// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/state_derivative.hpp"

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/dynamics/reduced_dynamics.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"

namespace pkm {

Status expand_state(const Model& m, const Vec8& y, Vec16& q, Vec16& qd) {
  if (!y.allFinite()) return Status::NonFinite;
  const Pose pose = y.head<4>();
  Status s = closed_form_position(m, pose, q);
  if (s != Status::Ok) return s;
  ReducedDynamics rd;
  const PlatformConfig pc = platform_config(pose);
  for (int i = 0; i < kLegs; ++i) {
    s = rd.prepare_leg_kinematics(m, i, leg_config_from_q(q, i), pc);
    if (s != Status::Ok) return s;
    qd.segment<3>(leg_offset(i)) = rd.leg_velocity(i, y.tail<4>());
  }
  qd.segment<4>(kPlatform) = y.tail<4>();
  return Status::Ok;
}

Vec16 with_passive_forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& f, unsigned stops) {
  Vec16 out = f;
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    out[o] += passive_joint_force(m.p, i, stops, q[o], qd[o]);
  }
  return out;
}

Status reduced_terms(const Model& m, const Vec8& y, const Vec16& f, unsigned stops, ReducedDynamics& rd,
                     JointMotion* joints) {
  // Hot path: no angles, no trigonometry but phi's (the leg's cos/sin
  // come algebraically from the closed-form inverse kinematics).
  const Pose pose = y.head<4>();
  const Pose pd = y.tail<4>();
  const PlatformConfig pc = platform_config(pose);
  for (int i = 0; i < kLegs; ++i) {
    LegConfig c;
    Status s = leg_inverse_kinematics(m, i, pc, c);
    if (s != Status::Ok) return s;
    s = rd.prepare_leg(m, i, c, pc);
    if (s != Status::Ok) return s;
    const Vec3 qd_leg = rd.leg_velocity(i, pd);
    rd.add_leg(m, i, qd_leg, pd[3], f[leg_offset(i)] + passive_joint_force(m.p, i, stops, c.rho, qd_leg[0]));
    if (joints) {
      joints->rho[i] = c.rho;
      joints->rhod[i] = qd_leg[0];
    }
  }
  return Status::Ok;
}

Status state_derivative(const Model& m, Formulation form, const Vec8& y, const Vec16& f, Vec8& ydot,
                        MechanismState* full, JointMotion* joints, unsigned stops) {
  if (!y.allFinite() || !f.allFinite()) return Status::NonFinite;
  ydot.head<4>() = y.tail<4>();
  if (form == Formulation::LegPartitioned && full == nullptr) {
    // The integrators' hot path: the reduced system without the legs' terms.
    Pose pdd;
    const Status s = ReducedDynamics::platform_derivative(m, platform_config(y.head<4>()), y.tail<4>(), f, stops,
                                                          joints ? &joints->rho : nullptr,
                                                          joints ? &joints->rhod : nullptr, pdd);
    if (s == Status::Ok) ydot.tail<4>() = pdd;
    return s;
  }
  MechanismState local;
  MechanismState& st = full ? *full : local;
  Status s = expand_state(m, y, st.q, st.qd);
  if (s != Status::Ok) return s;
  s = forward_dynamics(m, form, st.q, st.qd, with_passive_forces(m, st.q, st.qd, f, stops), st.qdd, st.lambda);
  if (s != Status::Ok) return s;
  if (joints) {
    for (int i = 0; i < kLegs; ++i) {
      joints->rho[i] = st.q[leg_offset(i)];
      joints->rhod[i] = st.qd[leg_offset(i)];
    }
  }
  ydot.tail<4>() = st.qdd.segment<4>(kPlatform);
  return Status::Ok;
}

}  // namespace pkm
