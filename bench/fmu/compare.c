/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench compare: one simulated second of the comparison test (docs/
 * model.md) at a 1 ms step through the C API (pkm_advance_fn to each
 * millisecond, the forces at the stage times from a table, as MuJoCo's from
 * an array; or the second in one call) and through the plant FMU (SetReal
 * of F held at the tick's midpoint or as a ramp, DoStep, GetReal of no
 * output, the pose, the 12 controller outputs or every Real output); one
 * warm-up, then the batches; median and minimum. An untimed run of the whole
 * 1.5 s test records t, x, y, z, phi, rho1 and ||C(q)||: --out DIR writes
 * DIR/<case>.csv and DIR/summary.csv for bench/engines_bench.py.
 *
 *   pkm_fmu_bench compare [--out DIR] [--batches N] */
#define _GNU_SOURCE

#include <math.h>

#include "fmu_bench.h"
#include "pkm4puu/pkm.h"

#define STEP 1e-3
#define STEPS_TIMED 1000 /* one simulated second */
#define STEPS_TEST 1500  /* the whole test */
#define MAX_BATCHES 101
#define MAX_OUTPUTS 256

static const double P0[4] = {0.0, 0.0, 0.05, 0.0};

static void forces(double t, double F[4]) { /* F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s) */
  F[0] = 0.02 * sin(2.0 * PI * t / 1.5), F[1] = F[2] = 0.0, F[3] = -F[0];
}

typedef struct {
  const char *name, *what;
  int solver, ramp, outputs; /* FMU: solver (1 RK4, 0 CVODE), forces as a ramp, outputs read: 0, 4, 12, -1 all */
  double median, min, max_c; /* s per simulated second; m */
} Case;

static double rows[STEPS_TEST + 1][7]; /* t, x, y, z, phi, rho1, ||C|| */

static FILE* open_csv(const char* dir, const char* name) {
  char path[1024];
  FILE* fp;
  snprintf(path, sizeof path, "%s/%s.csv", dir, name);
  if (!(fp = fopen(path, "w"))) fprintf(stderr, "pkm_fmu_bench: cannot write %s\n", path);
  return fp;
}

static int write_rows(const char* dir, const char* name, int n) {
  FILE* fp;
  int k;
  if (!dir) return 1;
  if (!(fp = open_csv(dir, name))) return 0;
  fprintf(fp, "t,x,y,z,phi,rho1,constraint_residual\n");
  for (k = 0; k < n; ++k)
    fprintf(fp, "%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.6e\n", rows[k][0], rows[k][1], rows[k][2], rows[k][3],
            rows[k][4], rows[k][5], rows[k][6]);
  fclose(fp);
  return 1;
}

/* ------------------------------------------------------------ the C API */
static double force_table[2 * STEPS_TEST + 1]; /* F1 at t_j = j h/2 */

/* The inputs u[PKM_PLANT_INPUTS] (F[1..4], then the wrench and the torques: zero, as the library passes them). */
static void input_callback(void* user, double t, double u[PKM_PLANT_INPUTS]) {
  const long j = lround(t / (0.5 * STEP));
  (void)user;
  if (j >= 0 && j <= 2 * STEPS_TEST && fabs(t / (0.5 * STEP) - (double)j) < 1e-9) {
    u[0] = force_table[j], u[1] = u[2] = 0.0, u[3] = -force_table[j];
  } else {
    forces(t, u); /* CVODE's own stage times */
  }
}

