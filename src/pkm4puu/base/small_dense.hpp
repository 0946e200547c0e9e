// SPDX-License-Identifier: BSD-2-Clause
// Dense solvers for the reference formulations of forward_dynamics.cpp
// (Eq. 12's 28x28 augmented system, Eq. 13's QR null space), written as
// plain loops over fixed-size matrices. Eigen's PartialPivLU, HouseholderQR
// and LLT instantiate their blocked (matrix-product) kernels even for small
// fixed sizes: in forward_dynamics.cpp they took 35 of its 37 s of compile
// time, in each of the four builds (host, Windows, aarch64, sanitizers). The
// default LegPartitioned formulation uses none of this.
#pragma once

#include <cmath>
#include <utility>

#include <Eigen/Core>

namespace pkm::dense {

/// Solves A x = b by Gaussian elimination with partial pivoting; A is
/// overwritten by its factors, b by x. False if a pivot is zero or not finite.
template <int N>
bool lu_solve_in_place(Eigen::Matrix<double, N, N>& A, Eigen::Matrix<double, N, 1>& b) {
  for (int k = 0; k < N; ++k) {
    int p = k;
    for (int i = k + 1; i < N; ++i)
      if (std::fabs(A(i, k)) > std::fabs(A(p, k))) p = i;
    if (!(std::fabs(A(p, k)) > 0.0) || !std::isfinite(A(p, k))) return false;
    if (p != k) {
      for (int j = k; j < N; ++j) std::swap(A(k, j), A(p, j));
      std::swap(b[k], b[p]);
    }
    for (int i = k + 1; i < N; ++i) {
      const double l = A(i, k) / A(k, k);
      if (l == 0.0) continue;
      for (int j = k + 1; j < N; ++j) A(i, j) -= l * A(k, j);
      b[i] -= l * b[k];
    }
  }
  for (int i = N - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < N; ++j) s -= A(i, j) * b[j];
    b[i] = s / A(i, i);
  }
  return true;
}

/// Householder QR of a full-column-rank A (R x C, R >= C): A = Q [U; 0] with
/// Q (R x R) orthogonal and U (C x C) upper triangular. False if a column is
/// dependent on the ones before it (|U(k,k)| <= tol).
template <int R, int C>
bool householder_qr(const Eigen::Matrix<double, R, C>& A, Eigen::Matrix<double, R, R>& Q,
                    Eigen::Matrix<double, C, C>& U, double tol) {
  static_assert(R >= C, "householder_qr: more columns than rows");
  Eigen::Matrix<double, R, C> W = A;
  Eigen::Matrix<double, R, C> V = Eigen::Matrix<double, R, C>::Zero();  // reflector k: I - beta_k v_k v_k^T
  double beta[C];
  for (int k = 0; k < C; ++k) {
    double norm2 = 0.0;
    for (int i = k; i < R; ++i) norm2 += W(i, k) * W(i, k);
    const double alpha = W(k, k) >= 0.0 ? -std::sqrt(norm2) : std::sqrt(norm2);  // no cancellation in v_k
    if (!(std::fabs(alpha) > tol)) return false;
    double v2 = 0.0;
    for (int i = k; i < R; ++i) {
      V(i, k) = W(i, k) - (i == k ? alpha : 0.0);
      v2 += V(i, k) * V(i, k);
    }
    beta[k] = 2.0 / v2;
    W(k, k) = alpha;
    for (int i = k + 1; i < R; ++i) W(i, k) = 0.0;
    for (int j = k + 1; j < C; ++j) {
      double s = 0.0;
      for (int i = k; i < R; ++i) s += V(i, k) * W(i, j);
      s *= beta[k];
      for (int i = k; i < R; ++i) W(i, j) -= s * V(i, k);
    }
  }
  U = W.template topRows<C>();
  // Q = H_0 H_1 ... H_{C-1}, applied to the identity from the last reflector.
  Q.setIdentity();
  for (int k = C - 1; k >= 0; --k)
    for (int j = 0; j < R; ++j) {
      double s = 0.0;
      for (int i = k; i < R; ++i) s += V(i, k) * Q(i, j);
      s *= beta[k];
      for (int i = k; i < R; ++i) Q(i, j) -= s * V(i, k);
    }
  return true;
}

/// x = U^{-1} b (U upper triangular).
template <int N>
Eigen::Matrix<double, N, 1> upper_solve(const Eigen::Matrix<double, N, N>& U, const Eigen::Matrix<double, N, 1>& b) {
  Eigen::Matrix<double, N, 1> x;
  for (int i = N - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < N; ++j) s -= U(i, j) * x[j];
    x[i] = s / U(i, i);
  }
  return x;
}

/// x = U^{-T} b (U upper triangular, so U^T lower).
template <int N>
Eigen::Matrix<double, N, 1> upper_transpose_solve(const Eigen::Matrix<double, N, N>& U,
                                                  const Eigen::Matrix<double, N, 1>& b) {
  Eigen::Matrix<double, N, 1> x;
  for (int i = 0; i < N; ++i) {
    double s = b[i];
    for (int j = 0; j < i; ++j) s -= U(j, i) * x[j];
    x[i] = s / U(i, i);
  }
  return x;
}

/// x = A^{-1} b for a symmetric positive definite A, by Cholesky
/// (A = L L^T). False if A is not (numerically) positive definite.
template <int N>
bool cholesky_solve(const Eigen::Matrix<double, N, N>& A, const Eigen::Matrix<double, N, 1>& b,
                    Eigen::Matrix<double, N, 1>& x) {
  Eigen::Matrix<double, N, N> L = Eigen::Matrix<double, N, N>::Zero();
  for (int j = 0; j < N; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k);
    if (!(d > 0.0)) return false;
    L(j, j) = std::sqrt(d);
    for (int i = j + 1; i < N; ++i) {
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k);
      L(i, j) = s / L(j, j);
    }
  }
  Eigen::Matrix<double, N, N> U = L.transpose();
  x = upper_solve<N>(U, upper_transpose_solve<N>(U, b));
  return true;
}

}  // namespace pkm::dense
