// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/lagrangian_derivatives.hpp"

#include "pkm4puu/dynamics/lagrangian.hpp"

namespace pkm {

LegTermsPartials leg_terms_partials(const Params& p, const LegConfig& c, const Vec3& qd, const Vec3& qdd) {
  const LegMassSlopes d = leg_mass_slopes(p, c);
  const double k = p.I_rod[0] - p.I_rod[1] - 0.25 * p.m_rod * p.l * p.l;
  const double ddM13 = -0.5 * p.m_rod * p.l * c.c2;
  const double ddM22 = 2.0 * k * (c.c2 * c.c2 - c.s2 * c.s2);
  const double a = qd[1], b = qd[2];
  LegTermsPartials out;
  out.dtheta2 << d.dM13 * qdd[2] + ddM13 * b * b,
                   d.dM22 * qdd[1] + ddM22 * a * b,
                   d.dM13 * qdd[0] - 0.5 * ddM22 * a * a - 0.5 * p.m_rod * p.g * p.l * c.s2;
  out.dqd << 0.0, 0.0, 2.0 * d.dM13 * b,
             0.0, d.dM22 * b, d.dM22 * a,
             0.0, -d.dM22 * a, 0.0;
  return out;
}

}  // namespace pkm
