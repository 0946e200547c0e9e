// SPDX-License-Identifier: BSD-2-Clause
// sin and cos of one angle (the platform's phi, once per state derivative).
//
// std::sin and std::cos everywhere but Windows, where GCC makes them one
// call to sincos as on Linux, but MinGW-w64's libm evaluates it in x87 long
// double, several times glibc's cost (docs/performance.md). There the
// Taylor series below, in doubles, after reducing x by multiples of pi/2:
// on |r| <= pi/4 the first omitted terms, r^19/19! and r^20/20!, are below
// 1e-19, so the error is the rounding of the evaluation, within 2 ulp
// (tests/core/kinematics.cpp checks it against std::sin, std::cos).
#pragma once

#include <cmath>

namespace pkm {

/// sin x and cos x by the series (header comment); std::sin and std::cos
/// for |x| >= 1e5 and non-finite x.
inline void sin_cos_series(double x, double& s, double& c) {
  if (!(std::fabs(x) < 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  // r = x - k pi/2 with pi/2 = P1 + P2 + P3: P1 holds pi/2's leading 33
  // bits and P2 the next 17, so k P1 and k P2 are exact for |k| < 2^20;
  // P3 = pi/2 - (P1 + P2), the double pi/2's own rounding error.
  constexpr double P1 = 0x1.921fb544p+0, P2 = 0x1.0b46p-34, P3 = 6.123233995736766e-17;
  // k: x / (pi/2) to the nearest integer by a conversion (one instruction;
  // MinGW's nearbyint and floor are library calls).
  const double q = x * 0.63661977236758134308;
  const long n = static_cast<long>(q + (q >= 0.0 ? 0.5 : -0.5));
  const double k = static_cast<double>(n);
  const double r = ((x - k * P1) - k * P2) - k * P3;
  const double r2 = r * r;
  // sin r = r - r^3/3! + ... - r^19/19! omitted; cos r = 1 - r^2/2! + ... .
  const double ps = -1.0 / 6 + r2 * (1.0 / 120 + r2 * (-1.0 / 5040 + r2 * (1.0 / 362880 + r2 * (-1.0 / 39916800 +
                    r2 * (1.0 / 6227020800 + r2 * (-1.0 / 1307674368000 + r2 * (1.0 / 355687428096000)))))));
  const double pc = 1.0 / 24 + r2 * (-1.0 / 720 + r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 + r2 * (1.0 / 479001600 +
                    r2 * (-1.0 / 87178291200 + r2 * (1.0 / 20922789888000 + r2 * (-1.0 / 6402373705728000)))))));
  const double sr = r + r * (r2 * ps);
  const double cr = 1.0 - (0.5 * r2 - (r2 * r2) * pc);
  switch (n & 3) {
    case 0: s = sr, c = cr; break;
    case 1: s = cr, c = -sr; break;
    case 2: s = -sr, c = -cr; break;
    default: s = -cr, c = sr; break;
  }
}

/// sin x and cos x (header comment).
inline void sin_cos(double x, double& s, double& c) {
#if defined(_WIN32)
  sin_cos_series(x, s, c);
#else
  s = std::sin(x);
  c = std::cos(x);
#endif
}

}  // namespace pkm