#define PKM_CHECK(call)                                                                  \
  if ((call) != PKM_OK) {                                                                \
    fprintf(stderr, "pkm_fmu_bench compare: %s: %s\n", #call, pkm_last_error(m));        \
    pkm_destroy(m);                                                                      \
    return 0;                                                                            \
  }

/* A C API run's solver settings, as parameters (pkm_set_parameters). */
typedef struct {
  double solver, rk4_step, rtol, atol;
} Settings;

/* one_call: the second as a single pkm_advance_fn (the integrator's own steps) instead of 1000 calls. */
static int run_capi(const Settings* settings, int one_call, int batches, const char* dir, Case* c) {
  static const char* const names[] = {"g", "solver", "rk4_step", "rtol", "atol"};
  const double values[] = {0.0, settings->solver, settings->rk4_step, settings->rtol, settings->atol};
  pkm_model* m = NULL;
  pkm_outputs o = {.size = sizeof(pkm_outputs)};
  pkm_state state = {.size = sizeof(pkm_state)};
  double per[MAX_BATCHES], u[PKM_PLANT_INPUTS] = {0.0};
  int b, k, n = 0;
  if (pkm_create(&m) != PKM_OK) return fprintf(stderr, "pkm_fmu_bench compare: pkm_create failed\n"), 0;
  PKM_CHECK(pkm_set_parameters(m, 5, names, values));
  for (b = -1; b < batches; ++b) {
    double t0;
    PKM_CHECK(pkm_init_pose(m, 0.0, P0, NULL));
    t0 = bench_now();
    for (k = one_call ? STEPS_TIMED - 1 : 0; k < STEPS_TIMED; ++k) {
      PKM_CHECK(pkm_advance_fn(m, (k + 1) * STEP, input_callback, NULL, 1));
      PKM_CHECK(pkm_get_state(m, &state));
    }
    if (b >= 0) per[b] = bench_now() - t0;
  }
  c->median = bench_median(per, (size_t)batches, &c->min);
  PKM_CHECK(pkm_init_pose(m, 0.0, P0, NULL));
  for (k = 0; k <= STEPS_TEST; k += one_call ? STEPS_TEST / 3 : 1, ++n) {
    if (k > 0) PKM_CHECK(pkm_advance_fn(m, k * STEP, input_callback, NULL, 1));
    forces(k * STEP, u);
    PKM_CHECK(pkm_get_outputs(m, u, &o));
    rows[n][0] = k * STEP;
    memcpy(&rows[n][1], o.pose, sizeof o.pose);
    rows[n][5] = o.rho[0];
    rows[n][6] = o.constraint_residual;
    c->max_c = fmax(c->max_c, o.constraint_residual);
  }
  pkm_destroy(m);
  return write_rows(dir, c->name, n);
}

static double held[STEPS_TEST][4], ramp[STEPS_TEST][4], slope[STEPS_TEST][4];
static double recorded[STEPS_TEST][6];

static int run_fmu(const Plant* plant, const fmi2ValueReference* md, const fmi2ValueReference* all, size_t n_all,
                   int batches, const char* dir, Case* c) {
  const fmi2Real settings[3] = {STEP, 0.0, P0[2]}; /* rk4_step, g, z0 */
  fmi2FMUstate home = NULL;
  fmi2Component inst = instantiate_plant(plant, c->name, c->solver, 3, md, settings, &home);
  fmi2ValueReference record[6];
  Ticks t = {STEP, STEPS_TIMED, c->ramp ? ramp : held, c->ramp ? slope : NULL, c->outputs < 0 ? all : plant->control,
             c->outputs < 0 ? n_all : (size_t)c->outputs, NULL, NULL};
  double per[MAX_BATCHES];
  int b, k, ok = inst != NULL;
  for (b = -1; ok && b < batches; ++b) {  /* one warm-up, then the batches, each from the state after initialisation */
    double s = -1.0;
    ok = plant->fmu.fmi2SetFMUstate(inst, home) == fmi2OK && (s = run_ticks(plant, inst, &t, 0.0)) >= 0.0;
    if (b >= 0) per[b] = s;
  }
  if (ok) c->median = bench_median(per, (size_t)batches, &c->min);
  /* the untimed 1.5 s run: the pose, rho1 and the constraint residual after every tick */
  memcpy(record, plant->control, 4 * sizeof record[0]);
  memcpy(record + 4, md + 3, 2 * sizeof record[0]);
  t.n = STEPS_TEST, t.out = record, t.n_out = 6, t.record = &recorded[0][0];
  ok = ok && plant->fmu.fmi2SetFMUstate(inst, home) == fmi2OK &&
       plant->fmu.fmi2GetReal(inst, record, 6, &rows[0][1]) == fmi2OK && run_ticks(plant, inst, &t, 0.0) >= 0.0;
  for (k = 0; ok && k <= STEPS_TEST; ++k) {
    rows[k][0] = k * STEP;
    if (k > 0) memcpy(&rows[k][1], recorded[k - 1], sizeof recorded[0]);
    c->max_c = fmax(c->max_c, rows[k][6]);
  }
  if (inst && !free_plant(plant, inst, &home)) ok = 0;
  return ok && write_rows(dir, c->name, STEPS_TEST + 1);
}

static int compare_run(const Plant* plant, const Options* o) {
  static const char* const names[] = {"rk4_step", "g", "z0", "rho[1]", "constraint_residual"};
  static Case cases[] = {
      {"capi_rk4", "C API, RK4 1 ms, forces at stage times", 1, 0, 0, 0, 0, 0},
      {"capi_cvode", "C API, CVODE rtol 1e-8 (default)", 0, 0, 0, 0, 0, 0},
      {"capi_cvode_tight", "C API, CVODE rtol 1e-12", 0, 0, 0, 0, 0, 0},
      {"capi_rk4_one_call", "C API, RK4 1 ms, one call for the second", 1, 0, 0, 0, 0, 0},
      {"capi_cvode_one_call", "C API, CVODE rtol 1e-12, one call", 0, 0, 0, 0, 0, 0},
      {"fmu_rk4_step", "plant FMU, RK4 1 ms, held F, no output", 1, 0, 0, 0, 0, 0},
      {"fmu_rk4", "plant FMU, RK4 1 ms, midpoint-held F", 1, 0, 4, 0, 0, 0},
      {"fmu_rk4_ctrl12", "plant FMU, RK4 1 ms, held F, 12 outputs", 1, 0, 12, 0, 0, 0},
      {"fmu_rk4_all", "plant FMU, RK4 1 ms, held F, every output", 1, 0, -1, 0, 0, 0},
      {"fmu_cvode_step", "plant FMU, CVODE rtol 1e-8, held F, no output", 0, 0, 0, 0, 0, 0},
      {"fmu_cvode", "plant FMU, CVODE rtol 1e-8, midpoint-held F", 0, 0, 4, 0, 0, 0},
      {"fmu_cvode_ctrl12", "plant FMU, CVODE 1e-8, held F, 12 outputs", 0, 0, 12, 0, 0, 0},
      {"fmu_cvode_all", "plant FMU, CVODE 1e-8, held F, every output", 0, 0, -1, 0, 0, 0},
      {"fmu_cvode_ramp_ctrl12", "plant FMU, CVODE 1e-8, F as ramp, 12 outputs", 0, 1, 12, 0, 0, 0}};
  const size_t n_cases = sizeof cases / sizeof cases[0];
  fmi2ValueReference md[5], all[MAX_OUTPUTS];
  const size_t n_all = real_outputs(plant->text, all, MAX_OUTPUTS);
  /* RK4 at the 1 ms step; CVODE Adams at the default rtol 1e-8, atol 1e-10, and tight */
  const Settings rk4 = {PKM_SOLVER_RK4, STEP, 1e-8, 1e-10}, cvode = {PKM_SOLVER_CVODE, STEP, 1e-8, 1e-10},
                 tight = {PKM_SOLVER_CVODE, STEP, 1e-12, 1e-14};
  size_t i;
  int k, ok = n_all > 0 && lookup_value_references(plant, names, 5, md);
  for (k = 0; k <= 2 * STEPS_TEST; ++k) force_table[k] = 0.02 * sin(2.0 * PI * (0.5 * STEP * k) / 1.5);
  for (k = 0; k < STEPS_TEST; ++k) {
    forces((k + 0.5) * STEP, held[k]);
    forces(k * STEP, ramp[k]);
    forces((k + 1) * STEP, slope[k]);
    for (i = 0; i < 4; ++i) slope[k][i] = (slope[k][i] - ramp[k][i]) / STEP;
  }
  printf("pkm_fmu_bench compare: one simulated second of the comparison test (docs/model.md; g = 0,\n"
         "F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s)) at a 1 ms step; median of %d batches after 1 warm-up\n",
         o->batches);
  bench_print_machine();
  printf("fmu:     %s\n\n", plant->so);
  for (i = 0; ok && i < n_cases; ++i) {
    Case* c = &cases[i];
    c->max_c = 0.0;
    if (i < 5)
      ok = run_capi(i == 0 || i == 3 ? &rk4 : i == 1 ? &cvode : &tight, i >= 3, o->batches, o->out, c);
    else
      ok = run_fmu(plant, md, all, n_all, o->batches, o->out, c);
  }
  if (!ok) return 0;
  printf("%-22s %-46s %12s %12s %12s %14s\n", "case", "what", "median ms/s", "min ms/s", "RT (median)", "max ||C|| (m)");
  for (i = 0; i < n_cases; ++i)
    printf("%-22s %-46s %12.4f %12.4f %11.0fx %14.2e\n", cases[i].name, cases[i].what, 1e3 * cases[i].median,
           1e3 * cases[i].min, 1.0 / cases[i].median, cases[i].max_c);
  printf("\nreading the 12 controller outputs adds %.1f %% to an RK4 tick (target <= 10 %%), %.1f %% to a CVODE one "
         "restarted; every output %.1f %%, %.1f %%\n",
         100.0 * (cases[7].median / cases[5].median - 1.0), 100.0 * (cases[11].median / cases[9].median - 1.0),
         100.0 * (cases[8].median / cases[5].median - 1.0), 100.0 * (cases[12].median / cases[9].median - 1.0));
  printf("target (context): an RK4 tick with the 12 outputs <= 3 us (> 300x real time): %.3f us, %s\n",
         1e3 * cases[7].median, cases[7].median <= 3e-3 ? "ok" : "OVER");
  if (o->out) {
    FILE* fp = open_csv(o->out, "summary");
    if (!fp) return 0;
    fprintf(fp, "case,what,median_s_per_sim_s,min_s_per_sim_s,max_constraint_residual\n");
    for (i = 0; i < n_cases; ++i)
      fprintf(fp, "%s,\"%s\",%.6e,%.6e,%.6e\n", cases[i].name, cases[i].what, cases[i].median, cases[i].min,
              cases[i].max_c);
    fclose(fp);
  }
  return 1;
}

const Subcommand compare_subcommand = {
    "compare", "one simulated second of the comparison test, C API and FMU (for bench/engines_bench.py)",
    compare_run, 21, MAX_BATCHES, "--out DIR (the runs as CSV)", 0};
