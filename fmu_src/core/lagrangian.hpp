// Terms of Eq. 1, M(q) qdd + V(q, qd) + G(q) + C_q^T lambda = f, derived
// analytically from the Lagrangian of Eq. 14 with the bodies of Table III:
//   slider: 1/2 m_s rhod^2,                       U = m_s g rho
//   rod:    1/2 m_r |v_c|^2 + 1/2 w3^T I w3,       U = m_r g (rho + h + l/2 s2)
//           v_c = d/dt[O2 + l/2 x3],  w3 (frame 3) = (s2 th1d, c2 th1d, th2d)
//   platform: 1/2 m_p |pd|^2 + 1/2 Izz phid^2,     U = m_p g z
// Each leg's 3x3 block depends on theta2 only; the platform block is constant.
//   M_leg = [ m_s+m_r          0                                    m_r l/2 c2
//             0                m_r l^2/4 c2^2 + Ix s2^2 + Iy c2^2   0
//             m_r l/2 c2       0                                    m_r l^2/4 + Iz ]
#pragma once

#include "leg_kinematics.hpp"

namespace pkm {

Mat3 leg_mass_matrix(const Params& p, const LegConfig& c);
/// Coriolis and centripetal terms of one leg: (dM/dt) qd - dT/dq.
Vec3 leg_coriolis(const Params& p, const LegConfig& c, double th1d, double th2d, double rhod);
/// dU/d(rho, theta1, theta2) of one leg.
Vec3 leg_gravity(const Params& p, const LegConfig& c);

/// Full 16x16 M(q) (block diagonal).
void mass_matrix(const Model& m, const Vec16& q, Mat16& M);
Vec16 coriolis(const Model& m, const Vec16& q, const Vec16& qd);
Vec16 gravity(const Model& m, const Vec16& q);

double kinetic_energy(const Model& m, const Vec16& q, const Vec16& qd);
double potential_energy(const Model& m, const Vec16& q);

/// f of Eq. 1: actuator forces F_i on rho_i, external wrench on (x,y,z,phi).
Vec16 generalized_forces(const Vec4& F, const Wrench& we);

}  // namespace pkm
