/* pkm_fmu_latency_bench: the distribution of the control tick's time over
 * 10^6 ticks of the plant FMU (PKM4PUU.so), raw FMI 2.0 Co-Simulation, as a
 * real-time controller drives it: every 1 ms, fmi2SetReal(F[1..4]) (with
 * CVODE also fmi2SetRealInputDerivatives: the force as a continuous ramp,
 * value and slope), fmi2DoStep, fmi2GetReal of the 12 controller outputs
 * (pose, rates, slider positions). Each tick is timed on its own
 * (clock_gettime(CLOCK_MONOTONIC), about 20 ns per reading).
 *
 *   pkm_fmu_latency_bench [PKM4PUU.so [modelDescription.xml]]
 *
 * Scenario: 1000 batches of 1000 ticks, each batch the same simulated second
 * from the home pose (the FMU state saved after initialisation is restored
 * between batches, outside the timing, so the platform never leaves the
 * workspace), F[1..4] = the static holding force (MODEL_SPEC), plus on F[1]
 * with RK4 0.2 cos(2 pi 3 t) N held over each tick (its midpoint value),
 * with CVODE the ramp 0.2 t N given as value and slope each tick (CVODE
 * continues across the ticks; it restarts at each batch's restore).
 *
 * What the outliers are: the model's work at tick k of a batch is the same in
 * every batch (same state, same inputs, bit for bit), the machine's
 * interruptions (timer interrupts, another process) fall on random ticks. So
 * the minimum over the 1000 batches of tick k is the model's own time for
 * that tick; its distribution (median, p99, p99.9, max over k) is the
 * model's share of the spread, the rest of the measured spread is the
 * machine's. (Hardware instruction counters are not available in every
 * virtual machine; this needs none.)
 *
 * Prints, per solver: median, p99, p99.9 and maximum tick time over the 10^6
 * ticks; the same over the model's own per-tick minima; how many ticks took
 * more than twice their own minimum. Exit status 0, 1 on any failure. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"

#define PKM_HARNESS_NAME "pkm_fmu_latency_bench"
#include "fmu_harness.h"

#ifndef PKM_FMU_PLANT_SO
#define PKM_FMU_PLANT_SO "PKM4PUU.so"
#endif

#define STATIC_FORCE 2.655616050 /* N, MODEL_SPEC "A check anyone can derive" */
#define AMPLITUDE 0.2            /* N, on F[1] */
#define FREQUENCY 3.0            /* Hz */
#define H 1e-3                   /* s */
#define TICKS 1000               /* per batch: 1 s simulated */
#define BATCHES 1000             /* 10^6 ticks */
#define PI 3.14159265358979323846

typedef struct {
  fmi2ValueReference F[4], control[12], solver;
  char guid[128];
} Refs;

static double quantile(double* sorted, size_t n, double q) {
  size_t i = (size_t)ceil(q * (double)n) - 1;
  if (i >= n) i = n - 1;
  return sorted[i];
}

static int run(const Fmu* f, const Refs* r, int solver, double* ticks /* BATCHES * TICKS */) {
  fmi2CallbackFunctions cb = {logger, allocate_memory, free, NULL, NULL};
  fmi2Component c = f->fmi2Instantiate("latency", fmi2CoSimulation, r->guid, "", &cb, fmi2False, fmi2False);
  fmi2FMUstate home = NULL;
  const fmi2Integer s = solver;
  const fmi2Integer order[4] = {1, 1, 1, 1};
  double u[TICKS][4], du[TICKS][4], y[12];
  int b, k, i;
  if (!c || f->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
      f->fmi2SetInteger(c, &r->solver, 1, &s) != fmi2OK || f->fmi2EnterInitializationMode(c) != fmi2OK ||
      f->fmi2ExitInitializationMode(c) != fmi2OK || f->fmi2GetFMUstate(c, &home) != fmi2OK)
    return 0;
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
  for (b = 0; b < BATCHES; ++b) {
    if (f->fmi2SetFMUstate(c, home) != fmi2OK) return 0;
    for (k = 0; k < TICKS; ++k) {
      const double t0 = now_seconds();
      int ok = f->fmi2SetReal(c, r->F, 4, u[k]) == fmi2OK;
      if (solver == 0) ok = ok && f->fmi2SetRealInputDerivatives(c, r->F, 4, order, du[k]) == fmi2OK;
      ok = ok && f->fmi2DoStep(c, k * H, H, fmi2True) == fmi2OK && f->fmi2GetReal(c, r->control, 12, y) == fmi2OK;
      ticks[(size_t)b * TICKS + (size_t)k] = now_seconds() - t0;
      if (!ok) {
        fprintf(stderr, "pkm_fmu_latency_bench: a call failed at batch %d, tick %d\n", b, k);
        return 0;
      }
    }
  }
  f->fmi2FreeFMUstate(c, &home);
  f->fmi2Terminate(c);
  f->fmi2FreeInstance(c);
  return 1;
}

static void report(const char* name, double* ticks) {
  const size_t n = (size_t)BATCHES * TICKS;
  double own[TICKS], sorted_own[TICKS];
  size_t slow = 0, k, b;
  for (k = 0; k < TICKS; ++k) {
    own[k] = ticks[k];
    for (b = 1; b < BATCHES; ++b)
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

int main(int argc, char** argv) {
  const char* so = argc > 1 ? argv[1] : PKM_FMU_PLANT_SO;
  char* xml_path = argc > 2 ? NULL : default_xml_path(so);
  const char* xml = argc > 2 ? argv[2] : xml_path;
  char* text = xml ? read_text(xml) : NULL;
  double* ticks = malloc(sizeof(double) * (size_t)BATCHES * TICKS);
  Refs r;
  Fmu f;
  if (!ticks || !read_controller_interface(text, r.guid, sizeof r.guid, r.F, r.control)) return 1;
  if (!lookup_value_reference(text, "solver", &r.solver) || !load_fmu(so, &f)) return 1;
  printf("pkm_fmu_latency_bench: 10^6 control ticks of the plant FMU (FMI 2.0 CS, 1 ms), each timed\n");
  print_machine();
  printf("tick: SetReal(F[1..4]) [+ SetRealInputDerivatives] + DoStep(1 ms) + GetReal(12 controller outputs)\n");
  printf("%d batches of %d ticks, each from the home pose (FMU state restored, untimed)\n\n", BATCHES, TICKS);
  printf("%-44s %9s %9s %9s %9s   (us)\n", "solver", "median", "p99", "p99.9", "max");
  if (!run(&f, &r, 1, ticks)) return 1;
  report("RK4 (rk4_step 1 ms), forces held", ticks);
  if (!run(&f, &r, 0, ticks)) return 1;
  report("CVODE (rtol 1e-8), forces as a ramp", ticks);
  free(ticks);
  free(text);
  free(xml_path);
  return 0;
}
