// SPDX-License-Identifier: BSD-2-Clause
// The immutable model: validated parameters plus the leg placement derived
// from them once (Pinocchio's "model" half; per-call workspaces live with
// the functions that need them).
#pragma once

#include <array>
#include <string>

#include "pkm4puu/model/params.hpp"
#include "pkm4puu/base/status.hpp"
#include "pkm4puu/base/types.hpp"

namespace pkm {

struct Model {
  Params p;
  // Leg i's base frame 0_i: origin B_i, orientation Rz(beta_i) (spec "Leg placement").
  std::array<Vec3, kLegs> B;
  std::array<double, kLegs> cos_beta, sin_beta;
  // Platform attachment point of leg i in the platform frame, r_Qi.
  std::array<Vec3, kLegs> r_Q;
  // Total mass carried by gravity (platform, sliders, rods, payload), kg.
  double total_mass = 0;
  // Derived machine quantities (params.hpp, "The machine around the mechanism").
  double drive_ratio = 0;     // 2 pi / screw_lead: force on rho per motor torque, 1/m
  double reflected_mass = 0;  // rotor_inertia (2 pi / screw_lead)^2, kg, on each rho's diagonal
  // The platform with its payload as one rigid body, about P:
  double platform_mass = 0;   // m_platform + payload_mass, kg
  double platform_Izz = 0;    // Izz_platform + payload_Izz + payload_mass |payload_com|^2, kg*m^2
  double payload_mx = 0, payload_my = 0;  // payload_mass * payload_com (platform frame), kg*m
  // The processor runs AVX (asked by make_model): the lane kernels (state
  // derivative, its Jacobians, inverse dynamics, regressor) then run their
  // AVX copies (lanes::resolve in base/lanes.hpp; the same bits).
  bool avx = false;
};

/// Validates `p` and derives the placement. On failure returns
/// Status::InvalidParameter and, if `error` is given, a message naming the
/// offending parameter.
Status make_model(const Params& p, Model& out, std::string* error = nullptr);

/// Rz(beta_i) * v, and its transpose applied to v.
inline Vec3 rotate_to_base(const Model& m, int leg, const Vec3& v) {
  const double c = m.cos_beta[leg], s = m.sin_beta[leg];
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()};
}
inline Vec3 rotate_to_leg(const Model& m, int leg, const Vec3& v) {
  const double c = m.cos_beta[leg], s = m.sin_beta[leg];
  return {c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z()};
}

}  // namespace pkm
