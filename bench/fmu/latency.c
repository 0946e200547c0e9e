/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench latency: the distribution of the control tick's time over
 * 10^6 ticks of the plant FMU, raw FMI 2.0 Co-Simulation, as a
 * real-time controller drives it: every 1 ms, fmi2SetReal(F[1..4]) (with
 * CVODE also fmi2SetRealInputDerivatives: the force as a continuous ramp,
 * value and slope), fmi2DoStep, fmi2GetReal of the 12 controller outputs
 * (pose, rates, slider positions). Each tick is timed on its own
 * (clock_gettime(CLOCK_MONOTONIC), about 20 ns per reading).
 *
 *   pkm_fmu_bench latency [--batches N] [--fmu SO] [--xml FILE]
 *
 * Scenario: --batches (default 1000) batches of 1000 ticks, each batch the
 * same simulated second from the home pose (the FMU state saved after
 * initialisation is restored between batches, outside the timing, so the
 * platform never leaves the workspace), F[1..4] = the static holding force (docs/model.md), plus on F[1]
 * with RK4 0.2 cos(2 pi 3 t) N held over each tick (its midpoint value),
 * with CVODE the ramp 0.2 t N given as value and slope each tick (CVODE
 * continues across the ticks; it restarts at each batch's restore).
 *
 * What the outliers are: the model's work at tick k of a batch is the same in
 * every batch (same state, same inputs, bit for bit), the machine's
 * interruptions (timer interrupts, another process) fall on random ticks. So
 * the minimum over the batches of tick k is the model's own time for
 * that tick; its distribution (median, p99, p99.9, max over k) is the
 * model's share of the spread, the rest of the measured spread is the
 * machine's. (Hardware instruction counters are not available in every
 * virtual machine; this needs none.)
 *
 * Prints, per solver: median, p99, p99.9 and maximum tick time over the 10^6
 * ticks; the same over the model's own per-tick minima; how many ticks took
 * more than twice their own minimum. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>

#include "bench.h"

#define AMPLITUDE 0.2            /* N, on F[1] */
#define FREQUENCY 3.0            /* Hz */
#define H 1e-3                   /* s */
#define TICKS 1000               /* per batch: 1 s simulated */
#define BATCHES 1000             /* 10^6 ticks */

static double quantile(double* sorted, size_t n, double q) {
  size_t i = (size_t)ceil(q * (double)n) - 1;
  if (i >= n) i = n - 1;
  return sorted[i];
}

static int run(const Plant* plant, int solver, int batches, double* ticks /* batches * TICKS */) {
  const Fmu* f = &plant->fmu;
  fmi2FMUstate home = NULL;
  fmi2Component c = instantiate_plant(plant, "latency", solver, 0, NULL, NULL, &home);
  const fmi2Integer order[4] = {1, 1, 1, 1};
  double u[TICKS][4], du[TICKS][4], y[12];
  int b, k, i;
  if (!c) return 0;
  for (k = 0; k < TICKS; ++k) {
    const double t = k * H, w = 2.0 * PI * FREQUENCY;
    for (i = 0; i < 4; ++i) u[k][i] = STATIC_FORCE, du[k][i] = 0.0;
    if (solver == 0) { /* a continuous ramp, value and slope: CVODE continues across ticks */
      u[k][0] += AMPLITUDE * t;
      du[k][0] = AMPLITUDE;
    } else { /* held over the tick */
      u[k][0] += AMPLITUDE * cos(w * (t + 0.5 * H));
    }
  }
  for (b = 0; b < batches; ++b) {
    if (f->fmi2SetFMUstate(c, home) != fmi2OK) return 0;
    for (k = 0; k < TICKS; ++k) {
      const double t0 = now_seconds();
      int ok = f->fmi2SetReal(c, plant->F, 4, u[k]) == fmi2OK;
      if (solver == 0) ok = ok && f->fmi2SetRealInputDerivatives(c, plant->F, 4, order, du[k]) == fmi2OK;
      ok = ok && f->fmi2DoStep(c, k * H, H, fmi2True) == fmi2OK && f->fmi2GetReal(c, plant->control, 12, y) == fmi2OK;
      ticks[(size_t)b * TICKS + (size_t)k] = now_seconds() - t0;
      if (!ok) {
        fprintf(stderr, PKM_HARNESS_NAME " latency: a call failed at batch %d, tick %d\n", b, k);
        return 0;
      }
    }
  }
  free_plant(plant, c, &home);
  return 1;
}

static void report(const char* name, int batches, double* ticks) {
  const size_t n = (size_t)batches * TICKS;
  double own[TICKS], sorted_own[TICKS];
  size_t slow = 0, k, b;
  for (k = 0; k < TICKS; ++k) {
    own[k] = ticks[k];
    for (b = 1; b < (size_t)batches; ++b)
      if (ticks[b * TICKS + k] < own[k]) own[k] = ticks[b * TICKS + k];
  }
  for (b = 0; b < n; ++b)
    if (ticks[b] > 2.0 * own[b % TICKS]) ++slow;
  memcpy(sorted_own, own, sizeof own);
  qsort(sorted_own, TICKS, sizeof sorted_own[0], compare_double);
  qsort(ticks, n, sizeof ticks[0], compare_double);
  printf("%-44s %9.3f %9.3f %9.3f %9.3f   p99.9/median %5.2f\n", name, 1e6 * quantile(ticks, n, 0.5),
         1e6 * quantile(ticks, n, 0.99), 1e6 * quantile(ticks, n, 0.999), 1e6 * ticks[n - 1],
         quantile(ticks, n, 0.999) / quantile(ticks, n, 0.5));
  printf("%-44s %9.3f %9.3f %9.3f %9.3f   max/median   %5.2f\n", "  the model's own (min over batches per tick)",
         1e6 * quantile(sorted_own, TICKS, 0.5), 1e6 * quantile(sorted_own, TICKS, 0.99),
         1e6 * quantile(sorted_own, TICKS, 0.999), 1e6 * sorted_own[TICKS - 1],
         sorted_own[TICKS - 1] / quantile(sorted_own, TICKS, 0.5));
  printf("%-44s %zu of %zu (%.3f %%) took more than twice their own minimum: the machine's\n", "", slow, n,
         100.0 * (double)slow / (double)n);
}

static int latency_run(const Plant* plant, const Options* o) {
  double* ticks = malloc(sizeof(double) * (size_t)o->batches * TICKS);
  int ok = ticks != NULL;
  if (ok) {
    printf("pkm_fmu_bench latency: %d control ticks of the plant FMU (FMI 2.0 CS, 1 ms), each timed\n",
           o->batches * TICKS);
    print_machine();
    printf("tick: SetReal(F[1..4]) [+ SetRealInputDerivatives] + DoStep(1 ms) + GetReal(12 controller outputs)\n");
    printf("%d batches of %d ticks, each from the home pose (FMU state restored, untimed)\n\n", o->batches, TICKS);
    printf("%-44s %9s %9s %9s %9s   (us)\n", "solver", "median", "p99", "p99.9", "max");
  }
  ok = ok && run(plant, 1, o->batches, ticks);
  if (ok) report("RK4 (rk4_step 1 ms), forces held", o->batches, ticks);
  ok = ok && run(plant, 0, o->batches, ticks);
  if (ok) report("CVODE (rtol 1e-8), forces as a ramp", o->batches, ticks);
  free(ticks);
  return ok;
}

const Subcommand latency_subcommand = {"latency", "10^6 control ticks (1000 batches of 1000), each timed", latency_run,
                                       BATCHES, BATCHES, ""};
