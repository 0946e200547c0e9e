// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"

#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"

namespace pkm {

Status inverse_dynamics_derivatives(const Model& m, const Pose& pose, const Pose& pd, const Pose& pdd,
                                    const Wrench& we, InverseDynamicsPartials& out) {
  if (!pose.allFinite() || !pd.allFinite() || !pdd.allFinite() || !we.allFinite()) return Status::NonFinite;
  Vec8 y;
  y << pose, pd;
  ReducedDynamics rd;
  const Status s = reduced_terms(m, y, generalized_forces(Vec4::Zero(), we), kStopsFromState, rd);
  if (s != Status::Ok) return s;
  Mat4 Mr, J_rho;
  Vec4 rhs;
  rd.reduced_system(m, we, Mr, rhs);
  for (int i = 0; i < kLegs; ++i) J_rho.row(i) = rd.leg(i).A.row(0);
  const Eigen::PartialPivLU<Mat4> lu(J_rho.transpose());
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::Singular;
  out.F = lu.solve(Mr * pdd - rhs);  // R(F = 0) = J_rho^T F
  ResidualPartials P;
  residual_partials(m, rd, pd, pdd, out.F, kStopsFromState, P);
  out.dp = lu.solve(P.dp);
  out.dpd = lu.solve(P.dpd);
  out.dpdd = lu.solve(P.Mr);
  out.dwe = -lu.solve(Mat4::Identity());
  out.J_rho = J_rho;
  out.drhod_dp = P.drhod_dp;
  const bool finite = out.F.allFinite() && out.dp.allFinite() && out.dpd.allFinite() && out.dpdd.allFinite();
  return finite ? Status::Ok : Status::Singular;
}

}  // namespace pkm
