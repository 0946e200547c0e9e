// SPDX-License-Identifier: BSD-2-Clause
// Partial derivatives of one leg's rows of Eq. 1 without the multipliers,
//   w = M(q) qdd + V(q, qd) + G(q)          (lagrangian.hpp),
// with respect to the leg's q = (rho, theta1, theta2) and qd. M, V and G
// depend on theta2 only (M13' = dM13, M22' = dM22 of leg_mass_slopes):
//   dw/dtheta2 = (M13' qdd3 + M13'' th2d^2,
//                 M22' qdd2 + M22'' th1d th2d,
//                 M13' qdd1 - 1/2 M22'' th1d^2 - m_r g l/2 s2)
//   dw/dqd = [0 0 2 M13' th2d; 0 M22' th2d M22' th1d; 0 -M22' th1d 0]
// with M13'' = -m_r l/2 c2 and M22'' = 2 k (c2^2 - s2^2),
// k = I_x - I_y - m_r l^2/4. The passive joint forces are apart
// (machine.hpp, passive_joint_force_slopes).
#pragma once

#include "pkm4puu/kinematics/leg_kinematics.hpp"

namespace pkm {

struct LegTermsPartials {
  Vec3 dtheta2;  // dw/dtheta2 (dw/drho = dw/dtheta1 = 0)
  Mat3 dqd;      // dw/d(rhod, th1d, th2d)
};

LegTermsPartials leg_terms_partials(const Params& p, const LegConfig& c, const Vec3& qd, const Vec3& qdd);

}  // namespace pkm
