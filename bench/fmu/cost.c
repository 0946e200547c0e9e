/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench cost: the plant FMU's cost table (time per simulated second per step h and solver, heap,
 * initialisation, throughput); latency: each 1 ms tick timed. Their scenarios: docs/performance.md. */
#include "fmu_bench.h"

#include <malloc.h>
#include <pthread.h>

#define N_STEPS 3
#define N_SOLVERS 4
#define N_MEMORY 64
#define N_INIT 101
#define MAX_TICKS 10000 /* one second at 0.1 ms */
#define TICKS 1000      /* latency's batch: one second at 1 ms, steps[1] */

static const double steps[N_STEPS] = {1e-4, 1e-3, 1e-2};
static const struct {
  const char* name;
  int solver;
  double rtol;
} solvers[N_SOLVERS] = {{"RK4, rk4_step = min(h, 1 ms)", 1, 1e-8},
                        {"CVODE rtol 1e-6", 0, 1e-6},
                        {"CVODE rtol 1e-8 (default)", 0, 1e-8},
                        {"CVODE rtol 1e-10", 0, 1e-10}};

static const Plant* plant; /* the subcommand's, for the worker threads */
static fmi2ValueReference settings[3]; /* rtol, atol, rk4_step */
static double F[N_STEPS][MAX_TICKS][4], dF[N_STEPS][MAX_TICKS][4], held[TICKS][4];

static fmi2Component instantiate_cell(const char* name, int i, int j, fmi2FMUstate* home) {
  const fmi2Real values[3] = {solvers[i].rtol, solvers[i].rtol / 100.0, steps[j] < 1e-3 ? steps[j] : 1e-3};
  return instantiate(plant, FMI2_CS, name, solvers[i].solver, 3, settings, values, home);
}

/* One simulated second of instance c at the step steps[j], from home if given: its wall time, < 0 on failure. */
static double second(fmi2Component c, fmi2FMUstate home, int j) {
  const Ticks t = {steps[j], (int)(1.0 / steps[j] + 0.5), F[j], dF[j], plant->control, 12, NULL, NULL};
  return run_ticks(plant, c, home, &t);
}

static fmi2Component cells[N_SOLVERS * N_STEPS]; /* [solver][step] */
static fmi2FMUstate homes[N_SOLVERS * N_STEPS];

static double cell_second(int i) { return second(cells[i], homes[i], i % N_STEPS); }

typedef struct {
  int solver, ok;
  double seconds, sim_seconds;
} Worker;

static void* worker(void* arg) {
  Worker* w = arg;
  const double start = bench_now();
  for (w->ok = 1; w->ok && bench_now() - start < w->seconds; w->sim_seconds += 1.0) {
    fmi2Component c = instantiate_cell("batch", w->solver, 1, NULL);
    w->ok = c && second(c, NULL, 1) >= 0.0 && free_instance(plant, FMI2_CS, c, NULL);
  }
  w->seconds = bench_now() - start;
  return NULL;
}

/* Instances x simulated seconds per wall second on n threads; *cores: the process's CPU time over the wall time. */
static double throughput(int n, int solver, double seconds, double* cores) {
  pthread_t th[256];
  Worker w[256];
  double sim = 0.0, wall = 0.0;
  const clock_t cpu = clock();
  for (int i = 0; i < n; ++i) {
    w[i] = (Worker){solver, 0, seconds, 0.0};
    if (pthread_create(&th[i], NULL, worker, &w[i]) != 0) return -1.0;
  }
  for (int i = 0; i < n; ++i) pthread_join(th[i], NULL);
  for (int i = 0; i < n; ++i) {
    if (!w[i].ok) return -1.0;
    sim += w[i].sim_seconds, wall = w[i].seconds > wall ? w[i].seconds : wall;
  }
  *cores = (double)(clock() - cpu) / CLOCKS_PER_SEC / wall;
  return sim / wall;
}

/* Both subcommands' start: the settings' value references, the forces; 0 after a message. */
static int set_up(const Plant* p) {
  static const char* const names[3] = {"rtol", "atol", "rk4_step"};
  plant = p;
  for (int j = 0; j < N_STEPS; ++j)
    for (int k = 0; k < MAX_TICKS; ++k) {
      for (int i = 0; i < 4; ++i) F[j][k][i] = STATIC_FORCE, dF[j][k][i] = 0.0;
      F[j][k][0] += 0.2 * k * steps[j], dF[j][k][0] = 0.2;
    }
  for (int k = 0; k < TICKS; ++k) { /* latency's RK4: held at each tick's midpoint */
    memcpy(held[k], F[1][k], sizeof held[k]);
    held[k][0] = STATIC_FORCE + 0.2 * cos(2.0 * PI * 3.0 * (k + 0.5) * steps[1]);
  }
  return lookup_value_references(p, names, 3, settings);
}

