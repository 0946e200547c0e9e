// SPDX-License-Identifier: BSD-2-Clause
// Four doubles as lanes: the legs' arithmetic of the lane kernels (the state
// derivative and its Jacobians, the inverse dynamics, the regressor) written
// once, for one leg (T = double) or for the four legs at once (T = Pack),
// with the same operations per lane.
//
// IEEE addition, subtraction, multiplication, division and square root are
// correctly rounded lane by lane, so a lane holds the same bits as the
// scalar code with the same expression order (no FMA contraction: the
// x86-64 baseline and the AVX variant have no FMA, aarch64 builds with
// -ffp-contract=off). Pack is a GCC/Clang vector extension (SSE2 pairs on
// the x86-64 baseline, one register with AVX, NEON pairs on aarch64) or, for
// other compilers, a plain struct of four doubles with loops.
//
// Every function is available for double and for Pack, so a template over T
// reads like scalar code; masks are bool for double and a lane mask for
// Pack (all bits set where true).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>

#if (defined(__GNUC__) || defined(__clang__)) && !defined(PKM_LANES_PORTABLE)
#define PKM_LANES_VECTOR_EXTENSIONS 1
#define PKM_LANES_INLINE inline __attribute__((always_inline))
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__)
#include <cpuid.h>
#endif
#else
#define PKM_LANES_VECTOR_EXTENSIONS 0
#if defined(_MSC_VER)
#define PKM_LANES_INLINE __forceinline
#else
#define PKM_LANES_INLINE inline
#endif
#endif

// x86-64 with GCC or Clang: the lane kernels compile an AVX variant beside
// the SSE2 baseline, taken where Model::avx (make_model asks CPUID). On
// Windows only with PKM_UNALIGNED_VECTOR_MOVES: MinGW-w64's GCC does not keep
// the 32-byte stack alignment its aligned AVX spills assume (GCC PR 54412),
// so the build has the assembler make every vector move unaligned
// (CMakeLists.txt).
#if PKM_LANES_VECTOR_EXTENSIONS && defined(__x86_64__) && !defined(__AVX__) && \
    (!defined(_WIN32) || defined(PKM_UNALIGNED_VECTOR_MOVES))
#define PKM_LANES_AVX_DISPATCH 1
// Marks a kernel's AVX copy (no FMA: no contraction, the same bits).
#define PKM_LANES_AVX_TARGET __attribute__((target("avx")))
#else
#define PKM_LANES_AVX_DISPATCH 0
#define PKM_LANES_AVX_TARGET
#endif

