/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench step: the cost of one 1-ms communication step of the plant
 * FMU, fmi2SetReal(F[1..4]) + fmi2DoStep every step, with four amounts of
 * output read.
 *
 *   pkm_fmu_bench step [--batches N] [--solver 0|1] [--fmu SO] [--xml FILE]
 *
 * Scenario: the home pose (default parameters), F[1..4] = 2.655616050 N (the
 * static forces of docs/model.md) plus 0.01 sin(2 pi t) N on F[1], set before
 * every fmi2DoStep of 1 ms. Cases, for solver = 1 (RK4, rk4_step 1e-3) and
 * solver = 0 (CVODE, rtol 1e-8, atol 1e-10):
 *   (a) fmi2SetReal(4 inputs) + fmi2DoStep
 *   (b) (a) + fmi2GetReal(x, y, z, phi)
 *   (c) (a) + fmi2GetReal of a controller's 12 outputs (pose, rates, rho[1..4])
 *   (d) (b) + fmi2GetReal(every Real output)
 * and what (c) adds to (a), in percent (target: at most 10 % with RK4).
 * A batch is 1 s of simulated time (1000 steps) from the home pose (the FMU
 * state saved after initialisation is restored before each batch, outside
 * the timed region, so every batch integrates the same second); one
 * untimed warm-up batch, then --batches timed batches (default 21); the
 * median and the minimum time per step are printed. Timing:
 * clock_gettime(CLOCK_MONOTONIC). For profiling (callgrind, perf), --solver
 * runs one solver only and --batches 1 one timed batch. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>

#include "bench.h"

#define SINE_AMPLITUDE 0.01      /* N, on F[1] */
#define COMM_STEP 1e-3           /* s */
#define STEPS_PER_BATCH 1000     /* 1 s of simulated time */
#define BATCHES 21 /* at most */
#define MAX_OUTPUTS 256