static int cost_run(const Plant* p, const Options* o) {
  double med[N_SOLVERS * N_STEPS], mn[N_SOLVERS * N_STEPS];
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  int i, j, ok = set_up(p);
  cores = cores < 1 ? 1 : cores > 256 ? 256 : cores;
  printf("%d interleaved batches per cell (median, min in parentheses); throughput over %.1f s\n\n", o->batches,
         o->seconds);
  for (i = 0; i < N_SOLVERS * N_STEPS; ++i)
    ok = ok && (cells[i] = instantiate_cell("cell", i / N_STEPS, i % N_STEPS, &homes[i])) != NULL;
  ok = ok && time_cases(N_SOLVERS * N_STEPS, o->batches, cell_second, med, mn);
  for (i = 0; i < N_SOLVERS * N_STEPS; ++i)
    if (cells[i] && !free_instance(p, FMI2_CS, cells[i], &homes[i])) ok = 0;
  if (!ok) return 0;
  printf("| wall time per simulated second (tick: SetReal + SetRealInputDerivatives + DoStep + GetReal of 12) "
         "| h = 0.1 ms | h = 1 ms | h = 10 ms |\n|---|---|---|---|\n");
  for (i = 0; i < N_SOLVERS; ++i) {
    printf("| %s |", solvers[i].name);
    for (j = 0; j < N_STEPS; ++j) printf(" %.2f ms (%.2f) |", 1e3 * med[i * N_STEPS + j], 1e3 * mn[i * N_STEPS + j]);
    printf("\n");
  }
  for (i = 0; ok && i < N_SOLVERS; i += 2) { /* RK4 and CVODE at its defaults */
    fmi2Component cs[N_MEMORY];
    double t_init[N_INIT], t_free[N_INIT], mn_i, mn_f, got_one = 0.0, got_all = 0.0;
#if defined(__GLIBC__)
    struct mallinfo2 before, after;
    malloc_trim(0);
    before = mallinfo2();
    for (j = 0; ok && j < N_MEMORY; ++j) ok = (cs[j] = instantiate_cell("memory", i, 1, NULL)) != NULL;
    after = mallinfo2();
    while (j > 0) p->fmu.fmi2FreeInstance(cs[--j]);
    printf("| memory per instance, %s, initialised (heap in use / %d instances) | %.1f kB | | |\n", solvers[i].name,
           N_MEMORY, (double)(after.uordblks + after.hblkhd - before.uordblks - before.hblkhd) / N_MEMORY / 1024.0);
#else
    (void)cs;
    printf("| memory per instance | not measured (needs glibc's mallinfo2) | | |\n");
#endif
    for (j = 0; ok && j < N_INIT; ++j) {
      const double t0 = bench_now();
      fmi2Component ci = instantiate_cell("init", i, 1, NULL);
      const double t1 = bench_now();
      ok = ci && free_instance(p, FMI2_CS, ci, NULL);
      t_init[j] = t1 - t0, t_free[j] = bench_now() - t1;
    }
    if (!ok) return 0;
    const double md_i = bench_median(t_init, N_INIT, &mn_i), md_f = bench_median(t_free, N_INIT, &mn_f);
    printf("| instantiate + initialise, %s (median of %d; then terminate + free) | %.1f µs (%.1f); %.1f µs | | |\n",
           solvers[i].name, N_INIT, 1e6 * md_i, 1e6 * mn_i, 1e6 * md_f);
    const double one = throughput(1, i, o->seconds, &got_one), all = throughput((int)cores, i, o->seconds, &got_all);
    if (one < 0 || all < 0) return 0;
    printf("| batch throughput, %s, h = 1 ms, instantiation included: instances × simulated s per wall s | "
           "%.0f on %ld threads, which got %.2f cores' CPU time (per CPU second: %.0f); 1 thread: %.0f (got %.2f) "
           "| | |\n",
           solvers[i].name, all, cores, got_all, all / got_all, one, got_one);
  }
  return ok;
}

const Subcommand cost_subcommand = {"cost",
                                    "the cost table: time per simulated second, memory, initialisation, throughput",
                                    cost_run, 7, "--seconds S (throughput's wall time, default 3)", 0};

/* The median, p99, p99.9 and largest of sorted[0..n-1] (us); the p99.9 (max_ratio: the largest) over the median. */
static void quantiles(const char* name, const double* sorted, size_t n, int max_ratio) {
  const double median = bench_quantile(sorted, n, 0.5), p999 = bench_quantile(sorted, n, 0.999);
  printf("%-44s %9.3f %9.3f %9.3f %9.3f   %s %5.2f\n", name, 1e6 * median, 1e6 * bench_quantile(sorted, n, 0.99),
         1e6 * p999, 1e6 * sorted[n - 1], max_ratio ? "max/median  " : "p99.9/median",
         (max_ratio ? sorted[n - 1] : p999) / median);
}

/* Solver i's rows (RK4: the forces held; CVODE: the ramp), each tick of each batch timed into ticks. */
static int latency_rows(int i, int batches, double* ticks, const char* name) {
  fmi2FMUstate home = NULL;
  fmi2Component c = instantiate_cell("latency", i, 1, &home);
  double own[TICKS];
  const size_t n = (size_t)batches * TICKS;
  size_t slow = 0;
  for (int b = 0; c && b < batches; ++b) {
    const Ticks t = {steps[1], TICKS, i ? F[1] : held, i ? dF[1] : NULL, plant->control, 12, NULL,
                     ticks + (size_t)b * TICKS};
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

static int latency_run(const Plant* p, const Options* o) {
  double* ticks = malloc(sizeof(double) * (size_t)o->batches * TICKS);
  int ok = ticks != NULL && set_up(p);
  printf("tick: SetReal(F[1..4]) [+ SetRealInputDerivatives] + DoStep(1 ms) + GetReal(12 controller outputs)\n");
  printf("%d batches of %d ticks, %d in all, each batch from the home pose (FMU state restored, untimed)\n\n",
         o->batches, TICKS, o->batches * TICKS);
  printf("%-44s %9s %9s %9s %9s   (us)\n", "solver", "median", "p99", "p99.9", "max");
  ok = ok && latency_rows(0, o->batches, ticks, "RK4 (rk4_step 1 ms), forces held");
  ok = ok && latency_rows(2, o->batches, ticks, "CVODE (rtol 1e-8), forces as a ramp");
  free(ticks);
  return ok;
}

const Subcommand latency_subcommand = {"latency", "control ticks of the plant FMU (FMI 2.0 CS, 1 ms), each timed",
                                       latency_run, 1000, "", 0};
