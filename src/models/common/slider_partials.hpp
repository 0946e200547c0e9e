// SPDX-License-Identifier: BSD-2-Clause
// The partial derivatives of a slider's outputs rho[i] and drho[i] over the
// pose p and its rates pd, as both FMUs' Jacobians give them:
// d rho = J_rho dp, d rhod = drhod_dp dp + J_rho dpd.
#pragma once

#include <cstring>

#include "pkm4puu/base/types.hpp"

namespace pkm_fmi {

/// Writes the row of `name` (rho[leg + 1] or drho[leg + 1]) over p (its
/// first 4 entries) and pd (the next 4); false, the row untouched, for any
/// other name.
template <class Row>
bool slider_partials(const char* name, int leg, const pkm::Mat4& J_rho, const pkm::Mat4& drhod_dp, Row& row) {
  if (std::strncmp(name, "rho[", 4) == 0) {
    row.template head<4>() = J_rho.row(leg);
  } else if (std::strncmp(name, "drho[", 5) == 0) {
    row.template head<4>() = drhod_dp.row(leg);
    row.template segment<4>(4) = J_rho.row(leg);
  } else {
    return false;
  }
  return true;
}

}  // namespace pkm_fmi