// Every function here is inlined: GCC's note that a 32-byte vector is
// passed differently with and without AVX (-Wpsabi) concerns no call. GCC
// emits it at the end of the translation unit, so it is silenced for the
// rest of the unit (a push/pop around the header would not reach it);
// Clang the same.
#if defined(__clang__)
#if __has_warning("-Wpsabi")
#pragma clang diagnostic ignored "-Wpsabi"
#endif
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace pkm::lanes {

constexpr int kWidth = 4;

#if PKM_LANES_VECTOR_EXTENSIONS

typedef double Pack __attribute__((vector_size(32)));
typedef std::int64_t Mask __attribute__((vector_size(32)));

PKM_LANES_INLINE Pack broadcast(double x) { return Pack{x, x, x, x}; }
PKM_LANES_INLINE Pack pack(double a, double b, double c, double d) { return Pack{a, b, c, d}; }
PKM_LANES_INLINE double lane(const Pack& v, int i) { return v[i]; }

PKM_LANES_INLINE Mask lt(const Pack& a, double b) { return (Mask)(a < b); }
PKM_LANES_INLINE Mask gt(const Pack& a, double b) { return (Mask)(a > b); }
/// !(a >= b) and !(a <= b): true for NaN too.
PKM_LANES_INLINE Mask not_ge(const Pack& a, double b) { return ~(Mask)(a >= b); }
PKM_LANES_INLINE Mask not_le(const Pack& a, double b) { return ~(Mask)(a <= b); }
PKM_LANES_INLINE Mask either(const Mask& a, const Mask& b) { return a | b; }
PKM_LANES_INLINE bool lane(const Mask& m, int i) { return m[i] != 0; }
PKM_LANES_INLINE bool any(const Mask& m) { return ((m[0] | m[1]) | (m[2] | m[3])) != 0; }

/// m ? a : b lane by lane.
PKM_LANES_INLINE Pack select(const Mask& m, const Pack& a, double b) {
  return (Pack)((m & (Mask)a) | (~m & (Mask)broadcast(b)));
}
/// m ? 0 : x lane by lane.
PKM_LANES_INLINE Pack zero_where(const Mask& m, const Pack& x) { return (Pack)(~m & (Mask)x); }

PKM_LANES_INLINE Pack abs(const Pack& x) {
  return (Pack)((Mask)x & Mask{INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX});
}

/// Square root lane by lane (correctly rounded, as std::sqrt).
PKM_LANES_INLINE Pack sqrt(const Pack& x) {
#if defined(__SSE2__)
  // Two SSE2 square roots; with AVX enabled in the caller they are VEX
  // encoded. The same instruction std::sqrt compiles to.
  typedef double Half __attribute__((vector_size(16)));
  const Half lo = _mm_sqrt_pd(Half{x[0], x[1]}), hi = _mm_sqrt_pd(Half{x[2], x[3]});
  return Pack{lo[0], lo[1], hi[0], hi[1]};
#else
  return Pack{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}

#else  // a plain struct for compilers without vector extensions

struct Pack {
  double v[kWidth];
  double operator[](int i) const { return v[i]; }
};
struct Mask {
  bool v[kWidth];
};

PKM_LANES_INLINE Pack broadcast(double x) { return Pack{{x, x, x, x}}; }
PKM_LANES_INLINE Pack pack(double a, double b, double c, double d) { return Pack{{a, b, c, d}}; }
PKM_LANES_INLINE double lane(const Pack& v, int i) { return v.v[i]; }

#define PKM_LANES_BINARY(op)                                                                  \
  PKM_LANES_INLINE Pack operator op(const Pack& a, const Pack& b) {                           \
    Pack r;                                                                                   \
    for (int i = 0; i < kWidth; ++i) r.v[i] = a.v[i] op b.v[i];                               \
    return r;                                                                                 \
  }                                                                                           \
  PKM_LANES_INLINE Pack operator op(const Pack& a, double b) {                                \
    Pack r;                                                                                   \
    for (int i = 0; i < kWidth; ++i) r.v[i] = a.v[i] op b;                                    \
    return r;                                                                                 \
  }                                                                                           \
  PKM_LANES_INLINE Pack operator op(double a, const Pack& b) {                                \
    Pack r;                                                                                   \
    for (int i = 0; i < kWidth; ++i) r.v[i] = a op b.v[i];                                    \
    return r;                                                                                 \
  }
PKM_LANES_BINARY(+)
PKM_LANES_BINARY(-)
PKM_LANES_BINARY(*)
PKM_LANES_BINARY(/)
#undef PKM_LANES_BINARY

PKM_LANES_INLINE Pack operator-(const Pack& a) {
  Pack r;
  for (int i = 0; i < kWidth; ++i) r.v[i] = -a.v[i];
  return r;
}

#define PKM_LANES_COMPARE(name, expr)                         \
  PKM_LANES_INLINE Mask name(const Pack& a, double b) {       \
    Mask m;                                                   \
    for (int i = 0; i < kWidth; ++i) {                        \
      const double x = a.v[i];                                \
      m.v[i] = (expr);                                        \
    }                                                         \
    return m;                                                 \
  }
PKM_LANES_COMPARE(lt, x < b)
PKM_LANES_COMPARE(gt, x > b)
PKM_LANES_COMPARE(not_ge, !(x >= b))
PKM_LANES_COMPARE(not_le, !(x <= b))
#undef PKM_LANES_COMPARE

PKM_LANES_INLINE Mask either(const Mask& a, const Mask& b) {
  Mask m;
  for (int i = 0; i < kWidth; ++i) m.v[i] = a.v[i] || b.v[i];
  return m;
}
PKM_LANES_INLINE bool lane(const Mask& m, int i) { return m.v[i]; }
PKM_LANES_INLINE bool any(const Mask& m) { return m.v[0] || m.v[1] || m.v[2] || m.v[3]; }

PKM_LANES_INLINE Pack select(const Mask& m, const Pack& a, double b) {
  Pack r;
  for (int i = 0; i < kWidth; ++i) r.v[i] = m.v[i] ? a.v[i] : b;
  return r;
}
PKM_LANES_INLINE Pack zero_where(const Mask& m, const Pack& x) {
  Pack r;
  for (int i = 0; i < kWidth; ++i) r.v[i] = m.v[i] ? 0.0 : x.v[i];
  return r;
}

PKM_LANES_INLINE Pack abs(const Pack& x) {
  Pack r;
  for (int i = 0; i < kWidth; ++i) r.v[i] = std::fabs(x.v[i]);
  return r;
}

PKM_LANES_INLINE Pack sqrt(const Pack& x) {
  Pack r;
  for (int i = 0; i < kWidth; ++i) r.v[i] = std::sqrt(x.v[i]);
  return r;
}

#endif

// The same functions for one lane (T = double).
PKM_LANES_INLINE double lane(double v, int) { return v; }
PKM_LANES_INLINE bool lt(double a, double b) { return a < b; }
PKM_LANES_INLINE bool gt(double a, double b) { return a > b; }
PKM_LANES_INLINE bool not_ge(double a, double b) { return !(a >= b); }
PKM_LANES_INLINE bool not_le(double a, double b) { return !(a <= b); }
PKM_LANES_INLINE bool either(bool a, bool b) { return a || b; }
PKM_LANES_INLINE bool lane(bool m, int) { return m; }
PKM_LANES_INLINE bool any(bool m) { return m; }
PKM_LANES_INLINE double select(bool m, double a, double b) { return m ? a : b; }
PKM_LANES_INLINE double zero_where(bool m, double x) { return m ? 0.0 : x; }
PKM_LANES_INLINE double abs(double x) { return std::fabs(x); }
PKM_LANES_INLINE double sqrt(double x) { return std::sqrt(x); }

/// Whether this x86-64 processor and its operating system run AVX (CPUID's
/// AVX and OSXSAVE bits, XCR0's XMM and YMM state): asked once per model
/// (make_model), so no static data of our own holds it. Out of line, so
/// that a caller's registers stay clear of CPUID's.
#if PKM_LANES_VECTOR_EXTENSIONS
__attribute__((noinline, cold))
#endif
inline bool cpu_runs_avx() {
#if PKM_LANES_VECTOR_EXTENSIONS && defined(__x86_64__)
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (!__get_cpuid(1, &a, &b, &c, &d)) return false;
  if (!(c & bit_OSXSAVE) || !(c & bit_AVX)) return false;
  unsigned lo = 0, hi = 0;
  __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0u));
  (void)hi;
  return (lo & 6u) == 6u;
#else
  return false;
#endif
}

