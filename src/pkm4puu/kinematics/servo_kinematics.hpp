// SPDX-License-Identifier: BSD-2-Clause
// Inverse kinematics with the platform motion as a servo-constraint
// (Eqs. 2-9): the 12 loop closures are augmented by the 4 servo equations
// q_platform - pose(t) = 0, giving the square 16x16 system
//   Phi(q) = [C(q); q_p - pose] = 0,   Phi_q = [C_q; 0 I4].
//   position:     Newton  Phi_q dq = -Phi,            Eqs. 2-4
//   velocity:     Phi_q qd  = [0; pose_d],             Eqs. 5-6
//   acceleration: Phi_q qdd = [-gamma; pose_dd],       Eqs. 7-9
#pragma once

#include "pkm4puu/model/model.hpp"

namespace pkm {

struct NewtonOptions {
  double residual_tol = 1e-14;  // stop when |Phi(q)|_inf <= this (m, rad)
  int max_iterations = 30;      // fail with NotConverged beyond this
};

struct NewtonReport {
  int iterations = 0;
  double residual = 0;  // |Phi(q)|_inf at exit
};

/// Newton's method on Phi(q) = 0 from the guess in `q` (Eqs. 2-4). The
/// platform part of the guess is overwritten by `pose` before iterating.
Status solve_position(const Model& m, const Pose& pose, Vec16& q,
                      const NewtonOptions& opt = {}, NewtonReport* report = nullptr);

/// Initial guess for the position problem from the closed-form leg
/// inverse kinematics (elbow-down). Status::Unreachable off the workspace.
Status closed_form_position(const Model& m, const Pose& pose, Vec16& q);

/// Phi_q = [C_q; 0 I4] factorised once at a configuration, for the
/// velocity and acceleration problems that share it.
class ServoJacobian {
 public:
  /// Status::Singular at a leg singularity (the platform rows are regular).
  Status factor(const Model& m, const Vec16& q);
  /// Phi_q^{-1} rhs.
  Vec16 solve(const Vec16& rhs) const { return lu_.solve(rhs); }
  /// Eqs. 5-6: Phi_q qd = [0; pose_d].
  Vec16 velocity(const Pose& pose_d) const;
  /// Eqs. 7-9: Phi_q qdd = [-gamma(q, qd); pose_dd].
  Vec16 acceleration(const Model& m, const Vec16& q, const Vec16& qd, const Pose& pose_dd) const;

 private:
  Eigen::PartialPivLU<Mat16> lu_;
};

/// Eqs. 5-6.
Status solve_velocity(const Model& m, const Vec16& q, const Pose& pose_d, Vec16& qd);

/// Eqs. 7-9.
Status solve_acceleration(const Model& m, const Vec16& q, const Vec16& qd,
                          const Pose& pose_dd, Vec16& qdd);

}  // namespace pkm
