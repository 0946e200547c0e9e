/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench latency: the control tick's time, each tick timed on its own,
 * every batch the same simulated second from the home pose, so the minimum
 * over the batches of tick k is the model's own time for it (the spread above
 * it is the machine's). F: the holding force, plus on F[1] with RK4
 * 0.2 cos(2 pi 3 t) N held over each tick, with CVODE 0.2 t N as a ramp. */
#include "fmu_bench.h"

#define TICKS 1000 /* a batch: one simulated second */
#define H 1e-3

static double F[TICKS][4], dF[TICKS][4];

/* The median, p99, p99.9 and largest of sorted[0..n-1] (us); the p99.9 (max_ratio: the largest) over the median. */
static void quantiles(const char* name, const double* sorted, size_t n, int max_ratio) {
  const double median = bench_quantile(sorted, n, 0.5), p999 = bench_quantile(sorted, n, 0.999);
  printf("%-44s %9.3f %9.3f %9.3f %9.3f   %s %5.2f\n", name, 1e6 * median, 1e6 * bench_quantile(sorted, n, 0.99),
         1e6 * p999, 1e6 * sorted[n - 1], max_ratio ? "max/median  " : "p99.9/median",
         (max_ratio ? sorted[n - 1] : p999) / median);
}

static int run(const Plant* plant, int solver, int batches, double* ticks, const char* name) {
  fmi2FMUstate home = NULL;
  fmi2Component c = instantiate(plant, FMI2_CS, "latency", solver, 0, NULL, NULL, &home);
  double own[TICKS];
  const size_t n = (size_t)batches * TICKS;
  size_t slow = 0;
  for (int k = 0; k < TICKS; ++k) {
    const double t = k * H;
    for (int i = 0; i < 4; ++i) F[k][i] = STATIC_FORCE, dF[k][i] = 0.0;
    if (solver == 0) F[k][0] += 0.2 * t, dF[k][0] = 0.2;
    else F[k][0] += 0.2 * cos(2.0 * PI * 3.0 * (t + 0.5 * H));
  }
  for (int b = 0; c && b < batches; ++b) {
    const Ticks t = {H, TICKS, F, solver == 0 ? dF : NULL, plant->control, 12, NULL, ticks + (size_t)b * TICKS};
    if (run_ticks(plant, c, home, &t) < 0.0) return 0;
  }
  if (!c || !free_instance(plant, FMI2_CS, c, &home)) return 0;
  for (int k = 0; k < TICKS; ++k) {
    own[k] = ticks[k];
    for (int b = 1; b < batches; ++b) own[k] = fmin(own[k], ticks[(size_t)b * TICKS + k]);
  }
  for (size_t k = 0; k < n; ++k) slow += ticks[k] > 2.0 * own[k % TICKS];
  bench_sort(ticks, n);
  bench_sort(own, TICKS);
  quantiles(name, ticks, n, 0);
  quantiles("  the model's own (min over batches per tick)", own, TICKS, 1);
  printf("%-44s %zu of %zu (%.3f %%) took more than twice their own minimum: the machine's\n", "", slow, n,
         100.0 * (double)slow / (double)n);
  return 1;
}

static int latency_run(const Plant* plant, const Options* o) {
  double* ticks = malloc(sizeof(double) * (size_t)o->batches * TICKS);
  int ok = ticks != NULL;
  printf("tick: SetReal(F[1..4]) [+ SetRealInputDerivatives] + DoStep(1 ms) + GetReal(12 controller outputs)\n");
  printf("%d batches of %d ticks, %d in all, each batch from the home pose (FMU state restored, untimed)\n\n",
         o->batches, TICKS, o->batches * TICKS);
  printf("%-44s %9s %9s %9s %9s   (us)\n", "solver", "median", "p99", "p99.9", "max");
  ok = ok && run(plant, 1, o->batches, ticks, "RK4 (rk4_step 1 ms), forces held");
  ok = ok && run(plant, 0, o->batches, ticks, "CVODE (rtol 1e-8), forces as a ramp");
  free(ticks);
  return ok;
}

const Subcommand latency_subcommand = {"latency", "control ticks of the plant FMU (FMI 2.0 CS, 1 ms), each timed",
                                       latency_run, 1000, "", 0};