#define CHECK(call)                                                                     \
  do {                                                                                  \
    const fmi2Status check_status_ = (call);                                            \
    if (check_status_ != fmi2OK) {                                                      \
      fprintf(stderr, PKM_HARNESS_NAME ": %s:%d: %s returned %s\n", __FILE__, __LINE__,     \
              #call, status_name(check_status_));                                       \
      return 0;                                                                         \
    }                                                                                   \
  } while (0)

/* ------------------------------------------------------------- the runs */

typedef struct {
  const fmi2ValueReference *F, *pose, *control; /* the plant's; pose: control's first 4 */
  fmi2ValueReference settings[3]; /* rk4_step, rtol, atol */
  fmi2ValueReference outputs[MAX_OUTPUTS]; /* every Real output */
  size_t n_outputs;
} References;

/* The value references of every Real output of the model description. */
static int find_outputs(const char* text, References* r) {
  const char* p = text;
  r->n_outputs = 0;
  while ((p = strstr(p, "<ScalarVariable")) != NULL) {
    const char* end = strstr(p, "</ScalarVariable>");
    char buf[64];
    if (!end) break;
    if (attribute(p, end, "causality", buf, sizeof buf) && strcmp(buf, "output") == 0) {
      const char* real = strstr(p, "<Real");
      if (real && real < end && attribute(p, end, "valueReference", buf, sizeof buf)) {
        if (r->n_outputs == MAX_OUTPUTS) return 0;
        r->outputs[r->n_outputs++] = (fmi2ValueReference)strtoul(buf, NULL, 10);
      }
    }
    p = end;
  }
  return r->n_outputs > 0;
}

typedef enum { CASE_STEP, CASE_POSE, CASE_CONTROL, CASE_ALL } Case;

typedef struct {
  double median_us, min_us;
  double pose[4]; /* at the end of the last batch */
} Result;

/* One batch: STEPS_PER_BATCH communication steps from t = 0. */
static int batch(const Fmu* f, fmi2Component c, const References* r, Case kind, const double* force1,
                 double* seconds, double* pose) {
  double u[4] = {STATIC_FORCE, STATIC_FORCE, STATIC_FORCE, STATIC_FORCE};
  double all[MAX_OUTPUTS];
  double t0, t1;
  int k;
  t0 = now_seconds();
  for (k = 0; k < STEPS_PER_BATCH; ++k) {
    const double t = (double)k * COMM_STEP;
    u[0] = force1[k];
    CHECK(f->fmi2SetReal(c, r->F, 4, u));
    CHECK(f->fmi2DoStep(c, t, COMM_STEP, fmi2True));
    if (kind == CASE_CONTROL) {
      double control[12];
      CHECK(f->fmi2GetReal(c, r->control, 12, control));
      memcpy(pose, control, 4 * sizeof pose[0]);
    } else if (kind != CASE_STEP) {
      CHECK(f->fmi2GetReal(c, r->pose, 4, pose));
    }
    if (kind == CASE_ALL) CHECK(f->fmi2GetReal(c, r->outputs, r->n_outputs, all));
  }
  t1 = now_seconds();
  *seconds = t1 - t0;
  if (kind == CASE_STEP) CHECK(f->fmi2GetReal(c, r->pose, 4, pose));
  return 1;
}

static int run(const Plant* plant, const References* r, int solver, Case kind, int batches, Result* result) {
  static const char* names[] = {"step", "step+pose", "step+control", "step+all"};
  static const fmi2Real settings[3] = {1e-3, 1e-8, 1e-10}; /* rk4_step, rtol, atol */
  const Fmu* f = &plant->fmu;
  double force1[STEPS_PER_BATCH], per_step[BATCHES], seconds = 0.0;
  fmi2FMUstate home = NULL;
  fmi2Component c;
  char name[64];
  int k, ok = 1;

  for (k = 0; k < STEPS_PER_BATCH; ++k)
    force1[k] = STATIC_FORCE + SINE_AMPLITUDE * sin(2.0 * PI * (double)k * COMM_STEP);

  snprintf(name, sizeof name, "bench_solver%d_%s", solver, names[kind]);
  c = instantiate_plant(plant, name, solver, 3, r->settings, settings, &home);
  if (!c) return 0;
  /* One warm-up batch, then the timed ones, each from the home pose at t = 0. */
  for (k = -1; ok && k < batches; ++k) {
    ok = f->fmi2SetFMUstate(c, home) == fmi2OK;
    if (!ok) {
      fprintf(stderr, PKM_HARNESS_NAME ": fmi2SetFMUstate failed\n");
      break;
    }
    ok = batch(f, c, r, kind, force1, &seconds, result->pose);
    if (ok && k >= 0) per_step[k] = seconds / STEPS_PER_BATCH;
  }
  if (!free_plant(plant, c, &home) || !ok) return 0;
  result->median_us = 1e6 * median_min(per_step, batches, &result->min_us);
  result->min_us *= 1e6;
  return 1;
}

/* ------------------------------------------------------------- the table */

static int step_run(const Plant* plant, const Options* o) {
  static const char* const setting_names[] = {"rk4_step", "rtol", "atol"};
  static const char* case_names[] = {"(a) SetReal(F) + DoStep", "(b) (a) + GetReal(x,y,z,phi)",
                                     "(c) (a) + GetReal(12 controller outputs)", "(d) (b) + GetReal(all outputs)"};
  static References r;
  const int first_solver = o->solver >= 0 ? o->solver : 1, last_solver = o->solver >= 0 ? o->solver : 0;
  int solver, kind, ok;

  r.F = plant->F;
  r.pose = r.control = plant->control;
  ok = find_outputs(plant->text, &r) && lookup_value_references(plant, setting_names, 3, r.settings);
  if (!ok) return 0;

  printf("pkm_fmu_bench step: FMI 2.0 Co-Simulation, one communication step of the plant FMU\n");
  print_machine();
  printf("fmu:     %s\n", plant->so);
  printf("xml:     %s\n", plant->xml);
  printf("guid:    %s; %zu Real outputs\n", plant->guid, r.n_outputs);
  printf("scenario: home pose, F[1..4] = %.9f N, + %.2f sin(2 pi t) N on F[1]; step %.0f ms; "
         "%d timed batches of %d steps (1 s simulated, from the home pose each) after 1 warm-up batch\n\n",
         STATIC_FORCE, SINE_AMPLITUDE, COMM_STEP * 1e3, o->batches, STEPS_PER_BATCH);
  printf("%-34s %-34s %10s %10s %12s %12s\n", "solver", "per step", "median us", "min us", "RT (median)",
         "RT (min)");

  for (solver = first_solver; ok && solver >= last_solver; --solver) {
    const char* solver_name = solver == 1 ? "RK4 (rk4_step 1e-3)" : "CVODE (rtol 1e-8, atol 1e-10)";
    double step_us = 0.0;
    for (kind = CASE_STEP; ok && kind <= CASE_ALL; ++kind) {
      Result res;
      ok = run(plant, &r, solver, (Case)kind, o->batches, &res);
      if (!ok) break;
      printf("%-34s %-34s %10.3f %10.3f %11.0fx %11.0fx\n", solver_name, case_names[kind], res.median_us,
             res.min_us, COMM_STEP * 1e6 / res.median_us, COMM_STEP * 1e6 / res.min_us);
      if (kind == CASE_STEP) step_us = res.median_us;
      if (kind == CASE_CONTROL)
        printf("%-34s   reading the 12 controller outputs adds %.1f %% to the step (median)\n", "",
               100.0 * (res.median_us - step_us) / step_us);
      if (kind == CASE_ALL)
        printf("%-34s   pose after 1 s: x %.6e m, y %.6e m, z %.6f m, phi %.6e rad\n", "", res.pose[0],
               res.pose[1], res.pose[2], res.pose[3]);
    }
  }
  if (ok) {
    printf("\ntarget (context): RK4 <= 3 us per 1-ms step (> 300x real time). Against MuJoCo's mj_step on the\n"
           "same mechanism, measured in one run: bench/engines_bench.py (the control-tick ratios).\n");
  }
  return ok;
}

const Subcommand step_subcommand = {"step", "one 1-ms communication step, four amounts of output read", step_run,
                                    BATCHES, BATCHES, "--solver 0|1 (one solver only)"};
