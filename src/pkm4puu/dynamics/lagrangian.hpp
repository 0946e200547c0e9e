// SPDX-License-Identifier: BSD-2-Clause
// Terms of Eq. 1, M(q) qdd + V(q, qd) + G(q) + C_q^T lambda = f, derived
// analytically from the Lagrangian of Eq. 14 with the bodies of Table III:
//   slider: 1/2 m_s rhod^2,                       U = m_s g rho
//   rod:    1/2 m_r |v_c|^2 + 1/2 w3^T I w3,       U = m_r g (rho + h + l/2 s2)
//           v_c = d/dt[O2 + l/2 x3],  w3 (frame 3) = (s2 th1d, c2 th1d, th2d)
//   platform: 1/2 m_p |pd|^2 + 1/2 Izz phid^2,     U = m_p g z
// The machine (docs/model.md "The machine around the mechanism") adds
//   rotor:   1/2 J (2 pi/p)^2 rhod^2 per leg: M_leg(0,0) += J (2 pi/p)^2
//   payload: mass m_l at c_w = Rz(phi) c (platform frame c, at P's height),
//            inertia I_l: 1/2 m_l |pd + phid e_z x c_w|^2 + 1/2 I_l phid^2, U = m_l g z.
//     With m = m_p + m_l, I = Izz + I_l + m_l |c|^2 and (mwx, mwy) = m_l c_w
//     the platform block over (x, y, z, phi) becomes
//       M_p = [ m 0 0 -mwy ; 0 m 0 mwx ; 0 0 m 0 ; -mwy mwx 0 I ]
//     and its velocity terms V_p = (-mwx phid^2, -mwy phid^2, 0, 0)
//     (d/dt dT/dxd = m xdd - mwy phidd - mwx phid^2; dT/dphi cancels the
//     phi row's own velocity products).
// Each leg's 3x3 block depends on theta2 only; the platform block is constant.
//   M_leg = [ m_s+m_r          0                                    m_r l/2 c2
//             0                m_r l^2/4 c2^2 + Ix s2^2 + Iy c2^2   0
//             m_r l/2 c2       0                                    m_r l^2/4 + Iz ]
#pragma once

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

/// Leg mass matrix, the rotor's reflected mass included in (0, 0).
Mat3 leg_mass_matrix(const Model& m, const LegConfig& c);

/// Derivatives with respect to theta2 of the two non-constant entries of
/// M_leg: M13 = m_r l/2 c2 and M22.
struct LegMassSlopes { double dM13, dM22; };
LegMassSlopes leg_mass_slopes(const Params& p, const LegConfig& c);

/// The platform with its payload about P at angle phi (cphi, sphi).
struct PlatformInertia {
  double mass, Izz;  // m_p + m_l; Izz + I_l + m_l |c|^2
  double mwx, mwy;   // m_l Rz(phi) c
};
PlatformInertia platform_inertia(const Model& m, double cphi, double sphi);
/// Coriolis and centripetal terms of one leg: (dM/dt) qd - dT/dq.
Vec3 leg_coriolis(const Params& p, const LegConfig& c, double th1d, double th2d, double rhod);
/// dU/d(rho, theta1, theta2) of one leg.
Vec3 leg_gravity(const Params& p, const LegConfig& c);

/// Full 16x16 M(q) (block diagonal).
void mass_matrix(const Model& m, const Vec16& q, Mat16& M);
Vec16 coriolis(const Model& m, const Vec16& q, const Vec16& qd);
Vec16 gravity(const Model& m, const Vec16& q);

double kinetic_energy(const Model& m, const Vec16& q, const Vec16& qd);
/// Gravity plus the end stops' springs (machine.hpp).
double potential_energy(const Model& m, const Vec16& q);

/// f of Eq. 1: actuator forces F_i on rho_i, external wrench on (x,y,z,phi).
Vec16 generalized_forces(const Vec4& F, const Wrench& we);
/// The same with motor torques tau on the screws: F_i + (2 pi/p) tau_i on rho_i.
Vec16 generalized_forces(const Model& m, const Vec4& F, const Vec4& tau, const Wrench& we);

}  // namespace pkm
