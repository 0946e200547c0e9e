#include "reduced_dynamics.hpp"

#include "constraints.hpp"
#include "lagrangian.hpp"

namespace pkm {

/// Below this |det L_i| / l^2 a leg is treated as singular.
constexpr double kLegSingularTol = 1e-12;

Status ReducedDynamics::prepare_leg(const Model& m, int leg, const LegConfig& c,
                                    const PlatformConfig& pc) {
  if (leg_singularity_measure(m.p, c) < kLegSingularTol) return Status::Singular;
  Leg& L = legs_[leg];
  L.c = c;
  L.attach = rotated_attachment(m, leg, pc);
  L.Linv = leg_block(m, leg, c).inverse();
  L.A = L.Linv * platform_point_jacobian(m, leg, pc);
  L.M = leg_mass_matrix(m.p, c);
  return Status::Ok;
}

void ReducedDynamics::add_leg(const Model& m, int leg, const Vec3& qd_leg, double phid, double F) {
  Leg& L = legs_[leg];
  const Vec3 gamma = rotate_to_base(m, leg, leg_point_quadratic(m.p, L.c, qd_leg[1], qd_leg[2])) +
                     L.attach * (phid * phid);
  L.b = -(L.Linv * gamma);
  const Vec3 f(F, 0.0, 0.0);
  L.r = f - leg_coriolis(m.p, L.c, qd_leg[1], qd_leg[2], qd_leg[0]) - leg_gravity(m.p, L.c) - L.M * L.b;
  if (leg == 0) {
    Mr_.setZero();
    rhs_.setZero();
  }
  Mr_.noalias() += L.A.transpose() * L.M * L.A;
  rhs_.noalias() += L.A.transpose() * L.r;
}

Status ReducedDynamics::solve_platform(const Model& m, const Wrench& we, Pose& a) const {
  const Params& p = m.p;
  Mat4 Mr = Mr_;
  Mr.diagonal() += Vec4(p.m_platform, p.m_platform, p.m_platform, p.Izz_platform);
  Vec4 rhs = rhs_ + we;
  rhs[2] -= p.m_platform * p.g;  // G_p
  const Eigen::LLT<Mat4> llt(Mr);
  if (llt.info() != Eigen::Success) return Status::Singular;
  a = llt.solve(rhs);
  return a.allFinite() ? Status::Ok : Status::Singular;
}

Status ReducedDynamics::solve(const Model& m, const Wrench& we, Vec16& qdd, Vec12& lambda) {
  Pose a;
  const Status s = solve_platform(m, we, a);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& L = legs_[i];
    const Vec3 qdd_i = L.A * a + L.b;
    qdd.segment<3>(leg_offset(i)) = qdd_i;
    lambda.segment<3>(3 * i) = L.Linv.transpose() * (L.r - L.M * (L.A * a));
  }
  qdd.segment<4>(kPlatform) = a;
  return lambda.allFinite() ? Status::Ok : Status::Singular;
}

}  // namespace pkm
