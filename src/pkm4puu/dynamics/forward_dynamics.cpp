// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/forward_dynamics.hpp"

#include <cmath>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/reduced_dynamics.hpp"
#include "pkm4puu/base/small_dense.hpp"

namespace pkm {
namespace {

using Mat28 = Eigen::Matrix<double, 28, 28>;
using Vec28 = Eigen::Matrix<double, 28, 1>;

/// M(q) and C_q(q), where both full-coordinate formulations start.
struct MassAndJacobian {
  Mat16 M;
  Mat12x16 Cq;
};

MassAndJacobian mass_and_jacobian(const Model& m, const Vec16& q) {
  MassAndJacobian r;
  mass_matrix(m, q, r.M);
  constraint_jacobian(m, q, r.Cq);
  return r;
}

Status augmented(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& f, Vec16& qdd,
                 Vec12& lambda) {
  const auto [M, Cq] = mass_and_jacobian(m, q);
  Mat28 A = Mat28::Zero();
  A.topLeftCorner<16, 16>() = M;
  A.topRightCorner<16, 12>() = Cq.transpose();
  A.bottomLeftCorner<12, 16>() = Cq;
  Vec28 x;
  x.head<16>() = f - coriolis(m, q, qd) - gravity(m, q);
  x.tail<12>() = -constraint_gamma(m, q, qd);
  if (!dense::lu_solve_in_place<28>(A, x)) return Status::Singular;
  qdd = x.head<16>();
  lambda = x.tail<12>();
  return x.allFinite() ? Status::Ok : Status::Singular;
}

Status null_space_qr(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& f, Vec16& qdd,
                     Vec12& lambda) {
  const auto [M, Cq] = mass_and_jacobian(m, q);
  Mat16 Q;
  Mat12 R;
  if (!dense::householder_qr<16, 12>(Cq.transpose(), Q, R, 1e-12)) return Status::Singular;  // C_q^T = Q [R; 0]
  const Eigen::Matrix<double, 16, 12> Q1 = Q.leftCols<12>();
  const Eigen::Matrix<double, 16, 4> B = Q.rightCols<4>();
  // Particular solution of C_q qdd = -gamma: C_q = R^T Q1^T, so qdd_p = Q1 R^{-T} (-gamma).
  const Vec12 gamma = constraint_gamma(m, q, qd);
  const Vec16 qdd_p = Q1 * dense::upper_transpose_solve<12>(R, -gamma);
  const Vec16 rhs = f - coriolis(m, q, qd) - gravity(m, q);
  // Eq. 13: B^T M B a = B^T (f - V - G - M qdd_p), qdd = qdd_p + B a.
  const Mat4 Mr = B.transpose() * M * B;
  Vec4 a;
  if (!dense::cholesky_solve<4>(Mr, B.transpose() * (rhs - M * qdd_p), a)) return Status::Singular;
  qdd = qdd_p + B * a;
  // C_q^T lambda = rhs - M qdd: lambda = R^{-1} Q1^T (rhs - M qdd).
  lambda = dense::upper_solve<12>(R, Q1.transpose() * (rhs - M * qdd));
  return (qdd.allFinite() && lambda.allFinite()) ? Status::Ok : Status::Singular;
}

Status leg_partitioned(const Model& m, const Vec16& q, const Vec16& qd, const Vec16& f, Vec16& qdd,
                       Vec12& lambda) {
  ReducedDynamics rd;
  const PlatformConfig pc = platform_config_from_q(q);
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    const Status s = rd.prepare_leg(m, i, leg_config_from_q(q, i), pc);
    if (s != Status::Ok) return s;
    rd.add_leg(m, i, qd.segment<3>(o), qd[15], f[o]);
  }
  return rd.solve(m, f.segment<4>(kPlatform), qdd, lambda);
}

}  // namespace

const char* formulation_name(Formulation f) {
  switch (f) {
    case Formulation::Augmented: return "augmented (Eq. 12)";
    case Formulation::NullSpaceQR: return "null space, QR (Eq. 13)";
    case Formulation::LegPartitioned: return "null space, leg-partitioned (Eq. 13)";
  }
  return "unknown";
}

Status forward_dynamics(const Model& m, Formulation form, const Vec16& q, const Vec16& qd,
                        const Vec16& f, Vec16& qdd, Vec12& lambda) {
  if (!q.allFinite() || !qd.allFinite() || !f.allFinite()) return Status::NonFinite;
  switch (form) {
    case Formulation::Augmented: return augmented(m, q, qd, f, qdd, lambda);
    case Formulation::NullSpaceQR: return null_space_qr(m, q, qd, f, qdd, lambda);
    case Formulation::LegPartitioned: return leg_partitioned(m, q, qd, f, qdd, lambda);
  }
  return Status::InvalidArgument;
}

}  // namespace pkm
