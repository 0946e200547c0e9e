// SPDX-License-Identifier: BSD-2-Clause
// A leg's closed-form inverse kinematics (elbow-down, docs/model.md) for
// one leg (T = double) or the four legs as lanes (T = lanes::Pack,
// base/lanes.hpp): shared by the forward hot path (leg_lanes.cpp) and the
// reduced inverse dynamics (inverse_lanes.cpp).
#pragma once

#include "pkm4puu/base/lanes.hpp"
#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm::lane_legs {

template <class T>
struct LegInputs {
  T Bx, By, Bz;    // B_i
  T cb, sb;        // cos, sin beta_i
  T rx, ry;        // r_Qi (x, y)
  T f_rho;         // applied force on rho_i
};

// leg_inverse_kinematics per lane (with rotated_attachment): the
// derivative's legs, actuator_positions and the inverse dynamics. out_of_reach: the lanes it
// reports Unreachable for (their other members are meaningless).
template <class T>
struct LegPosition {
  T ax, ay;          // Rz(phi) r_Qi (its z is 0)
  T c1, s1, c2, s2;  // the leg's angles' cosines and sines
  T rho;
  T qy;              // q~'s y in the leg's frame (the quadrant of theta1)
  decltype(lanes::not_ge(T(), 0.0)) out_of_reach;
};

template <class T>
PKM_LANES_INLINE LegPosition<T> leg_position(const Params& p, const PlatformConfig& pc, const LegInputs<T>& in) {
  LegPosition<T> o;
  // rotated_attachment: Rz(phi) r_Qi (its z is 0).
  o.ax = pc.cphi * in.rx - pc.sphi * in.ry;
  o.ay = pc.sphi * in.rx + pc.cphi * in.ry;
  // leg_inverse_kinematics: q~ = Rz(beta_i)^T (p + attach - B_i), then the
  // elbow-down branch.
  const T vx = (pc.pose[0] + o.ax) - in.Bx;
  const T vy = (pc.pose[1] + o.ay) - in.By;
  const T qz = (pc.pose[2] + 0.0) - in.Bz;
  const T qx = in.cb * vx + in.sb * vy;
  const T qy = -in.sb * vx + in.cb * vy;
  const T r2 = qx * qx + qy * qy;
  const T A2 = r2 - p.h_prime * p.h_prime;
  const auto below = lanes::not_ge(A2, 0.0);  // also catches NaN
  const T A = lanes::sqrt(lanes::zero_where(below, A2));
  o.out_of_reach = lanes::either(below, lanes::not_le(A, p.l));
  o.c1 = (qx * A - qy * p.h_prime) / r2;
  o.s1 = (qy * A + qx * p.h_prime) / r2;
  o.c2 = A / p.l;
  const T s2sq = 1.0 - o.c2 * o.c2;
  o.s2 = -lanes::sqrt(lanes::select(lanes::gt(s2sq, 0.0), s2sq, 0.0));  // elbow-down
  o.rho = qz - p.h - p.l * o.s2;
  o.qy = qy;
  return o;
}

// The four legs' geometry as lanes (f_rho left 0).
PKM_LANES_INLINE LegInputs<lanes::Pack> lane_inputs(const Model& m) {
  using lanes::pack;
  LegInputs<lanes::Pack> in;
  in.Bx = pack(m.B[0].x(), m.B[1].x(), m.B[2].x(), m.B[3].x());
  in.By = pack(m.B[0].y(), m.B[1].y(), m.B[2].y(), m.B[3].y());
  in.Bz = pack(m.B[0].z(), m.B[1].z(), m.B[2].z(), m.B[3].z());
  in.cb = pack(m.cos_beta[0], m.cos_beta[1], m.cos_beta[2], m.cos_beta[3]);
  in.sb = pack(m.sin_beta[0], m.sin_beta[1], m.sin_beta[2], m.sin_beta[3]);
  in.rx = pack(m.r_Q[0].x(), m.r_Q[1].x(), m.r_Q[2].x(), m.r_Q[3].x());
  in.ry = pack(m.r_Q[0].y(), m.r_Q[1].y(), m.r_Q[2].y(), m.r_Q[3].y());
  in.f_rho = lanes::broadcast(0.0);
  return in;
}

}  // namespace pkm::lane_legs
