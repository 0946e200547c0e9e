// pkm_bench: timing figures of the 4-PUU core. It prints a table; it is not
// a test (no pass/fail exit code for the timings; targets are shown for
// context only).
//
//   1. one forward-dynamics state derivative, for the three formulations;
//   2. one inverse-dynamics solve, cold (closed-form start) and warm-started;
//   3. the 2-s auto-test with RK4 at 1 ms, forward only (forces tabulated
//      beforehand) and round trip (inverse dynamics at every stage), then
//      the same with CVODE;
//   4. heap allocations inside time steps (counting operator new, and on
//      glibc the whole malloc family).
//
// Timing: std::chrono::steady_clock; every figure is the median (and the
// minimum) of 31 batches. A batch is N calls, N chosen so that a batch lasts
// a few milliseconds; whole runs (item 3) are timed one run per batch.
//
// To find where an allocation comes from: run under gdb with
//   break pkm_bench_alloc_event
// (it is called for every allocation while a counting window is open).
#include <sys/utsname.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include <sundials/sundials_config.h>

#include "autotest.hpp"
#include "inverse_dynamics.hpp"
#include "inverse_dynamics_derivatives.hpp"
#include "lagrangian.hpp"
#include "minimal_state.hpp"
#include "plant.hpp"
#include "reduced_dynamics_derivatives.hpp"
#include "servo_kinematics.hpp"
#include "trajectory.hpp"

// ---------------------------------------------------------------------------
// Allocation counting
// ---------------------------------------------------------------------------

namespace alloc_count {
std::atomic<long> news{0};      // operator new / new[], every variant
std::atomic<long> mallocs{0};   // malloc family (includes the ones behind operator new)
std::atomic<bool> armed{false};  // a counting window is open: call the breakpoint hook
}  // namespace alloc_count

// A place for a gdb breakpoint; called for each allocation while armed.
extern "C" __attribute__((noinline)) void pkm_bench_alloc_event(std::size_t bytes) {
  asm volatile("" : : "r"(bytes) : "memory");
}

namespace {
inline void note_alloc(std::atomic<long>& counter, std::size_t bytes) {
  counter.fetch_add(1, std::memory_order_relaxed);
  if (alloc_count::armed.load(std::memory_order_relaxed)) pkm_bench_alloc_event(bytes);
}
}  // namespace

