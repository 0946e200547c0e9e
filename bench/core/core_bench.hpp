// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench: what its parts (pkm_bench.cpp, ticks.cpp) share: how long each
// figure is measured, the loops that time them, the Plant's 1-ms steps.
#ifndef PKM_BENCH_CORE_BENCH_HPP
#define PKM_BENCH_CORE_BENCH_HPP

#include <algorithm>
#include <cmath>
#include <vector>

#include "pkm4puu/sim/plant.hpp"
#include "timer.h"

namespace pkm::bench {

/// How long each figure is measured: the defaults, or --quick.
struct Effort {
  int batches = 31;       // batches per per-call figure, runs per whole-run figure
  double batch_s = 4e-3;  // a per-call batch lasts at least this
  int tick_runs = 15;     // runs of a simulated second per tick row
};
extern Effort effort;

struct Figure {
  double median = NAN, min = NAN;  // s per call (per run)
  int batches = 0;
};

/// One warm-up run, then `runs` (fewer if one fails); run() returns the
/// seconds it measured itself (set-up kept outside), < 0 on failure.
template <class Run>
Figure time_runs(Run&& run, int runs = effort.batches) {
  std::vector<double> v;
  run();
  for (double s; static_cast<int>(v.size()) < runs && (s = run()) >= 0;) v.push_back(s);
  Figure f;
  if (!v.empty()) f.median = bench_median(v.data(), v.size(), &f.min), f.batches = static_cast<int>(v.size());
  return f;
}

constexpr double kTick = 1e-3;  // s, the communication step of the auto-test runs and the ticks
inline const Pose kHome(0, 0, 0.05, 0);

/// Solver settings: CVODE's defaults (Adams) but these, RK4 and ROS2 at the 1-ms step.
inline SolverSettings settings(Solver solver, double rtol = 1e-8, double atol = 1e-10,
                               CvodeMethod method = CvodeMethod::Adams) {
  SolverSettings st;
  st.solver = solver, st.rk4_step = kTick, st.rtol = rtol, st.atol = atol, st.cvode_method = method;
  return st;
}

struct StepRun {
  double seconds = 0;  // the steps' wall time, up to the first failing step included
  double us = NAN;     // timed_steps: the runs' median microseconds per step (the failing step included)
  Status status = Status::Ok;
  long ok_steps = 0, rhs = 0, rhs_max = 0, cvode_steps = 0;  // rhs_max: the most in one step
  std::vector<Vec8> states;                                  // pose and rates after each step, the initial first
};

/// n steps of the Plant from (p0, pd0), set up outside the timing: step(plant, k) advances it to step k's end.
template <class Step>
StepRun plant_steps(const Model& m, const SolverSettings& st, const Pose& p0, const Pose& pd0, long n, Step&& step) {
  StepRun r;
  Plant plant(m);
  r.status = plant.set_solver(st);
  if (r.status == Status::Ok) r.status = plant.initialize(0.0, p0, pd0);
  if (r.status != Status::Ok) return r;
  r.states.reserve(static_cast<size_t>(n) + 1);
  r.states.push_back(plant.state().head<8>());
  const double t0 = bench_now();
  for (; r.ok_steps < n; ++r.ok_steps) {
    const long before = plant.rhs_evaluations();
    if ((r.status = step(plant, r.ok_steps)) != Status::Ok) break;
    r.rhs_max = std::max(r.rhs_max, plant.rhs_evaluations() - before);
    r.states.push_back(plant.state().head<8>());
  }
  r.seconds = bench_now() - t0;
  r.rhs = plant.rhs_evaluations();
  r.cvode_steps = plant.cvode_steps();
  return r;
}

/// effort.tick_runs timed runs of n steps from the home pose at rest (plant_steps): the last run, with its `us`.
template <class Step>
StepRun timed_steps(const Model& m, const SolverSettings& st, long n, Step&& step) {
  StepRun r;
  const Figure f = time_runs([&] {
    r = plant_steps(m, st, kHome, Pose::Zero(), n, step);
    return r.seconds / static_cast<double>(std::min(r.ok_steps + 1, n));
  }, effort.tick_runs);
  r.us = 1e6 * f.median;
  return r;
}

int ticks_part(bool parseable);  // ticks.cpp

}  // namespace pkm::bench

#endif  // PKM_BENCH_CORE_BENCH_HPP
