// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/model/model.hpp"

#include <cmath>

#include "pkm4puu/base/lanes.hpp"

namespace pkm {

Status make_model(const Params& p, Model& out, std::string* error) {
  std::string why = validate(p);
  if (!why.empty()) {
    if (error) *error = why;
    return Status::InvalidParameter;
  }
  out.p = p;
  for (int i = 0; i < kLegs; ++i) {
    out.cos_beta[i] = std::cos(p.beta[i]);
    out.sin_beta[i] = std::sin(p.beta[i]);
    out.B[i] = Vec3(p.r_b * out.cos_beta[i], p.r_b * out.sin_beta[i], 0.0);
    const double a = p.beta[i] + p.gamma[i];
    out.r_Q[i] = Vec3(p.r_Q * std::cos(a), p.r_Q * std::sin(a), 0.0);
  }
  out.total_mass = p.m_platform + p.payload_mass + kLegs * (p.m_slider + p.m_rod);
  out.drive_ratio = 2.0 * kPi / p.screw_lead;
  out.reflected_mass = p.rotor_inertia * out.drive_ratio * out.drive_ratio;
  out.platform_mass = p.m_platform + p.payload_mass;
  const double c2 = p.payload_com[0] * p.payload_com[0] + p.payload_com[1] * p.payload_com[1];
  out.platform_Izz = p.Izz_platform + p.payload_Izz + p.payload_mass * c2;
  out.payload_mx = p.payload_mass * p.payload_com[0];
  out.payload_my = p.payload_mass * p.payload_com[1];
  out.avx = lanes::cpu_runs_avx();
  return Status::Ok;
}

}  // namespace pkm