#if defined(__GLIBC__) && !defined(PKM_BENCH_NO_MALLOC_HOOK)
// glibc: interpose the C allocation functions (the executable's definitions
// take precedence for every library in the process) and forward to glibc's
// own. This also sees allocations that never pass through operator new
// (Eigen's dynamic storage, SUNDIALS, libc).
#define PKM_BENCH_MALLOC_HOOK 1
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) noexcept {
  note_alloc(alloc_count::mallocs, n);
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) noexcept {
  note_alloc(alloc_count::mallocs, k * n);
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) noexcept {
  note_alloc(alloc_count::mallocs, n);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t al, std::size_t n) noexcept {
  note_alloc(alloc_count::mallocs, n);
  return __libc_memalign(al, n);
}
void* aligned_alloc(std::size_t al, std::size_t n) noexcept {
  note_alloc(alloc_count::mallocs, n);
  return __libc_memalign(al, n);
}
int posix_memalign(void** out, std::size_t al, std::size_t n) noexcept {
  if (al == 0 || (al & (al - 1)) != 0 || al % sizeof(void*) != 0) return EINVAL;
  note_alloc(alloc_count::mallocs, n);
  void* p = __libc_memalign(al, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}  // extern "C"
#else
#define PKM_BENCH_MALLOC_HOOK 0
#endif

namespace {
void* counted_new(std::size_t n) {
  note_alloc(alloc_count::news, n);
  return std::malloc(n ? n : 1);
}
void* counted_new_aligned(std::size_t n, std::align_val_t al) {
  note_alloc(alloc_count::news, n);
  std::size_t a = static_cast<std::size_t>(al);
  if (a < sizeof(void*)) a = sizeof(void*);
  void* p = nullptr;
  if (posix_memalign(&p, a, n ? n : 1) != 0) return nullptr;
  return p;
}
}  // namespace

void* operator new(std::size_t n) {
  if (void* p = counted_new(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = counted_new(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted_new(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted_new(n); }
void* operator new(std::size_t n, std::align_val_t al) {
  if (void* p = counted_new_aligned(n, al)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t al) {
  if (void* p = counted_new_aligned(n, al)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_new_aligned(n, al);
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_new_aligned(n, al);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

namespace {

using pkm::Formulation;
using pkm::Pose;
using pkm::Status;
using pkm::Vec16;
using pkm::Vec4;
using pkm::Vec8;
using pkm::Wrench;
using Clock = std::chrono::steady_clock;

volatile double g_sink = 0;  // results go here so no call is optimised away

// Counts allocations between construction and stop(); opens the gdb window.
class AllocWindow {
 public:
  AllocWindow() {
    news0_ = alloc_count::news.load();
    mallocs0_ = alloc_count::mallocs.load();
    alloc_count::armed.store(true);
  }
  void stop() {
    alloc_count::armed.store(false);
    news_ = alloc_count::news.load() - news0_;
    mallocs_ = alloc_count::mallocs.load() - mallocs0_;
  }
  long news() const { return news_; }
  long mallocs() const { return mallocs_; }

 private:
  long news0_ = 0, mallocs0_ = 0, news_ = 0, mallocs_ = 0;
};

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Figure {
  double median = NAN;  // s per call
  double min = NAN;
  long per_batch = 0;
  int batches = 0;
};

Figure summarise(std::vector<double> v, long per_batch) {
  Figure f;
  if (v.empty()) return f;
  std::sort(v.begin(), v.end());
  f.median = v[v.size() / 2];
  f.min = v.front();
  f.per_batch = per_batch;
  f.batches = static_cast<int>(v.size());
  return f;
}

/// Per-call time of body(): N calls per batch (N calibrated so that a batch
/// lasts at least target_s), `batches` batches.
template <class Body>
Figure time_per_call(Body&& body, int batches = 31, double target_s = 4e-3) {
  long n = 1;
  for (;;) {
    const auto t0 = Clock::now();
    for (long k = 0; k < n; ++k) body();
    const double dt = seconds(Clock::now() - t0);
    if (dt >= target_s || n >= (1L << 26)) break;
    const double grow = dt > 0 ? std::min(10.0, std::max(2.0, 1.2 * target_s / dt)) : 10.0;
    n = static_cast<long>(std::ceil(static_cast<double>(n) * grow));
  }
  std::vector<double> per_call;
  per_call.reserve(static_cast<size_t>(batches));
  for (int b = 0; b < batches; ++b) {
    const auto t0 = Clock::now();
    for (long k = 0; k < n; ++k) body();
    per_call.push_back(seconds(Clock::now() - t0) / static_cast<double>(n));
  }
  return summarise(std::move(per_call), n);
}

/// Whole runs: run() returns the seconds it measured itself (set-up kept
/// outside); repeated up to `max_runs` times or until about `budget_s` of
/// wall time is spent (at least `min_runs`).
template <class Run>
Figure time_runs(Run&& run, int max_runs = 31, int min_runs = 5, double budget_s = 6.0) {
  std::vector<double> v;
  const auto start = Clock::now();
  run();  // warm-up (caches, page faults, lazy binding)
  for (int r = 0; r < max_runs; ++r) {
    const double s = run();
    if (!(s >= 0)) break;  // failed
    v.push_back(s);
    if (r + 1 >= min_runs && seconds(Clock::now() - start) > budget_s) break;
  }
  return summarise(std::move(v), 1);
}

std::string fmt_time(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "n/a";
  if (s < 1e-6) std::snprintf(buf, sizeof buf, "%.0f ns", s * 1e9);
  else if (s < 1e-3) std::snprintf(buf, sizeof buf, "%.3f us", s * 1e6);
  else if (s < 1.0) std::snprintf(buf, sizeof buf, "%.3f ms", s * 1e3);
  else std::snprintf(buf, sizeof buf, "%.3f s", s);
  return buf;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto c = line.find(':');
      if (c != std::string::npos) return line.substr(c + 2);
    }
  }
  return "unknown CPU";
}

void rule() {
  std::printf("------------------------------------------------------------------------------------------------\n");
}

// --- inputs ---------------------------------------------------------------

/// Forces tabulated at t_j = j * dt (j = 0..n-1), looked up exactly by
/// index round(t / dt).
struct ForceTable {
  double dt = 0.5e-3;
  std::vector<Vec4> F;
  long misses = 0;  // lookups off the table (would mean a stage time off the grid)
  pkm::InputSignal signal() { return {&ForceTable::eval, this}; }
  static void eval(void* user, double t, Vec4& F, Wrench& we) {
    auto* tb = static_cast<ForceTable*>(user);
    const double x = t / tb->dt;
    long j = std::lround(x);
    if (std::fabs(x - static_cast<double>(j)) > 1e-6) ++tb->misses;
    j = std::clamp(j, 0L, static_cast<long>(tb->F.size()) - 1);
    F = tb->F[static_cast<size_t>(j)];
    we.setZero();
  }
};

const char* ok_mark(double value, double target) { return value <= target ? "ok" : "OVER"; }

}  // namespace

int main() {
  // ---------------------------------------------------------------- set-up
  pkm::Model model;
  std::string why;
  if (pkm::make_model(pkm::Params{}, model, &why) != Status::Ok) {
    std::fprintf(stderr, "make_model failed: %s\n", why.c_str());
    return 1;
  }
  const pkm::RestToRest path;
  const double T = path.duration;
  const double h = 1e-3;  // RK4 step and output interval
  const long n_out = std::lround(T / h);  // 2000 one-ms calls
  int failures = 0;

  utsname un{};
  uname(&un);
#ifdef PKM_BENCH_BUILD_TYPE
  const char* build_type = PKM_BENCH_BUILD_TYPE;
#else
  const char* build_type = "unknown";
#endif
#ifdef NDEBUG
  const char* ndebug = "NDEBUG";
#else
  const char* ndebug = "asserts ON";
#endif

  rule();
  std::printf("pkm_bench  machine: %s, %u hardware threads (%s)\n", un.machine,
              std::thread::hardware_concurrency(), cpu_model().c_str());
  std::printf("           build: %s (%s), %s %s, Eigen %d.%d.%d, SUNDIALS %s\n", build_type, ndebug,
#if defined(__clang__)
              "clang",
#else
              "gcc",
#endif
              __VERSION__, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, SUNDIALS_VERSION);
  std::printf("           timing: steady_clock; median and min over 31 batches of N calls (N: a batch >= 4 ms)\n");
  std::printf("           allocation counter: operator new (all variants)%s\n",
              PKM_BENCH_MALLOC_HOOK ? " + malloc family (glibc interposition)" : "");
  rule();

  // The state of items 1-2: the auto-test path at t = 1 s.
  const double t_mid = 1.0;
  Pose p, pd, pdd;
  path.eval(t_mid, p, pd, pdd);
  pkm::InverseDynamicsResult id_mid;
  if (pkm::inverse_dynamics(model, p, pd, pdd, Wrench::Zero(), id_mid, false) != Status::Ok) {
    std::fprintf(stderr, "inverse dynamics failed at t = 1 s\n");
    return 1;
  }
  Vec8 y_mid;
  y_mid << p, pd;
  const Vec16 f_mid = pkm::generalized_forces(id_mid.F, Wrench::Zero());

  // ------------------------------------------------------- 1. state derivative
  const Formulation forms[3] = {Formulation::LegPartitioned, Formulation::NullSpaceQR,
                                Formulation::Augmented};
  const char* const form_names[3] = {"LegPartitioned", "NullSpaceQR", "Augmented"};
  Figure sd[3];
  double sd_acc_err[3] = {0, 0, 0};  // |pdd - prescribed| at the unperturbed state (sanity)
  for (int i = 0; i < 3; ++i) {
    Vec8 yk = y_mid, ydot;
    long k = 0;
    double acc = 0;
    Status bad = Status::Ok;
    sd[i] = time_per_call([&] {
      yk[0] = y_mid[0] + 1e-12 * static_cast<double>(k++ & 1023);
      const Status s = pkm::state_derivative(model, forms[i], yk, f_mid, ydot);
      if (s != Status::Ok) bad = s;
      acc += ydot[4] + ydot[7];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! state_derivative(%s) failed: %s\n", form_names[i],
                  pkm::status_name(bad));
      ++failures;
    }
    if (pkm::state_derivative(model, forms[i], y_mid, f_mid, ydot) == Status::Ok)
      sd_acc_err[i] = (ydot.tail<4>() - pdd).lpNorm<Eigen::Infinity>();
  }
  std::printf("1. Forward dynamics: one pkm::state_derivative at t = %.3f s of the auto-test path\n", t_mid);
  std::printf("   (y = path pose and velocity, f = inverse-dynamics forces there; y[0] += 1e-12*(k%%1024) per call)\n");
  std::printf("   %-16s %12s %12s %10s %9s %16s %13s\n", "formulation", "median/call", "min/call", "N/batch",
              "vs LegP", "target", "|pdd-path|");
  for (int i = 0; i < 3; ++i) {
    char target[32] = "";
    if (i == 0) std::snprintf(target, sizeof target, "<= 1 us  %s", ok_mark(sd[0].median, 1e-6));
    std::printf("   %-16s %12s %12s %10ld %8.2fx %16s %13.2e\n", form_names[i],
                fmt_time(sd[i].median).c_str(), fmt_time(sd[i].min).c_str(), sd[i].per_batch,
                sd[i].median / sd[0].median, target, sd_acc_err[i]);
  }
  rule();

  // ----------------------------------------- 1b. analytic derivatives (issue 13)
  // The full Jacobian of the state derivative, A (8x8) and B (8x12), and the
  // inverse dynamics' dF/d(p, pd, pdd, we), each against its own value
  // measured here in the same run: one state_derivative (LegPartitioned,
  // item 1's figure) and one cold inverse_dynamics. Central differences
  // would need 24 state derivatives for A and B.
  Figure jac, sd_same, idd, id_plain;
  {
    Vec8 yk = y_mid, ydot;
    pkm::Mat8 A;
    pkm::Mat8x12 B;
    long k = 0;
    double acc = 0;
    Status bad = Status::Ok;
    const Vec4 tau0 = Vec4::Zero();
    jac = time_per_call([&] {
      yk[0] = y_mid[0] + 1e-12 * static_cast<double>(k++ & 1023);
      const Status s =
          pkm::state_derivative_jacobians(model, yk, id_mid.F, tau0, Wrench::Zero(), pkm::kStopsFromState, ydot, A, B);
      if (s != Status::Ok) bad = s;
      acc += A(4, 0) + B(7, 3);
    });
    sd_same = time_per_call([&] {  // the baseline again, right beside it
      yk[0] = y_mid[0] + 1e-12 * static_cast<double>(k++ & 1023);
      const Status s = pkm::state_derivative(model, Formulation::LegPartitioned, yk, f_mid, ydot);
      if (s != Status::Ok) bad = s;
      acc += ydot[4];
    });
    pkm::InverseDynamicsPartials d;
    pkm::InverseDynamicsResult r;
    Pose pk = p;
    idd = time_per_call([&] {
      pk[0] = p[0] + 1e-12 * static_cast<double>(k++ & 1023);
      const Status s = pkm::inverse_dynamics_derivatives(model, pk, pd, pdd, Wrench::Zero(), d);
      if (s != Status::Ok) bad = s;
      acc += d.dp(0, 0);
    });
    id_plain = time_per_call([&] {
      pk[0] = p[0] + 1e-12 * static_cast<double>(k++ & 1023);
      const Status s = pkm::inverse_dynamics(model, pk, pd, pdd, Wrench::Zero(), r, false);
      if (s != Status::Ok) bad = s;
      acc += r.F[0];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! derivatives failed: %s\n", pkm::status_name(bad));
      ++failures;
    }
  }
  const double jac_ratio = jac.median / sd_same.median;
  std::printf("1b. Analytic derivatives at the same state (reduced_dynamics_derivatives.hpp)\n");
  std::printf("   %-44s %12s %12s %10s %16s\n", "evaluation", "median/call", "min/call", "ratio", "target");
  std::printf("   %-44s %12s %12s %10s\n", "state_derivative (LegPartitioned, baseline)",
              fmt_time(sd_same.median).c_str(), fmt_time(sd_same.min).c_str(), "1.00x");
  std::printf("   %-44s %12s %12s %9.2fx %16s\n", "state_derivative_jacobians: ydot, A 8x8, B 8x12",
              fmt_time(jac.median).c_str(), fmt_time(jac.min).c_str(), jac_ratio,
              (std::string("<= 3x  ") + ok_mark(jac_ratio, 3.0)).c_str());
  std::printf("   %-44s %12s %12s %9.2fx\n", "  (central differences: 24 state derivatives)", "", "", 24.0);
  std::printf("   %-44s %12s %12s %10s\n", "inverse_dynamics (cold, baseline)", fmt_time(id_plain.median).c_str(),
              fmt_time(id_plain.min).c_str(), "1.00x");
  std::printf("   %-44s %12s %12s %9.2fx\n", "inverse_dynamics_derivatives: F, dF 4x16", fmt_time(idd.median).c_str(),
              fmt_time(idd.min).c_str(), idd.median / id_plain.median);
  rule();

  // ------------------------------------------------------- 2. inverse dynamics
  // The points: the stage-time grid of the auto-test, t_j = j * h/2, j = 0..4000.
  const double half_h = 0.5 * h;
  const long n_grid = 2 * n_out + 1;  // 4001
  std::vector<Pose> gp(static_cast<size_t>(n_grid)), gpd(gp.size()), gpdd(gp.size());
  for (long j = 0; j < n_grid; ++j)
    path.eval(static_cast<double>(j) * half_h, gp[static_cast<size_t>(j)], gpd[static_cast<size_t>(j)],
              gpdd[static_cast<size_t>(j)]);
  Figure id_cold, id_warm;
  {
    pkm::InverseDynamicsResult r;
    long j = 0;
    double acc = 0;
    Status bad = Status::Ok;
    id_cold = time_per_call([&] {
      const size_t u = static_cast<size_t>(j);
      j = (j + 1) % n_grid;
      const Status s = pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, false);
      if (s != Status::Ok) bad = s;
      acc += r.F[0];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! inverse_dynamics (cold) failed: %s\n", pkm::status_name(bad));
      ++failures;
    }
  }
  {
    // Ping-pong along the grid so that every warm start is the neighbour 0.5 ms away.
    pkm::InverseDynamicsResult r;
    long j = 0, dir = 1;
    double acc = 0;
    Status bad = pkm::inverse_dynamics(model, gp[0], gpd[0], gpdd[0], Wrench::Zero(), r, false);
    id_warm = time_per_call([&] {
      if (j + dir < 0 || j + dir >= n_grid) dir = -dir;
      j += dir;
      const size_t u = static_cast<size_t>(j);
      const Status s = pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, true);
      if (s != Status::Ok) bad = s;
      acc += r.F[0];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! inverse_dynamics (warm) failed: %s\n", pkm::status_name(bad));
      ++failures;
    }
  }
  Figure id_same, id_stages;
  {
    // Warm start from the same point again (RK4 asks twice at t + h/2 and at
    // t + h): the point t = 1 s over and over, seeded once.
    pkm::InverseDynamicsResult r;
    const size_t u = static_cast<size_t>(n_out);
    double acc = 0;
    Status bad = pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, false);
    id_same = time_per_call([&] {
      const Status s = pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, true);
      if (s != Status::Ok) bad = s;
      acc += r.F[0];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! inverse_dynamics (warm, same point) failed: %s\n", pkm::status_name(bad));
      ++failures;
    }
  }
  {
    // The RK4 round trip's sequence of stage times (what PathForces sees):
    // t_k, t_k + h/2, t_k + h/2, t_k + h, then t_k + h again as the next step's
    // first stage: grid indices 2k, 2k+1, 2k+1, 2k+2, 2k+2, 2k+3, ...
    pkm::InverseDynamicsResult r;
    long c = 0;
    double acc = 0;
    Status bad = pkm::inverse_dynamics(model, gp[0], gpd[0], gpdd[0], Wrench::Zero(), r, false);
    id_stages = time_per_call([&] {
      const long m = c % (4 * n_out);  // one pass over the 2 s = 4 * 2000 calls
      ++c;
      const long step = m / 4, stage = m % 4;
      const long j = 2 * step + (stage == 0 ? 0 : stage == 3 ? 2 : 1);
      const size_t u = static_cast<size_t>(j);
      // at the wrap (back to t = 0) the start is far: take the closed form there
      const Status s = pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, m != 0);
      if (s != Status::Ok) bad = s;
      acc += r.F[0];
    });
    g_sink = acc;
    if (bad != Status::Ok) {
      std::printf("  !! inverse_dynamics (stage sequence) failed: %s\n", pkm::status_name(bad));
      ++failures;
    }
  }
  // Newton iterations at t = 1 s: from the closed form, and from the grid neighbour.
  int it_cold = -1, it_warm = -1;
  {
    const size_t mid = static_cast<size_t>(n_out);  // t = 1 s
    Vec16 q;
    pkm::NewtonReport rep;
    if (pkm::closed_form_position(model, gp[mid], q) == Status::Ok &&
        pkm::solve_position(model, gp[mid], q, {}, &rep) == Status::Ok)
      it_cold = rep.iterations;
    if (pkm::closed_form_position(model, gp[mid - 1], q) == Status::Ok &&
        pkm::solve_position(model, gp[mid - 1], q) == Status::Ok &&
        pkm::solve_position(model, gp[mid], q, {}, &rep) == Status::Ok)
      it_warm = rep.iterations;
  }
  std::printf("2. Inverse dynamics: one pkm::inverse_dynamics on the stage-time grid (t = j*0.5 ms, 4001 points)\n");
  std::printf("   %-34s %12s %12s %10s %12s %8s\n", "start", "median/call", "min/call", "N/batch", "vs sd(LegP)",
              "Newton it");
  std::printf("   %-34s %12s %12s %10ld %11.2fx %8d\n", "cold (closed-form start)", fmt_time(id_cold.median).c_str(),
              fmt_time(id_cold.min).c_str(), id_cold.per_batch, id_cold.median / sd[0].median, it_cold);
  std::printf("   %-34s %12s %12s %10ld %11.2fx %8d\n", "warm (previous point, 0.5 ms away)",
              fmt_time(id_warm.median).c_str(), fmt_time(id_warm.min).c_str(), id_warm.per_batch,
              id_warm.median / sd[0].median, it_warm);
  std::printf("   %-34s %12s %12s %10ld %11.2fx %8d\n", "warm (the same point again)",
              fmt_time(id_same.median).c_str(), fmt_time(id_same.min).c_str(), id_same.per_batch,
              id_same.median / sd[0].median, 0);
  std::printf("   %-34s %12s %12s %10ld %11.2fx %8s\n", "warm, RK4 stage sequence [**]",
              fmt_time(id_stages.median).c_str(), fmt_time(id_stages.min).c_str(), id_stages.per_batch,
              id_stages.median / sd[0].median, "2/0");
  std::printf("   (Newton it = iterations of solve_position at t = 1 s, residual tolerance 1e-14)\n");
  std::printf("   [**] t_k, t_k+h/2, t_k+h/2, t_k+h, t_k+h, ... as PathForces sees them in the RK4 round trip:\n");
  std::printf("        every other call is a repeat of the previous point.\n");
  rule();

  // ------------------------------------------------------- 3. the 2-s auto-test
  // Forces on the stage-time grid, by warm-started inverse dynamics (as PathForces does).
  ForceTable table;
  table.dt = half_h;
  table.F.resize(static_cast<size_t>(n_grid));
  {
    pkm::InverseDynamicsResult r;
    for (long j = 0; j < n_grid; ++j) {
      const size_t u = static_cast<size_t>(j);
      if (pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, j > 0) != Status::Ok) {
        std::fprintf(stderr, "inverse dynamics failed at t = %g s\n", static_cast<double>(j) * half_h);
        return 1;
      }
      table.F[u] = r.F;
    }
  }
  Pose p0, pd0, pdd0;
  path.eval(0.0, p0, pd0, pdd0);

  // Error of a recorded trajectory (one pose per ms) against the path.
  auto max_error = [&](const std::vector<Pose>& traj) {
    double e = 0;
    for (long k = 0; k <= n_out; ++k) {
      Pose q, qd, qdd;
      path.eval(static_cast<double>(k) * h, q, qd, qdd);
      e = std::max(e, (traj[static_cast<size_t>(k)] - q).head<3>().lpNorm<Eigen::Infinity>());
    }
    return e;
  };

  struct RunInfo {
    Figure fig;
    long rhs = 0;
    double err = NAN;  // max |x,y,z - path| over the 1-ms samples, m
    std::string note;
  };

  // Forward only: Plant::advance over 2 s in 1-ms calls; Plant built and
  // initialised outside the timing; CVODE objects are created by the first
  // advance (inside the timing).
  // `at_rest`: the error is taken against P0 (held forces) instead of the path.
  auto forward_run = [&](const pkm::SolverSettings& st, pkm::InputSignal input, bool record_continuous,
                         bool at_rest) {
    RunInfo info;
    std::vector<Pose> traj(static_cast<size_t>(n_out) + 1);
    Status bad = Status::Ok;
    info.fig = time_runs([&]() -> double {
      pkm::Plant plant(model);
      if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, p0, pd0) != Status::Ok) return -1;
      traj[0] = plant.state().head<4>();
      const auto t0 = Clock::now();
      for (long k = 1; k <= n_out; ++k) {
        const Status s = plant.advance(static_cast<double>(k) * h, input, record_continuous && k > 1);
        if (s != Status::Ok) {
          bad = s;
          return -1;
        }
        traj[static_cast<size_t>(k)] = plant.state().head<4>();
      }
      const double dt = seconds(Clock::now() - t0);
      info.rhs = plant.rhs_evaluations();
      return dt;
    });
    if (bad != Status::Ok) {
      info.note = std::string("FAILED: ") + pkm::status_name(bad);
      ++failures;
    }
    if (at_rest) {
      info.err = 0;
      for (const Pose& q : traj) info.err = std::max(info.err, (q - p0).head<3>().lpNorm<Eigen::Infinity>());
    } else {
      info.err = max_error(traj);
    }
    return info;
  };

  // Round trip, bare: Plant::advance with PathForces (inverse dynamics at
  // every stage time), no sampling work.
  auto bare_round_trip = [&](const pkm::SolverSettings& st) {
    RunInfo info;
    std::vector<Pose> traj(static_cast<size_t>(n_out) + 1);
    Status bad = Status::Ok;
    info.fig = time_runs([&]() -> double {
      pkm::Plant plant(model);
      pkm::PathForces forces;
      forces.model = &model;
      forces.path = path;
      const pkm::InputSignal input = forces.signal();
      if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, p0, pd0) != Status::Ok) return -1;
      traj[0] = plant.state().head<4>();
      const auto t0 = Clock::now();
      for (long k = 1; k <= n_out; ++k) {
        const Status s = plant.advance(static_cast<double>(k) * h, input, k > 1);
        if (s != Status::Ok || forces.status != Status::Ok) {
          bad = s != Status::Ok ? s : forces.status;
          return -1;
        }
        traj[static_cast<size_t>(k)] = plant.state().head<4>();
      }
      const double dt = seconds(Clock::now() - t0);
      info.rhs = plant.rhs_evaluations();
      return dt;
    });
    if (bad != Status::Ok) {
      info.note = std::string("FAILED: ") + pkm::status_name(bad);
      ++failures;
    }
    info.err = max_error(traj);
    return info;
  };

  // Round trip: pkm::run_autotest as a whole (includes its 2001 samples:
  // mechanism state, constraint residual, Jacobian condition).
  auto autotest_run = [&](const pkm::SolverSettings& st) {
    RunInfo info;
    Status bad = Status::Ok;
    std::string err;
    info.fig = time_runs([&]() -> double {
      pkm::AutotestOptions opt;
      opt.solver = st;
      opt.path = path;
      pkm::AutotestResult res;
      const auto t0 = Clock::now();
      const Status s = pkm::run_autotest(model, opt, res);
      const double dt = seconds(Clock::now() - t0);
      if (s != Status::Ok) {
        bad = s;
        err = res.error;
        return -1;
      }
      info.rhs = res.rhs_evaluations;
      info.err = res.max_position_error;
      return dt;
    });
    if (bad != Status::Ok) {
      info.note = std::string("FAILED: ") + pkm::status_name(bad) + " " + err;
      ++failures;
    }
    return info;
  };

  pkm::SolverSettings rk4;
  rk4.solver = pkm::Solver::Rk4;
  rk4.rk4_step = h;
  pkm::SolverSettings cv_tight;
  cv_tight.solver = pkm::Solver::Cvode;
  cv_tight.cvode_method = pkm::CvodeMethod::Adams;
  cv_tight.rtol = 1e-12;
  cv_tight.atol = 1e-14;
  pkm::SolverSettings cv_default = cv_tight;
  cv_default.rtol = 1e-8;
  cv_default.atol = 1e-10;

  // Static forces at the start (rest at P0), held constant.
  pkm::LinearInputs held;
  {
    pkm::InverseDynamicsResult r;
    if (pkm::inverse_dynamics(model, p0, Pose::Zero(), Pose::Zero(), Wrench::Zero(), r, false) != Status::Ok) {
      std::fprintf(stderr, "static forces failed\n");
      return 1;
    }
    held.F0 = r.F;
  }

  const RunInfo rk4_fwd = forward_run(rk4, table.signal(), false, false);
  const RunInfo rk4_bare = bare_round_trip(rk4);
  const RunInfo rk4_rt = autotest_run(rk4);
  const RunInfo cvt_fwd = forward_run(cv_tight, held.signal(), true, true);
  const RunInfo cvt_bare = bare_round_trip(cv_tight);
  const RunInfo cvt_rt = autotest_run(cv_tight);
  const RunInfo cvd_fwd = forward_run(cv_default, held.signal(), true, true);
  const RunInfo cvd_bare = bare_round_trip(cv_default);
  const RunInfo cvd_rt = autotest_run(cv_default);
  if (table.misses != 0) {
    std::printf("  !! %ld force-table lookups were off the stage-time grid\n", table.misses);
    ++failures;
  }

  std::printf("3. The 2-s auto-test (t = 0..2 s, 2000 Plant::advance calls of 1 ms; set-up outside the timing)\n");
  std::printf("   %-40s %10s %10s %5s %9s %7s %10s %s\n", "run", "median", "min", "runs", "RT factor", "rhs",
              "max|dxyz|m", "target / note");
  auto row = [&](const char* name, const RunInfo& r, const char* note) {
    const double rt = T / r.fig.median;
    std::printf("   %-40s %10s %10s %5d %8.0fx %7ld %10.2e %s%s\n", name, fmt_time(r.fig.median).c_str(),
                fmt_time(r.fig.min).c_str(), r.fig.batches, rt, r.rhs, r.err, note, r.note.c_str());
  };
  char rk4_target[48];
  std::snprintf(rk4_target, sizeof rk4_target, "<= 10 ms  %s", ok_mark(rk4_fwd.fig.median, 10e-3));
  row("RK4 1 ms  (a) forward only [table]", rk4_fwd, rk4_target);
  row("RK4 1 ms  (b) round trip, bare [*]", rk4_bare, "");
  row("RK4 1 ms  (b) round trip, run_autotest", rk4_rt, "");
  row("CVODE 1e-12/1e-14 (a') forward, held F", cvt_fwd, "held static F; error vs P0");
  row("CVODE 1e-12/1e-14 (b) round trip, bare", cvt_bare, "");
  row("CVODE 1e-12/1e-14 (b) run_autotest", cvt_rt, "");
  row("CVODE 1e-8/1e-10 (a') forward, held F", cvd_fwd, "held static F; error vs P0");
  row("CVODE 1e-8/1e-10 (b) round trip, bare", cvd_bare, "");
  row("CVODE 1e-8/1e-10 (b) run_autotest", cvd_rt, "");
  std::printf("   RT factor = 2 s simulated / wall time; rhs = state-derivative evaluations per run (RK4: 4 per step).\n");
  std::printf("   (a)  forces tabulated beforehand by inverse dynamics at the 4001 stage times j*0.5 ms, looked up\n");
  std::printf("        by index round(t/0.5 ms): the timing is forward dynamics + RK4 only.\n");
  std::printf("   (a') CVODE picks its own stage times, so no table is possible: the forward-only CVODE runs use\n");
  std::printf("        the static forces at P0 held constant (the platform stays at rest; a measure of CVODE's\n");
  std::printf("        per-call overhead with at least one step per 1-ms output, not of the path's dynamics).\n");
  std::printf("        Forward-only estimate for the path (derived, not measured): held-F time x round-trip rhs /\n");
  std::printf("        held-F rhs = %s (1e-12), %s (1e-8); of which derivatives (rhs x sd(LegP)) %s, %s.\n",
              fmt_time(cvt_fwd.fig.median * static_cast<double>(cvt_rt.rhs) / static_cast<double>(cvt_fwd.rhs)).c_str(),
              fmt_time(cvd_fwd.fig.median * static_cast<double>(cvd_rt.rhs) / static_cast<double>(cvd_fwd.rhs)).c_str(),
              fmt_time(static_cast<double>(cvt_rt.rhs) * sd[0].median).c_str(),
              fmt_time(static_cast<double>(cvd_rt.rhs) * sd[0].median).c_str());
  std::printf("        CVODE's steps are capped by the 1-ms output calls (stop time): ~1 step and ~1 rhs per call.\n");
  std::printf("   [*]  bare = Plant::advance with pkm::PathForces (inverse dynamics at every stage time), without\n");
  std::printf("        run_autotest's per-sample work (mechanism state, residual, Jacobian condition, static forces).\n");
  rule();

  // ------------------------------------------------------- 4. allocations
  std::printf("4. Heap allocations inside time steps (counted: operator new | malloc family incl. new)\n");
  std::printf("   %-62s %8s %8s  %s\n", "window", "new", "malloc", "expected");
  auto alloc_row = [&](const char* name, const AllocWindow& w, const char* expected, bool must_be_zero) {
    const bool zero = w.news() == 0 && (!PKM_BENCH_MALLOC_HOOK || w.mallocs() == 0);
    std::printf("   %-62s %8ld %8s  %s%s\n", name, w.news(),
                PKM_BENCH_MALLOC_HOOK ? std::to_string(w.mallocs()).c_str() : "n/a", expected,
                (must_be_zero && !zero) ? "  <-- NOT ZERO" : "");
  };
  // (i) state derivatives
  for (int i = 0; i < 3; ++i) {
    Vec8 yk = y_mid, ydot;
    double acc = 0;
    AllocWindow w;
    for (int k = 0; k < 1000; ++k) {
      yk[0] = y_mid[0] + 1e-12 * k;
      pkm::state_derivative(model, forms[i], yk, f_mid, ydot);
      acc += ydot[4];
    }
    w.stop();
    g_sink = acc;
    char name[96];
    std::snprintf(name, sizeof name, "(i) 1000 state_derivative, %s", form_names[i]);
    alloc_row(name, w, "0", true);
  }
  // inverse dynamics (context)
  {
    pkm::InverseDynamicsResult r;
    pkm::inverse_dynamics(model, gp[0], gpd[0], gpdd[0], Wrench::Zero(), r, false);
    AllocWindow w;
    for (long j = 1; j <= 1000; ++j) {
      const size_t u = static_cast<size_t>(j);
      pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, true);
    }
    w.stop();
    alloc_row("    1000 inverse_dynamics, warm", w, "0", true);
    AllocWindow w2;
    for (long j = 1; j <= 1000; ++j) {
      const size_t u = static_cast<size_t>(j);
      pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, false);
    }
    w2.stop();
    alloc_row("    1000 inverse_dynamics, cold", w2, "0", true);
  }
  // the analytic derivatives (item 1b)
  {
    Vec8 yk = y_mid, ydot;
    pkm::Mat8 A;
    pkm::Mat8x12 B;
    pkm::InverseDynamicsPartials d;
    double acc = 0;
    AllocWindow w;
    for (int k = 0; k < 1000; ++k) {
      yk[0] = y_mid[0] + 1e-12 * k;
      pkm::state_derivative_jacobians(model, yk, id_mid.F, Vec4::Zero(), Wrench::Zero(), pkm::kStopsFromState, ydot,
                                      A, B);
      pkm::inverse_dynamics_derivatives(model, yk.head<4>(), pd, pdd, Wrench::Zero(), d);
      acc += A(4, 0) + d.dp(0, 0);
    }
    w.stop();
    g_sink = acc;
    alloc_row("    1000 state_derivative_jacobians + inverse_dynamics_derivatives", w, "0", true);
  }
  // (ii) RK4 Plant::advance, 1 s in 1-ms calls, after initialisation
  auto plant_window = [&](const pkm::SolverSettings& st, pkm::InputSignal input, bool skip_first,
                          AllocWindow* out, Status* status) {
    pkm::Plant plant(model);
    *status = Status::Ok;
    if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, p0, pd0) != Status::Ok) {
      *status = Status::InvalidArgument;
      return;
    }
    long k = 1;
    if (skip_first) {
      *status = plant.advance(h, input, false);  // creates the CVODE objects
      ++k;
    }
    const long k_end = k + 999;  // 1000 calls = 1 s
    AllocWindow w;
    for (; k <= k_end && *status == Status::Ok; ++k)
      *status = plant.advance(static_cast<double>(k) * h, input, k > 1);
    w.stop();
    *out = w;
  };
  {
    AllocWindow w;
    Status s;
    plant_window(rk4, table.signal(), false, &w, &s);
    alloc_row("(ii) RK4 advance 0..1 s, 1000 calls, table forces", w, "0", true);
    if (s != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(s));
    pkm::PathForces forces;
    forces.model = &model;
    forces.path = path;
    plant_window(rk4, forces.signal(), false, &w, &s);
    alloc_row("     RK4 advance 0..1 s, 1000 calls, PathForces (round trip)", w, "0", true);
    if (s != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(s));
  }
  // (iii) CVODE, from the second call on
  {
    AllocWindow w;
    Status s;
    pkm::PathForces forces;
    forces.model = &model;
    forces.path = path;
    plant_window(cv_tight, forces.signal(), true, &w, &s);
    alloc_row("(iii) CVODE 1e-12 advance 1..1001 ms, 1000 calls, PathForces", w, "0 (no alloc in steps)", false);
    if (s != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(s));
    pkm::PathForces forces2;
    forces2.model = &model;
    forces2.path = path;
    plant_window(cv_default, forces2.signal(), true, &w, &s);
    alloc_row("      CVODE 1e-8 advance 1..1001 ms, 1000 calls, PathForces", w, "0 (no alloc in steps)", false);
    if (s != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(s));
    plant_window(cv_tight, held.signal(), true, &w, &s);
    alloc_row("      CVODE 1e-12 advance 1..1001 ms, 1000 calls, held forces", w, "0 (no alloc in steps)", false);
    if (s != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(s));
  }
  // Controls: windows that do allocate, to show that the counter sees them.
  {
    pkm::Plant plant(model);
    Status s = plant.set_solver(cv_tight);
    if (s == Status::Ok) s = plant.initialize(0.0, p0, pd0);
    AllocWindow w;
    if (s == Status::Ok) s = plant.advance(h, held.signal(), false);
    w.stop();
    alloc_row("control: CVODE first advance (creates the SUNDIALS objects)", w, "> 0", false);
    pkm::AutotestOptions opt;
    opt.solver = rk4;
    opt.path = path;
    pkm::AutotestResult res;
    AllocWindow w2;
    pkm::run_autotest(model, opt, res);
    w2.stop();
    alloc_row("control: one run_autotest, RK4 (samples vector, ...)", w2, "> 0", false);
  }
  rule();

  // ------------------------------------------------------- machine-independent ratios
  const double sd0 = sd[0].median;
  std::printf("Machine-independent ratios (medians)\n");
  std::printf("   sd(NullSpaceQR) / sd(LegPartitioned)                 %8.2f\n", sd[1].median / sd0);
  std::printf("   sd(Augmented)   / sd(LegPartitioned)                 %8.2f\n", sd[2].median / sd0);
  std::printf("   ID / sd(LegP): cold, warm 0.5 ms, same point, [**]   %8.2f %8.2f %8.2f %8.2f\n",
              id_cold.median / sd0, id_warm.median / sd0, id_same.median / sd0, id_stages.median / sd0);
  std::printf("   ID warm (0.5 ms away) / ID cold                      %8.2f\n", id_warm.median / id_cold.median);
  std::printf("   Jacobians A, B / sd(LegP) (same run, item 1b)        %8.2f   (target <= 3)\n", jac_ratio);
  std::printf("   RK4 forward run / (8000 x sd(LegP))                  %8.2f   (integrator + input overhead)\n",
              rk4_fwd.fig.median / (8000.0 * sd0));
  std::printf("   RK4 bare round trip / forward only                   %8.2f   (~ 1 + ID[**] / sd = %.2f)\n",
              rk4_bare.fig.median / rk4_fwd.fig.median, 1.0 + id_stages.median / sd0);
  std::printf("   RK4 run_autotest / forward only                      %8.2f\n", rk4_rt.fig.median / rk4_fwd.fig.median);
  std::printf("   CVODE rhs evaluations / RK4's 8000: 1e-12 %.2f, 1e-8 %.2f\n", static_cast<double>(cvt_rt.rhs) / 8000.0,
              static_cast<double>(cvd_rt.rhs) / 8000.0);
  std::printf("   CVODE run_autotest / RK4 run_autotest: 1e-12 %.2f, 1e-8 %.2f\n", cvt_rt.fig.median / rk4_rt.fig.median,
              cvd_rt.fig.median / rk4_rt.fig.median);
  std::printf("   targets: state derivative <= 1 us: %s (%s);  2-s RK4 forward run <= 10 ms: %s (%s)\n",
              ok_mark(sd0, 1e-6), fmt_time(sd0).c_str(), ok_mark(rk4_fwd.fig.median, 10e-3),
              fmt_time(rk4_fwd.fig.median).c_str());
  rule();
  if (failures) std::printf("%d measurement(s) FAILED (see the marks above)\n", failures);
  return failures ? 1 : 0;
}