/// The compiled copies of a lane kernel, one template each: Scalar (one leg
/// at a time, T = double, where the kernel has that instance), Baseline (the
/// four legs as lanes in the baseline instruction set: SSE2 pairs on x86-64,
/// NEON on aarch64, the plain struct elsewhere), Avx (one AVX register, where
/// PKM_LANES_AVX_DISPATCH). Best is Avx where the model's processor runs it
/// (Model::avx), else Baseline. Every copy gives the same bits.
enum class Kernel { Best, Scalar, Baseline, Avx };

/// The copy that runs for `kind`: Best resolved (Avx where `model_avx`,
/// Model::avx, and the build has it, else Baseline); false where that copy
/// is missing (Scalar of a kernel without one; Avx where the build or the
/// processor has none). The one place a lane kernel's copy is chosen.
PKM_LANES_INLINE bool resolve(Kernel kind, bool model_avx, bool has_scalar, Kernel& copy) {
  if (kind == Kernel::Best) {  // first: the product's every call
    copy = PKM_LANES_AVX_DISPATCH && model_avx ? Kernel::Avx : Kernel::Baseline;
    return true;
  }
  copy = kind;
  if (kind == Kernel::Scalar) return has_scalar;
  if (kind == Kernel::Avx) return PKM_LANES_AVX_DISPATCH && cpu_runs_avx();
  return kind == Kernel::Baseline;
}

/// A kernel's compiled copies: `body` (one PKM_LANES_INLINE function of
/// the legs as lanes) compiled for the baseline instruction set and, where
/// PKM_LANES_AVX_DISPATCH, for AVX (no FMA: no contraction, the same bits).
template <class Fn, Fn* body>
struct Copies;
template <class R, class... A, R (*body)(A...)>
struct Copies<R(A...), body> {
  static R baseline(A... a) { return body(a...); }
#if PKM_LANES_AVX_DISPATCH
  PKM_LANES_AVX_TARGET static R avx(A... a) { return body(a...); }
#endif
};

/// Runs the copy of a kernel (K: its Copies; kScalar: its one-leg copy, a
/// function of the same signature, or nullptr) that resolve() picks for
/// `kind`, calling it directly; `missing` where that copy is missing.
template <class K, auto kScalar = nullptr, class R, class... Args>
PKM_LANES_INLINE R run(Kernel kind, bool model_avx, R missing, Args&&... args) {
  Kernel copy = Kernel::Baseline;
  if (!resolve(kind, model_avx, !std::is_null_pointer_v<decltype(kScalar)>, copy)) return missing;
#if PKM_LANES_AVX_DISPATCH
  if (copy == Kernel::Avx) return K::avx(std::forward<Args>(args)...);
#endif
  if constexpr (!std::is_null_pointer_v<decltype(kScalar)>) {
    if (copy == Kernel::Scalar) return kScalar(std::forward<Args>(args)...);
  }
  return K::baseline(std::forward<Args>(args)...);
}

/// T's number of lanes and its broadcast constant.
template <class T> struct Traits;
template <> struct Traits<double> {
  static constexpr int width = 1;
  static PKM_LANES_INLINE double constant(double x) { return x; }
};
template <> struct Traits<Pack> {
  static constexpr int width = kWidth;
  static PKM_LANES_INLINE Pack constant(double x) { return broadcast(x); }
};

}  // namespace pkm::lanes
