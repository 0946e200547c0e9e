#include "model.hpp"

#include <cmath>

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
  out.total_mass = p.m_platform + kLegs * (p.m_slider + p.m_rod);
  return Status::Ok;
}

}  // namespace pkm
