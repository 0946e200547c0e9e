// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/lagrangian.hpp"

#include <cmath>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/machine/end_stops.hpp"

namespace pkm {
LegMassSlopes leg_mass_slopes(const Params& p, const LegConfig& c) {
  const double k = p.I_rod[0] - p.I_rod[1] - 0.25 * p.m_rod * p.l * p.l;
  return {-0.5 * p.m_rod * p.l * c.s2, 2.0 * k * c.s2 * c.c2};
}

Mat3 leg_mass_matrix(const Model& m, const LegConfig& c) {
  const Params& p = m.p;
  const double mr = p.m_rod, l = p.l;
  Mat3 M = Mat3::Zero();
  M(0, 0) = p.m_slider + mr + m.reflected_mass;
  M(0, 2) = M(2, 0) = 0.5 * mr * l * c.c2;
  M(1, 1) = 0.25 * mr * l * l * c.c2 * c.c2 + p.I_rod[0] * c.s2 * c.s2 + p.I_rod[1] * c.c2 * c.c2;
  M(2, 2) = 0.25 * mr * l * l + p.I_rod[2];
  return M;
}

Vec3 leg_coriolis(const Params& p, const LegConfig& c, double th1d, double th2d, double rhod) {
  // M depends on theta2 only: (dM/dt) qd = th2d M' qd, dT/dth2 = 1/2 qd^T M' qd.
  (void)rhod;  // the rho-th2 products cancel: M13' rhod th2d - M13' rhod th2d
  const LegMassSlopes d = leg_mass_slopes(p, c);
  return {d.dM13 * th2d * th2d, d.dM22 * th1d * th2d, -0.5 * d.dM22 * th1d * th1d};
}

Vec3 leg_gravity(const Params& p, const LegConfig& c) {
  return {(p.m_slider + p.m_rod) * p.g, 0.0, 0.5 * p.m_rod * p.g * p.l * c.c2};
}

PlatformInertia platform_inertia(const Model& m, double cphi, double sphi) {
  return {m.platform_mass, m.platform_Izz, cphi * m.payload_mx - sphi * m.payload_my,
          sphi * m.payload_mx + cphi * m.payload_my};
}

void mass_matrix(const Model& m, const Vec16& q, Mat16& M) {
  M.setZero();
  for (int i = 0; i < kLegs; ++i)
    M.block<3, 3>(leg_offset(i), leg_offset(i)) = leg_mass_matrix(m, leg_config_from_q(q, i));
  const PlatformInertia pi = platform_inertia(m, std::cos(q[15]), std::sin(q[15]));
  M(12, 12) = M(13, 13) = M(14, 14) = pi.mass;
  M(15, 15) = pi.Izz;
  M(12, 15) = M(15, 12) = -pi.mwy;
  M(13, 15) = M(15, 13) = pi.mwx;
}

Vec16 coriolis(const Model& m, const Vec16& q, const Vec16& qd) {
  Vec16 V = Vec16::Zero();
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    V.segment<3>(o) = leg_coriolis(m.p, leg_config_from_q(q, i), qd[o + 1], qd[o + 2], qd[o]);
  }
  const PlatformInertia pi = platform_inertia(m, std::cos(q[15]), std::sin(q[15]));
  V[12] = -pi.mwx * qd[15] * qd[15];
  V[13] = -pi.mwy * qd[15] * qd[15];
  return V;
}

Vec16 gravity(const Model& m, const Vec16& q) {
  Vec16 G = Vec16::Zero();
  for (int i = 0; i < kLegs; ++i) G.segment<3>(leg_offset(i)) = leg_gravity(m.p, leg_config_from_q(q, i));
  G[14] = m.platform_mass * m.p.g;
  return G;
}

double kinetic_energy(const Model& m, const Vec16& q, const Vec16& qd) {
  double T = 0.0;
  for (int i = 0; i < kLegs; ++i) {
    const Vec3 v = qd.segment<3>(leg_offset(i));
    T += 0.5 * v.dot(leg_mass_matrix(m, leg_config_from_q(q, i)) * v);
  }
  const PlatformInertia pi = platform_inertia(m, std::cos(q[15]), std::sin(q[15]));
  T += 0.5 * pi.mass * qd.segment<3>(kPlatform).squaredNorm();
  T += 0.5 * pi.Izz * qd[15] * qd[15];
  T += qd[15] * (pi.mwx * qd[13] - pi.mwy * qd[12]);
  return T;
}

double potential_energy(const Model& m, const Vec16& q) {
  const Params& p = m.p;
  double U = m.platform_mass * p.g * q[14];
  for (int i = 0; i < kLegs; ++i) {
    const int o = leg_offset(i);
    U += p.m_slider * p.g * q[o];
    U += p.m_rod * p.g * (q[o] + p.h + 0.5 * p.l * std::sin(q[o + 2]));
    U += stop_potential(p, q[o]);
  }
  return U;
}

Vec16 generalized_forces(const Vec4& F, const Wrench& we) {
  Vec16 f = Vec16::Zero();
  for (int i = 0; i < kLegs; ++i) f[leg_offset(i)] = F[i];
  f.segment<4>(kPlatform) = we;
  return f;
}

Vec16 generalized_forces(const Model& m, const Vec4& F, const Vec4& tau, const Wrench& we) {
  return generalized_forces(F + m.drive_ratio * tau, we);
}

}  // namespace pkm
