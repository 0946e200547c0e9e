/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench cost: the plant FMU's cost in one table,
 * through the FMU binary (no Python in any timed loop):
 *
 *   - wall time per simulated second against the communication step h
 *     (0.1, 1, 10 ms) and the solver and tolerance (RK4 with rk4_step =
 *     min(h, 1 ms); CVODE Adams at rtol 1e-6, 1e-8 (the default), 1e-10,
 *     atol = rtol / 100 as the defaults are), each tick fmi2SetReal(F[1..4])
 *     + fmi2SetRealInputDerivatives + fmi2DoStep(h) + fmi2GetReal of the 12
 *     controller outputs (pose, rates, rho[1..4]);
 *   - memory per instance: the heap in use (glibc mallinfo2) after
 *     instantiating and initialising 64 instances, over 64;
 *   - instantiate + initialise: fmi2Instantiate, fmi2SetupExperiment,
 *     fmi2SetInteger(solver), Enter/ExitInitializationMode (median of 101);
 *   - batch throughput: one thread per online core, each running its own
 *     instances one after another (RK4 and CVODE 1e-8, h = 1 ms, 1 simulated
 *     second each, instantiation included), for about --seconds S of wall
 *     time: instances x simulated seconds per wall second, all threads
 *     together, beside one thread alone; with the CPU time the threads got
 *     (CLOCK_THREAD_CPUTIME_ID) over the wall time, since on a shared
 *     machine they may get fewer cores than they are (the scheduler's
 *     autogroup gives a session its share whatever its thread count), and
 *     the throughput per CPU second, which does not depend on that.
 *
 * Scenario: from the home pose, g as declared, F[1..4] = the static holding
 * force (docs/model.md "Bodies") plus on F[1] the ramp 0.2 t N
 * given as value and slope each tick, so the inputs continue and CVODE keeps
 * its history across ticks (a held input that jumps every tick restarts it:
 * see docs/performance.md's continuation table). Timings: --batches B (default 7)
 * batches of 1 simulated second per cell, the cells interleaved batch by
 * batch; the median, and the minimum in parentheses.
 *
 *   pkm_fmu_bench cost [--batches B] [--seconds S] [--fmu SO] [--xml FILE]
 *
 * Prints a Markdown table. */
#define _GNU_SOURCE

#if defined(__GLIBC__) || defined(__linux__)
#include <malloc.h>
#endif
#include <math.h>
#include <pthread.h>

#include "bench.h"

#define SLOPE 0.2                /* N/s on F[1] */
#define MAX_BATCHES 101
#define N_STEPS 3
#define N_SOLVERS 4
#define N_MEMORY 64
#define N_INIT 101

static const double steps[N_STEPS] = {1e-4, 1e-3, 1e-2};
static const struct {
  const char* name;
  int solver;
  double rtol;
} solvers[N_SOLVERS] = {{"RK4, rk4_step = min(h, 1 ms)", 1, 0.0},
                        {"CVODE rtol 1e-6", 0, 1e-6},
                        {"CVODE rtol 1e-8 (default)", 0, 1e-8},
                        {"CVODE rtol 1e-10", 0, 1e-10}};

typedef struct {
  fmi2ValueReference tolerances[2], rk4_step; /* rtol, atol */
} Refs;

static const Plant* plant; /* the subcommand's, for the worker threads */
static const Fmu* fmu;
static Refs refs;

/* CVODE: rtol and atol = rtol / 100; RK4: rk4_step = min(h, 1 ms). */
static fmi2Component instantiate(const char* name, int solver, double rtol, double h, fmi2FMUstate* home) {
  const fmi2Real tolerances[2] = {rtol, rtol / 100.0}, step = h < 1e-3 ? h : 1e-3;
  if (solver == 0) return instantiate_plant(plant, name, solver, 2, refs.tolerances, tolerances, home);
  return instantiate_plant(plant, name, solver, 1, &refs.rk4_step, &step, home);
}

/* One simulated second from the instance's current state at time t0. */
static int simulate_second(fmi2Component c, double t0, double h) {
  const fmi2Integer order[4] = {1, 1, 1, 1};
  const int n = (int)lround(1.0 / h);
  double u[4], du[4] = {SLOPE, 0.0, 0.0, 0.0}, y[12];
  int k;
  for (k = 0; k < n; ++k) {
    const double t = t0 + k * h;
    u[0] = STATIC_FORCE + SLOPE * t, u[1] = u[2] = u[3] = STATIC_FORCE;
    if (fmu->fmi2SetReal(c, plant->F, 4, u) != fmi2OK || fmu->fmi2SetRealInputDerivatives(c, plant->F, 4, order, du) != fmi2OK ||
        fmu->fmi2DoStep(c, t, h, fmi2True) != fmi2OK || fmu->fmi2GetReal(c, plant->control, 12, y) != fmi2OK) {
      fprintf(stderr, PKM_HARNESS_NAME " cost: a call failed at t = %g (h = %g)\n", t, h);
      return 0;
    }
  }
  return 1;
}

/* --- batch throughput ----------------------------------------------------------------------------- */
typedef struct {
  int solver;
  double rtol, seconds, sim_seconds, cpu;
  int ok;
} Worker;

static double thread_cpu_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void* worker(void* arg) {
  Worker* w = arg;
  const double start = now_seconds(), cpu0 = thread_cpu_seconds();
  w->sim_seconds = 0.0;
  w->ok = 1;
  while (now_seconds() - start < w->seconds) {
    fmi2Component c = instantiate("batch", w->solver, w->rtol, 1e-3, NULL);
    if (!c || !simulate_second(c, 0.0, 1e-3)) {
      w->ok = 0;
      return NULL;
    }
    free_plant(plant, c, NULL);
    w->sim_seconds += 1.0;
  }
  w->seconds = now_seconds() - start;
  w->cpu = thread_cpu_seconds() - cpu0;
  return NULL;
}

/* instances x simulated seconds per wall second over n_threads threads; *cores: the CPU time the threads
 * got over the wall time (how many cores they actually had: on a shared machine fewer than n_threads). */
static double throughput(int n_threads, int solver, double rtol, double seconds, double* cores) {
  pthread_t th[256];
  Worker w[256];
  double sim = 0.0, wall = 0.0, cpu = 0.0;
  int i;
  for (i = 0; i < n_threads; ++i) {
    w[i] = (Worker){solver, rtol, seconds, 0.0, 0.0, 0};
    if (pthread_create(&th[i], NULL, worker, &w[i]) != 0) return -1.0;
  }
  for (i = 0; i < n_threads; ++i) pthread_join(th[i], NULL);
  for (i = 0; i < n_threads; ++i) {
    if (!w[i].ok) return -1.0;
    sim += w[i].sim_seconds;
    cpu += w[i].cpu;
    if (w[i].seconds > wall) wall = w[i].seconds;
  }
  *cores = cpu / wall;
  return sim / wall;
}

static int cost_run(const Plant* p, const Options* o) {
  static const char* const tolerance_names[] = {"rtol", "atol"};
  static double per[N_SOLVERS][N_STEPS][MAX_BATCHES];
  const int batches = o->batches;
  const double seconds = o->seconds;
  int i, j, b;
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  plant = p;
  fmu = &p->fmu;
  if (cores < 1) cores = 1;
  if (cores > 256) cores = 256;
  if (!lookup_value_references(p, tolerance_names, 2, refs.tolerances) ||
      !lookup_value_reference(p->text, "rk4_step", &refs.rk4_step))
    return 0;

  printf("pkm_fmu_bench cost: the plant FMU's cost (FMI 2.0 CS through dlopen, plain C)\n");
  print_machine();
  printf("fmu:     %s\n", p->so);
  printf("online cores: %ld; %d interleaved batches per cell (median, min in parentheses); throughput over %.1f s\n\n",
         cores, batches, seconds);

  /* Cost per simulated second: one instance per cell, the cells interleaved batch by batch; each batch
   * restores the state saved after initialisation (untimed), then times one simulated second. */
  {
    fmi2Component c[N_SOLVERS][N_STEPS];
    fmi2FMUstate home[N_SOLVERS][N_STEPS];
    for (i = 0; i < N_SOLVERS; ++i)
      for (j = 0; j < N_STEPS; ++j) {
        home[i][j] = NULL;
        if (!(c[i][j] = instantiate("cell", solvers[i].solver, solvers[i].rtol, steps[j], &home[i][j]))) return 0;
      }
    for (b = -1; b < batches; ++b)
      for (i = 0; i < N_SOLVERS; ++i)
        for (j = 0; j < N_STEPS; ++j) {
          double t0;
          if (fmu->fmi2SetFMUstate(c[i][j], home[i][j]) != fmi2OK) return 0;
          t0 = now_seconds();
          if (!simulate_second(c[i][j], 0.0, steps[j])) return 0;
          if (b >= 0) per[i][j][b] = now_seconds() - t0;
        }
    for (i = 0; i < N_SOLVERS; ++i)
      for (j = 0; j < N_STEPS; ++j) free_plant(p, c[i][j], &home[i][j]);
  }
  printf("| wall time per simulated second (tick: SetReal + SetRealInputDerivatives + DoStep + GetReal of 12) "
         "| h = 0.1 ms | h = 1 ms | h = 10 ms |\n|---|---|---|---|\n");
  for (i = 0; i < N_SOLVERS; ++i) {
    printf("| %s |", solvers[i].name);
    for (j = 0; j < N_STEPS; ++j) {
      double mn, md = median_min(per[i][j], batches, &mn);
      printf(" %.2f ms (%.2f) |", 1e3 * md, 1e3 * mn);
    }
    printf("\n");
  }

#if defined(__GLIBC__)
  /* Memory per instance (CVODE default: its objects are created at initialisation; RK4 beside it). */
  for (i = 0; i < N_SOLVERS; i += 2) {
    fmi2Component cs[N_MEMORY];
    struct mallinfo2 before, after;
    malloc_trim(0);
    before = mallinfo2();
    for (j = 0; j < N_MEMORY; ++j)
      if (!(cs[j] = instantiate("memory", solvers[i].solver, solvers[i].rtol, 1e-3, NULL))) return 0;
    after = mallinfo2();
    for (j = 0; j < N_MEMORY; ++j) fmu->fmi2FreeInstance(cs[j]);
    printf("| memory per instance, %s, initialised (heap in use / %d instances) | %.1f kB | | |\n", solvers[i].name,
           N_MEMORY, (double)(after.uordblks + after.hblkhd - before.uordblks - before.hblkhd) / N_MEMORY / 1024.0);
  }

#else
  printf("| memory per instance | not measured (needs glibc's mallinfo2) | | |\n");
#endif

  /* Instantiate + initialise, and free. */
  for (i = 0; i < N_SOLVERS; i += 2) {
    double t_init[N_INIT], t_free[N_INIT], mn_i, mn_f, md_i, md_f;
    for (j = 0; j < N_INIT; ++j) {
      double t0 = now_seconds(), t1;
      fmi2Component c = instantiate("init", solvers[i].solver, solvers[i].rtol, 1e-3, NULL);
      t1 = now_seconds();
      if (!c) return 0;
      free_plant(p, c, NULL);
      t_init[j] = t1 - t0;
      t_free[j] = now_seconds() - t1;
    }
    md_i = median_min(t_init, N_INIT, &mn_i);
    md_f = median_min(t_free, N_INIT, &mn_f);
    printf("| instantiate + initialise, %s (median of %d; then terminate + free) | %.1f µs (%.1f); %.1f µs | | |\n",
           solvers[i].name, N_INIT, 1e6 * md_i, 1e6 * mn_i, 1e6 * md_f);
  }

  /* Batch throughput on all cores, beside one. */
  for (i = 0; i < N_SOLVERS; i += 2) {
    double got_one, got_all;
    const double one = throughput(1, solvers[i].solver, solvers[i].rtol, seconds, &got_one);
    const double all = throughput((int)cores, solvers[i].solver, solvers[i].rtol, seconds, &got_all);
    if (one < 0 || all < 0) return 0;
    printf("| batch throughput, %s, h = 1 ms, instantiation included: instances × simulated s per wall s | "
           "%.0f on %ld threads, which got %.2f cores' CPU time (per CPU second: %.0f); 1 thread: %.0f (got %.2f) "
           "| | |\n",
           solvers[i].name, all, cores, got_all, all / got_all, one, got_one);
  }
  return 1;
}

const Subcommand cost_subcommand = {"cost", "the cost table: time per simulated second, memory, initialisation, throughput",
                                    cost_run, 7, MAX_BATCHES, "--seconds S (throughput's wall time, default 3)"};
