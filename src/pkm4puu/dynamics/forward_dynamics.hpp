// SPDX-License-Identifier: BSD-2-Clause
// Forward dynamics: given (q, qd) on the constraint manifold and the
// generalised forces f, the accelerations qdd and multipliers lambda of
//   M qdd + V + G + C_q^T lambda = f,   C_q qdd + gamma = 0.
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

enum class Formulation {
  /// Eq. 12: the augmented (saddle-point) 28x28 system, solved by LU.
  Augmented = 0,
  /// Eq. 13: null-space projection with B from a QR of C_q^T (16x12):
  /// C_q^T = [Q1 Q2] [R; 0], B = Q2, so C_q B = 0 and B^T B = I.
  NullSpaceQR = 1,
  /// Eq. 13 with the null-space basis read off the leg blocks instead of a
  /// QR: B = [L_1^{-1} P_1; ...; L_4^{-1} P_4; I4] (coordinate partitioning
  /// with the platform pose as independent coordinates). Same qdd and
  /// lambda; only 3x3 and 4x4 solves. The default.
  LegPartitioned = 2,
};

const char* formulation_name(Formulation f);

/// Accelerations and multipliers. Status::Singular if the system is
/// (numerically) singular.
Status forward_dynamics(const Model& m, Formulation form, const Vec16& q, const Vec16& qd,
                        const Vec16& f, Vec16& qdd, Vec12& lambda);

}  // namespace pkm
