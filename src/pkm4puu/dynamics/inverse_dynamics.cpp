// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/inverse_dynamics.hpp"

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/inverse_lanes.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/machine/passive_force.hpp"

namespace pkm {
namespace {

constexpr int kActuatedCoord[kLegs] = {0, 3, 6, 9};
constexpr int kUnactuated[kM] = {1, 2, 4, 5, 7, 8, 10, 11, 12, 13, 14, 15};

/// Eqs. 10-11; with `passive`, on top of the joints' passive forces.
Status forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& qdd, const Wrench& we, bool passive,
              Vec4& F, Vec12& lambda) {
  if (!we.allFinite() || !qdd.allFinite()) return Status::NonFinite;
  Mat16 M;
  mass_matrix(m, q, M);
  Mat12x16 Cq;
  constraint_jacobian(m, q, Cq);
  // Inertial, Coriolis and gravity terms: everything of Eq. 1 but C_q^T lambda.
  const Vec16 inertial = M * qdd + coriolis(m, q, qd) + gravity(m, q);
  const Vec16 f_known = generalized_forces(Vec4::Zero(), we);

  Mat12 CuT;  // (C_q restricted to the unactuated columns)^T
  Vec12 rhs;
  for (int r = 0; r < kM; ++r) {
    const int k = kUnactuated[r];
    CuT.row(r) = Cq.col(k).transpose();
    rhs[r] = f_known[k] - inertial[k];
  }
  Eigen::PartialPivLU<Mat12> lu(CuT);
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::Singular;
  lambda = lu.solve(rhs);  // Eq. 10
  for (int i = 0; i < kLegs; ++i) {
    const int k = kActuatedCoord[i];
    F[i] = inertial[k] + Cq.col(k).dot(lambda);  // Eq. 11
    if (passive) F[i] -= passive_joint_force(m.p, q[k], qd[k]);
  }
  if (!F.allFinite() || !lambda.allFinite()) return Status::Singular;
  return Status::Ok;
}

}  // namespace

Status actuator_forces(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& qdd,
                       const Wrench& we, Vec4& F, Vec12& lambda) {
  return forces(m, q, qd, qdd, we, /*passive=*/true, F, lambda);
}

Status holding_forces(const Model& m, const Vec16& q, const Wrench& we, Vec4& F) {
  // At rest friction is zero; the end stops' springs are not counted on:
  // no passive force at all (so that F does not follow rho through them).
  Vec12 lambda;
  return forces(m, q, Vec16::Zero(), Vec16::Zero(), we, /*passive=*/false, F, lambda);
}

Status inverse_dynamics_general(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                                const Wrench& we, InverseDynamicsResult& out, bool warm_start,
                                const NewtonOptions& opt) {
  if (!pose.allFinite() || !pose_d.allFinite() || !pose_dd.allFinite() || !we.allFinite())
    return Status::NonFinite;
  Status s = Status::Ok;
  if (!warm_start) {
    s = closed_form_position(m, pose, out.q);
    if (s != Status::Ok) return s;
  }
  s = solve_position(m, pose, out.q, opt);
  if (s != Status::Ok) return s;
  ServoJacobian J;
  s = J.factor(m, out.q);
  if (s != Status::Ok) return s;
  out.qd = J.velocity(pose_d);
  out.qdd = J.acceleration(m, out.q, out.qd, pose_dd);
  Vec4 rho;
  for (int i = 0; i < kLegs; ++i) rho[i] = out.q[leg_offset(i)];
  out.beyond_stops = stops_passed(m.p, rho);
  s = actuator_forces(m, out.q, out.qd, out.qdd, we, out.F, out.lambda);
  out.tau = out.F / m.drive_ratio;
  return s;
}

Status inverse_dynamics(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                        const Wrench& we, InverseDynamicsResult& out, bool, const NewtonOptions&) {
  return reduced_inverse(m, pose, pose_d, pose_dd, we, &out, nullptr);
}

Status inverse_actuators(const Model& m, const Pose& pose, const Pose& pose_d, const Pose& pose_dd,
                         const Wrench& we, InverseActuators& out) {
  return reduced_inverse(m, pose, pose_d, pose_dd, we, nullptr, &out);
}

}  // namespace pkm
