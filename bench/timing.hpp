// SPDX-License-Identifier: BSD-2-Clause
// The timing of pkm_bench: per-call figures of short calls (batches of N
// calls, N calibrated) and of whole runs, each the median and the minimum of
// up to 31 batches; std::chrono::steady_clock.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace bench {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// How long each figure is measured: the defaults below, or a short run
/// (--quick: fewer and shorter batches, noisier medians, the same rows), as
/// the documentation build runs the benchmarks.
struct Effort {
  int batches = 31;          // batches per per-call figure
  double batch_s = 4e-3;     // a per-call batch lasts at least this
  int max_runs = 31;         // whole runs: at most, at least, and the wall-time budget
  int min_runs = 5;
  double runs_budget_s = 6.0;
};
inline Effort effort;
inline void set_quick() { effort = Effort{7, 2e-3, 7, 3, 1.0}; }

struct Figure {
  double median = NAN;  // s per call
  double min = NAN;
  long per_batch = 0;
  int batches = 0;
};

inline Figure summarise(std::vector<double> v, long per_batch) {
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
Figure time_per_call(Body&& body, int batches = effort.batches, double target_s = effort.batch_s) {
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
Figure time_runs(Run&& run, int max_runs = effort.max_runs, int min_runs = effort.min_runs,
                 double budget_s = effort.runs_budget_s) {
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

/// "123 ns", "1.234 us", "1.234 ms", "1.234 s".
inline std::string fmt_time(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "n/a";
  if (s < 1e-6) std::snprintf(buf, sizeof buf, "%.0f ns", s * 1e9);
  else if (s < 1e-3) std::snprintf(buf, sizeof buf, "%.3f us", s * 1e6);
  else if (s < 1.0) std::snprintf(buf, sizeof buf, "%.3f ms", s * 1e3);
  else std::snprintf(buf, sizeof buf, "%.3f s", s);
  return buf;
}

}  // namespace bench
