// SPDX-License-Identifier: BSD-2-Clause
// The sliders' joint friction (docs/model.md "The machine around the
// mechanism"): viscous plus a Coulomb term regularised by tanh,
//   F_fric,i = -b rhod_i - F_c tanh(rhod_i / v_s)   on rho_i, opposing rhod_i.
#pragma once

#include <cmath>

#include "pkm4puu/model/params.hpp"

namespace pkm {

/// Regularised joint friction on rho (N, opposes rhod).
inline double friction_force(const Params& p, double rhod) {
  double F = -p.friction_viscous * rhod;
  if (p.friction_coulomb != 0.0) F -= p.friction_coulomb * std::tanh(rhod / p.friction_velocity);
  return F;
}

/// dF_fric/drhod.
inline double friction_slope(const Params& p, double rhod) {
  double s = -p.friction_viscous;
  if (p.friction_coulomb != 0.0) {
    const double th = std::tanh(rhod / p.friction_velocity);
    s -= p.friction_coulomb / p.friction_velocity * (1.0 - th * th);
  }
  return s;
}

}  // namespace pkm
