// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/dynamics/leg_lanes_derivatives.hpp"

#include "pkm4puu/dynamics/leg_lanes_kernel.hpp"
#include "pkm4puu/dynamics/reduced_dynamics.hpp"


namespace pkm {
namespace {

using namespace leg_lanes_kernel;

/// One leg's share of dR/dp and dR/dpd (row-major 4x4), its rows of
/// d rho/dp and d rhod/dp.
template <class T>
struct LegShare {
  T dp[16], dpd[16], jr[4], rdp[4];
};

/// The passive joint force's slopes per lane (passive_joint_force_slopes;
/// for the lanes its plain case, as leg_lanes_kernel's passive_force).
PKM_LANES_INLINE void passive_slopes(const Params& p, int first, unsigned stops, double rho, double rhod,
                                     double& drho, double& drhod) {
  const PassiveSlopes s = passive_joint_force_slopes(p, first, stops, rho, rhod);
  drho = s.drho;
  drhod = s.drhod;
}
PKM_LANES_INLINE void passive_slopes(const Params& p, int first, unsigned stops, const lanes::Pack& rho,
                                     const lanes::Pack& rhod, lanes::Pack& drho, lanes::Pack& drhod) {
  if (p.friction_coulomb == 0.0 &&
      (stops == kStopsFromState
           ? !lanes::any(lanes::either(lanes::lt(rho, p.rho_min), lanes::gt(rho, p.rho_max)))
           : (stops & ((1u << (2 * kLegs)) - 1u)) == 0u)) {
    drho = lanes::broadcast(0.0);
    drhod = lanes::broadcast(-p.friction_viscous);
    return;
  }
  double a[lanes::kWidth], b[lanes::kWidth];
  for (int i = 0; i < lanes::kWidth; ++i)
    passive_slopes(p, first + i, stops, lanes::lane(rho, i), lanes::lane(rhod, i), a[i], b[i]);
  drho = lanes::pack(a[0], a[1], a[2], a[3]);
  drhod = lanes::pack(b[0], b[1], b[2], b[3]);
}

/// add_projected (reduced_dynamics_derivatives.cpp) for one leg:
/// out = A^T X A + (A^T x) e_phi^T, A = L^{-1} [I3, c], c = (cx, cy, 0),
/// with L^{-1}'s third column e_0 written out.
template <class T>
PKM_LANES_INLINE void projected(const LegKeep<T>& k, const T& cx, const T& cy, const T X[3][3], const T x[3],
                                T out[16]) {
  T Z[3][3];  // X L^{-1}
  for (int r = 0; r < 3; ++r) {
    Z[r][0] = X[r][0] * k.l00 + X[r][1] * k.l10 + X[r][2] * k.l20;
    Z[r][1] = X[r][0] * k.l01 + X[r][1] * k.l11 + X[r][2] * k.l21;
    Z[r][2] = X[r][0];
  }
  T Y[3][3];  // L^{-T} X L^{-1}
  for (int c = 0; c < 3; ++c) {
    Y[0][c] = k.l00 * Z[0][c] + k.l10 * Z[1][c] + k.l20 * Z[2][c];
    Y[1][c] = k.l01 * Z[0][c] + k.l11 * Z[1][c] + k.l21 * Z[2][c];
    Y[2][c] = Z[0][c];
  }
  const T y[3] = {k.l00 * x[0] + k.l10 * x[1] + k.l20 * x[2], k.l01 * x[0] + k.l11 * x[1] + k.l21 * x[2], x[0]};
  T Yc[3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[4 * r + c] = Y[r][c];
    Yc[r] = Y[r][0] * cx + Y[r][1] * cy;
    out[4 * r + 3] = Yc[r] + y[r];
  }
  for (int c = 0; c < 3; ++c) out[12 + c] = cx * Y[0][c] + cy * Y[1][c];
  out[15] = (cx * Yc[0] + cy * Yc[1]) + (cx * y[0] + cy * y[1]);
}

/// Leg i's share (reduced_dynamics_derivatives.hpp's formulas) from what
/// the first pass kept, at the solved pdd.
template <class T>
PKM_LANES_INLINE void leg_share(const Model& m, int first, unsigned stops, const LegKeep<T>& k, const T& rho,
                                const Pose& pd, const Pose& pdd, LegShare<T>& o) {
  const Params& p = m.p;
  const double l = p.l, hp = p.h_prime, phid = pd[3];
  const T c1 = k.c1, s1 = k.s1, c2 = k.c2, s2 = k.s2;
  // qdd = A pdd + b and w = M qdd + V + G - f = M A pdd - r.
  const T Ap0 = ((k.l00 * pdd[0] + k.l01 * pdd[1]) + pdd[2]) + k.a03 * pdd[3];
  const T Ap1 = (k.l10 * pdd[0] + k.l11 * pdd[1]) + k.a13 * pdd[3];
  const T Ap2 = (k.l20 * pdd[0] + k.l21 * pdd[1]) + k.a23 * pdd[3];
  const T qdd0 = Ap0 + k.b0, qdd1 = Ap1 + k.b1, qdd2 = Ap2 + k.b2;
  const double m00 = p.m_slider + p.m_rod + m.reflected_mass, m22 = 0.25 * p.m_rod * l * l + p.I_rod[2];
  const T m02 = k.m02, m11 = k.m11;
  const T w0 = (m00 * Ap0 + m02 * Ap2) - k.r0, w1 = m11 * Ap1 - k.r1, w2 = (m02 * Ap0 + m22 * Ap2) - k.r2;
  // c = e_z x r and L^{-1} r (r = Rz(phi) r_Qi, its z is 0).
  const T cx = -k.ay, cy = k.ax;
  const T lr0 = k.l00 * k.ax + k.l01 * k.ay, lr1 = k.l10 * k.ax + k.l11 * k.ay, lr2 = k.l20 * k.ax + k.l21 * k.ay;
  // leg_point_curvature (z = 0 where not written): p111 = (-p11y, p11x),
  // p112 = (-p12y, p12x), p122 = (-p22y, p22x), p222 = (-p12y, p12x, -l c2).
  const T p11x = -l * c1 * c2 - hp * s1, p11y = -l * s1 * c2 + hp * c1;
  const T p12x = l * s1 * s2, p12y = -l * c1 * s2;
  const T p22x = -l * c1 * c2, p22y = -l * s1 * c2, p22z = -l * s2;
  const T p222z = -l * c2;
  const T a = k.qd1, b = k.qd2;
  // E(qd) (columns 1, 2) and Na = -J^{-1} E(qd).
  const T e1x = p11x * a + p12x * b, e1y = p11y * a + p12y * b;
  const T e2x = p12x * a + p22x * b, e2y = p12y * a + p22y * b, e2z = p22z * b;
  const T na01 = -(k.j00 * e1x + k.j01 * e1y), na11 = -(k.j10 * e1x + k.j11 * e1y),
          na21 = -(k.j20 * e1x + k.j21 * e1y);
  const T na02 = -((k.j00 * e2x + k.j01 * e2y) + e2z), na12 = -(k.j10 * e2x + k.j11 * e2y),
          na22 = -(k.j20 * e2x + k.j21 * e2y);
  const T n0 = -phid * lr0, n1 = -phid * lr1, n2 = -phid * lr2;
  // Y = E(qdd) + T(qd) + 2 E(qd) Na and Qa = -J^{-1} Y (columns 1, 2).
  const T aa = a * a, ab = 2.0 * a * b, bb = b * b;
  const T y1x = (p11x * qdd1 + p12x * qdd2) + ((-p11y * aa - p12y * ab) - p22y * bb) + 2.0 * (e1x * na11 + e2x * na21);
  const T y1y = (p11y * qdd1 + p12y * qdd2) + ((p11x * aa + p12x * ab) + p22x * bb) + 2.0 * (e1y * na11 + e2y * na21);
  const T y1z = 2.0 * (e2z * na21);
  const T y2x = (p12x * qdd1 + p22x * qdd2) + ((-p12y * aa - p22y * ab) - p12y * bb) + 2.0 * (e1x * na12 + e2x * na22);
  const T y2y = (p12y * qdd1 + p22y * qdd2) + ((p12x * aa + p22x * ab) + p12x * bb) + 2.0 * (e1y * na12 + e2y * na22);
  const T y2z = (p22z * qdd2 + p222z * bb) + 2.0 * (e2z * na22);
  const T qa01 = -((k.j00 * y1x + k.j01 * y1y) + y1z), qa11 = -(k.j10 * y1x + k.j11 * y1y),
          qa21 = -(k.j20 * y1x + k.j21 * y1y);
  const T qa02 = -((k.j00 * y2x + k.j01 * y2y) + y2z), qa12 = -(k.j10 * y2x + k.j11 * y2y),
          qa22 = -(k.j20 * y2x + k.j21 * y2y);
  // qa = 2 Na n - L^{-1} (pdd_phi r + phid^2 c).
  const T vx = pdd[3] * k.ax + (phid * phid) * cx, vy = pdd[3] * k.ay + (phid * phid) * cy;
  const T qa0 = 2.0 * (na01 * n1 + na02 * n2) - (k.l00 * vx + k.l01 * vy);
  const T qa1 = 2.0 * (na11 * n1 + na12 * n2) - (k.l10 * vx + k.l11 * vy);
  const T qa2 = 2.0 * (na21 * n1 + na22 * n2) - (k.l20 * vx + k.l21 * vy);
  // leg_terms_partials with the passive force's slopes (W_qd's zeros out).
  const double kk = p.I_rod[0] - p.I_rod[1] - 0.25 * p.m_rod * l * l;
  const T dM13 = -0.5 * p.m_rod * l * s2, dM22 = 2.0 * kk * s2 * c2;
  const T ddM13 = -0.5 * p.m_rod * l * c2, ddM22 = 2.0 * kk * (c2 * c2 - s2 * s2);
  const T dt0 = dM13 * qdd2 + ddM13 * b * b, dt1 = dM22 * qdd1 + ddM22 * a * b;
  const T dt2 = (dM13 * qdd0 - 0.5 * ddM22 * a * a) - 0.5 * p.m_rod * p.g * l * s2;
  T drho_p, drhod_p;
  passive_slopes(p, first, stops, rho, k.qd0, drho_p, drhod_p);
  const T wq00 = -drhod_p, wq02 = 2.0 * dM13 * b, wq11 = dM22 * b, wq12 = dM22 * a, wq21 = -dM22 * a;
  // mu = J^{-T} w and K = W_q - H_mu + W_qd Na + M Qa.
  const T mu0 = (k.j00 * w0 + k.j10 * w1) + k.j20 * w2, mu1 = (k.j01 * w0 + k.j11 * w1) + k.j21 * w2, mu2 = w0;
  const T mu11 = mu0 * p11x + mu1 * p11y, mu12 = mu0 * p12x + mu1 * p12y;
  const T mu22 = (mu0 * p22x + mu1 * p22y) + mu2 * p22z;
  const T zero = lanes::Traits<T>::constant(0.0);
  const T K[3][3] = {
      {-drho_p, (wq00 * na01 + wq02 * na21) + (m00 * qa01 + m02 * qa21),
       ((wq00 * na02 + wq02 * na22) + (m00 * qa02 + m02 * qa22)) + dt0},
      {zero, ((wq11 * na11 + wq12 * na21) + m11 * qa11) - mu11, (((wq11 * na12 + wq12 * na22) + m11 * qa12) + dt1) - mu12},
      {zero, (wq21 * na11 + (m02 * qa01 + m22 * qa21)) - mu12, ((wq21 * na12 + (m02 * qa02 + m22 * qa22)) + dt2) - mu22}};
  const T x[3] = {(wq00 * n0 + wq02 * n2) + (m00 * qa0 + m02 * qa2), (wq11 * n1 + wq12 * n2) + m11 * qa1,
                  wq21 * n1 + (m02 * qa0 + m22 * qa2)};
  projected(k, cx, cy, K, x, o.dp);
  o.dp[15] = o.dp[15] - ((w0 * lr0 + w1 * lr1) + w2 * lr2);
  // dR/dpd: W_qd + 2 M Na, 2 M n.
  const T Xd[3][3] = {{wq00, 2.0 * (m00 * na01 + m02 * na21), wq02 + 2.0 * (m00 * na02 + m02 * na22)},
                      {zero, wq11 + 2.0 * (m11 * na11), wq12 + 2.0 * (m11 * na12)},
                      {zero, wq21 + 2.0 * (m02 * na01 + m22 * na21), 2.0 * (m02 * na02 + m22 * na22)}};
  const T xd[3] = {2.0 * (m00 * n0 + m02 * n2), 2.0 * (m11 * n1), 2.0 * (m02 * n0 + m22 * n2)};
  projected(k, cx, cy, Xd, xd, o.dpd);
  // d rho/dp = A's row 0; d rhod/dp = Na's row 0 times A, plus n_0 on phi.
  o.jr[0] = k.l00;
  o.jr[1] = k.l01;
  o.jr[2] = lanes::Traits<T>::constant(1.0);
  o.jr[3] = k.a03;
  o.rdp[0] = na01 * k.l10 + na02 * k.l20;
  o.rdp[1] = na01 * k.l11 + na02 * k.l21;
  o.rdp[2] = zero;
  o.rdp[3] = (na01 * k.a13 + na02 * k.a23) + n0;
}

// Summed from leg 0's share on, ((s0 + s1) + s2) + s3 as the lanes' sum
// (not from +0, which would turn a sum of -0s into +0).
PKM_LANES_INLINE void add_share(const LegShare<double>& s, int leg, LegPartialSums& out) {
  for (int n = 0; n < 16; ++n) {
    out.dp(n / 4, n % 4) = leg == 0 ? s.dp[n] : out.dp(n / 4, n % 4) + s.dp[n];
    out.dpd(n / 4, n % 4) = leg == 0 ? s.dpd[n] : out.dpd(n / 4, n % 4) + s.dpd[n];
  }
  for (int c = 0; c < 4; ++c) {
    out.J_rho(leg, c) = s.jr[c];
    out.drhod_dp(leg, c) = s.rdp[c];
  }
}

Status partials_scalar(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                       LegPartialSums& out) {
  LegSums& sums = out.sums;
  LegKeep<double> keep[kLegs];
  Status s = legs_one_at_a_time(m, pc, pd, f, stops, sums, keep);
  if (s == Status::Ok) s = ReducedDynamics::solve_leg_sums(m, f.segment<4>(kPlatform), sums, pc, pd[3], out.pdd);
  if (s != Status::Ok) return s;
  for (int i = 0; i < kLegs; ++i) {
    LegShare<double> share;
    leg_share(m, i, stops, keep[i], sums.rho[i], pd, out.pdd, share);
    add_share(share, i, out);
  }
  return Status::Ok;
}

PKM_LANES_INLINE double lane_sum(const lanes::Pack& v) {
  return ((lanes::lane(v, 0) + lanes::lane(v, 1)) + lanes::lane(v, 2)) + lanes::lane(v, 3);
}

PKM_LANES_INLINE Status partials_as_lanes(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f,
                                          unsigned stops, LegPartialSums& out) {
  LegInputs<lanes::Pack> in = lane_inputs(m);
  in.f_rho = lanes::pack(f[leg_offset(0)], f[leg_offset(1)], f[leg_offset(2)], f[leg_offset(3)]);
  LegContribution<lanes::Pack> c;
  LegKeep<lanes::Pack> keep;
  Status s = leg_contribution(m, 0, pc, pd, stops, in, c, &keep);
  if (s != Status::Ok) return s;
  sum_lanes(c, out.sums);
  s = ReducedDynamics::solve_leg_sums(m, f.segment<4>(kPlatform), out.sums, pc, pd[3], out.pdd);
  if (s != Status::Ok) return s;
  LegShare<lanes::Pack> share;
  leg_share(m, 0, stops, keep, c.rho, pd, out.pdd, share);
  for (int n = 0; n < 16; ++n) {
    out.dp(n / 4, n % 4) = lane_sum(share.dp[n]);
    out.dpd(n / 4, n % 4) = lane_sum(share.dpd[n]);
  }
  for (int i = 0; i < kLegs; ++i)
    for (int col = 0; col < 4; ++col) {
      out.J_rho(i, col) = lanes::lane(share.jr[col], i);
      out.drhod_dp(i, col) = lanes::lane(share.rdp[col], i);
    }
  return Status::Ok;
}

using PartialsCopies = lanes::Copies<decltype(partials_as_lanes), partials_as_lanes>;

}  // namespace

Status leg_partial_sums(const Model& m, const PlatformConfig& pc, const Pose& pd, const Vec16& f, unsigned stops,
                        LegPartialSums& out, lanes::Kernel kind) {
  return lanes::run<PartialsCopies, partials_scalar>(kind, m.avx, Status::InvalidArgument, m, pc, pd, f, stops, out);
}

}  // namespace pkm
