// SPDX-License-Identifier: BSD-2-Clause
// Analytic derivatives of the inverse dynamics (inverse_dynamics.hpp) with
// respect to the platform motion and the external wrench. The actuator
// forces F solve the reduced residual R(p, pd, pdd, F, we) = 0
// (reduced_dynamics_derivatives.hpp), where F enters as -J_rho^T F and the
// wrench as -we, so
//   F = J_rho^{-T} R(F = 0),   dF/dx = J_rho^{-T} dR/dx at fixed F,
//   dF/dpdd = J_rho^{-T} Mr,   dF/dwe = -J_rho^{-T}.
// The machine is included as in actuator_forces: rotor, payload, friction
// and, beyond a stop, the stop's force.
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

struct InverseDynamicsPartials {
  Vec4 F = Vec4::Zero();       // N, as actuator_forces gives them
  Mat4 dp = Mat4::Zero();      // dF/d(x, y, z, phi)
  Mat4 dpd = Mat4::Zero();     // dF/d(dx, dy, dz, dphi)
  Mat4 dpdd = Mat4::Zero();    // dF/d(ddx, ddy, ddz, ddphi)
  Mat4 dwe = Mat4::Zero();     // dF/d(Fe[1..3], Me_z)
  Mat4 J_rho = Mat4::Zero();   // d rho/dp (= d rhod/dpd)
  Mat4 drhod_dp = Mat4::Zero();  // d rhod/dp
};

/// Status::Unreachable off the workspace, ::Singular at a leg or parallel
/// singularity, ::NonFinite for a non-finite argument.
Status inverse_dynamics_derivatives(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd,
                                    const Wrench& we, InverseDynamicsPartials& out);

}  // namespace pkm
