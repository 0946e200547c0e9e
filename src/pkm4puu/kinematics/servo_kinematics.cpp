// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/kinematics/servo_kinematics.hpp"

#include <cmath>

#include "pkm4puu/kinematics/constraints.hpp"

namespace pkm {
Status ServoJacobian::factor(const Model& m, const Vec16& q) {
  if (!q.allFinite()) return Status::NonFinite;
  // det Phi_q is the product of the four leg blocks' determinants.
  for (int i = 0; i < kLegs; ++i)
    if (leg_singularity_measure(m.p, leg_config_from_q(q, i)) < kLegSingularFloor) return Status::Singular;
  Mat16 A = Mat16::Zero();
  Mat12x16 Cq;
  constraint_jacobian(m, q, Cq);
  A.topRows<12>() = Cq;
  A.bottomRightCorner<4, 4>().setIdentity();
  lu_.compute(A);
  return Status::Ok;
}

Vec16 ServoJacobian::velocity(const Pose& pose_d) const {
  Vec16 rhs = Vec16::Zero();
  rhs.tail<4>() = pose_d;
  return solve(rhs);
}

Vec16 ServoJacobian::acceleration(const Model& m, const Vec16& q, const Vec16& qd,
                                  const Pose& pose_dd) const {
  Vec16 rhs;
  rhs.head<12>() = -constraint_gamma(m, q, qd);
  rhs.tail<4>() = pose_dd;
  return solve(rhs);
}

Status closed_form_position(const Model& m, const Pose& pose, Vec16& q) {
  if (!pose.allFinite()) return Status::NonFinite;
  const PlatformConfig pc = platform_config(pose);
  for (int i = 0; i < kLegs; ++i) {
    LegConfig c;
    LegAngles a;
    const Status s = leg_inverse_kinematics(m, i, pc, c, &a);
    if (s != Status::Ok) return s;
    const int o = leg_offset(i);
    q[o] = c.rho;
    q[o + 1] = a.theta1;
    q[o + 2] = a.theta2;
  }
  q.segment<4>(kPlatform) = pose;
  return Status::Ok;
}

Status solve_position(const Model& m, const Pose& pose, Vec16& q, const NewtonOptions& opt,
                      NewtonReport* report) {
  if (!pose.allFinite() || !q.allFinite()) return Status::NonFinite;
  q.segment<4>(kPlatform) = pose;  // the servo rows are then satisfied exactly
  ServoJacobian J;
  Vec16 phi = Vec16::Zero();
  int it = 0;
  double res = 0;
  for (;; ++it) {
    phi.head<12>() = constraints(m, q);
    res = phi.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(res)) break;
    if (res <= opt.residual_tol || it >= opt.max_iterations) break;
    const Status s = J.factor(m, q);
    if (s != Status::Ok) {
      if (report) *report = {it, res};
      return s;
    }
    q -= J.solve(phi);  // Eq. 3-4: q_{k+1} = q_k - Phi_q^{-1} Phi
  }
  if (report) *report = {it, res};
  if (!(res <= opt.residual_tol)) return Status::NotConverged;
  return Status::Ok;
}

Status solve_velocity(const Model& m, const Vec16& q, const Pose& pose_d, Vec16& qd) {
  if (!pose_d.allFinite()) return Status::NonFinite;
  ServoJacobian J;
  const Status s = J.factor(m, q);
  if (s == Status::Ok) qd = J.velocity(pose_d);
  return s;
}

Status solve_acceleration(const Model& m, const Vec16& q, const Vec16& qd, const Pose& pose_dd,
                          Vec16& qdd) {
  if (!pose_dd.allFinite() || !qd.allFinite()) return Status::NonFinite;
  ServoJacobian J;
  const Status s = J.factor(m, q);
  if (s == Status::Ok) qdd = J.acceleration(m, q, qd, pose_dd);
  return s;
}

}  // namespace pkm
