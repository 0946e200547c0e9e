/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench compare: one simulated second of the comparison test at a
 * 1 ms step through the C API (pkm_advance_fn, the forces at the stage times
 * from a table as MuJoCo's from an array) and through the plant FMU (F held
 * at each tick's midpoint or as a ramp), the cases below. An untimed run of
 * the whole 1.5 s test records t, x, y, z, phi, rho1 and ||C(q)||: --out DIR
 * writes DIR/<case>.csv and DIR/summary.csv for bench/engines_bench.py. */
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
  int fmu, solver;             /* through the plant FMU, else the C API; PKM_SOLVER_RK4 or _CVODE */
  double rtol;                 /* atol: rtol / 100 */
  int one_call, outputs, ramp; /* C API: the second in one call; FMU: outputs read (-1 all), F as a ramp */
  double target;               /* bench/engines_bench.py's: at least this many times MuJoCo's mj_step (0: none) */
} Case;

#define RK4 PKM_SOLVER_RK4
#define CVODE PKM_SOLVER_CVODE
static Case cases[] = {
    {"capi_rk4", "C API: RK4, 1 ms", 0, RK4, 1e-8, 0, 0, 0, 10},
    {"capi_cvode", "C API: CVODE (default rtol 1e-8), stop every 1 ms", 0, CVODE, 1e-8, 0, 0, 0, 10},
    {"capi_cvode_tight", "C API: CVODE (rtol 1e-12), stop every 1 ms", 0, CVODE, 1e-12, 0, 0, 0, 10},
    {"capi_rk4_one_call", "C API: RK4, 1 ms, one call per second", 0, RK4, 1e-8, 1, 0, 0, 0},
    {"capi_cvode_one_call", "C API: CVODE (rtol 1e-12), own steps, one call", 0, CVODE, 1e-12, 1, 0, 0, 10},
    {"fmu_rk4_step", "plant FMU: RK4, 1 ms, no output", 1, RK4, 1e-8, 0, 0, 0, 0},
    {"fmu_rk4", "plant FMU: RK4, 1 ms, + get x, y, z, phi", 1, RK4, 1e-8, 0, 4, 0, 0},
    {"fmu_rk4_ctrl12", "plant FMU: RK4, 1 ms, + get 12 controller outputs", 1, RK4, 1e-8, 0, 12, 0, 15},
    {"fmu_rk4_all", "plant FMU: RK4, 1 ms, + get every Real output", 1, RK4, 1e-8, 0, -1, 0, 0},
    {"fmu_cvode_step", "plant FMU: CVODE (rtol 1e-8), no output", 1, CVODE, 1e-8, 0, 0, 0, 0},
    {"fmu_cvode", "plant FMU: CVODE (rtol 1e-8), + get x, y, z, phi", 1, CVODE, 1e-8, 0, 4, 0, 0},
    {"fmu_cvode_ctrl12", "plant FMU: CVODE (rtol 1e-8), + get 12 controller outputs", 1, CVODE, 1e-8, 0, 12, 0, 0},
    {"fmu_cvode_all", "plant FMU: CVODE (rtol 1e-8), + get every Real output", 1, CVODE, 1e-8, 0, -1, 0, 0},
    {"fmu_cvode_ramp_ctrl12", "plant FMU: CVODE (rtol 1e-8), continued, + get 12 controller outputs", 1, CVODE, 1e-8,
     0, 12, 1, 10}};
#define N_CASES (sizeof cases / sizeof cases[0])
typedef struct {
  double median, min, max_c; /* s per simulated second; m */
} Result;
static Result results[N_CASES];

static double times[STEPS_TEST + 1], rows[STEPS_TEST + 1][6]; /* t; x, y, z, phi, rho1, ||C|| */

static FILE* open_csv(const char* dir, const char* name) {
  char path[1024];
  FILE* fp;
  snprintf(path, sizeof path, "%s/%s.csv", dir, name);
  if (!(fp = fopen(path, "w"))) fprintf(stderr, "pkm_fmu_bench: cannot write %s\n", path);
  return fp;
}

static int write_rows(const char* dir, const char* name, int n) {
  FILE* fp = dir ? open_csv(dir, name) : NULL;
  if (!dir || !fp) return !dir;
  fprintf(fp, "t,x,y,z,phi,rho1,constraint_residual\n");
  for (int k = 0; k < n; ++k)
    fprintf(fp, "%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.6e\n", times[k], rows[k][0], rows[k][1], rows[k][2],
            rows[k][3], rows[k][4], rows[k][5]);
  fclose(fp);
  return 1;
}

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

static int run_capi(int batches, const char* dir, const Case* c, Result* r) {
  static const char* const names[] = {"g", "solver", "rk4_step", "rtol", "atol"};
  const double values[] = {0.0, c->solver, STEP, c->rtol, c->rtol / 100.0};
  pkm_model* m = NULL;
  pkm_outputs o = {.size = sizeof(pkm_outputs)};
  pkm_state state = {.size = sizeof(pkm_state)};
  double per[MAX_BATCHES], u[PKM_PLANT_INPUTS] = {0.0};
  int n = 0, ok = pkm_create(&m) == PKM_OK && pkm_set_parameters(m, 5, names, values) == PKM_OK;
  for (int b = -1; ok && b < batches; ++b) { /* one warm-up, then the batches */
    ok = pkm_init_pose(m, 0.0, P0, NULL) == PKM_OK;
    const double t0 = bench_now();
    for (int k = c->one_call ? STEPS_TIMED - 1 : 0; ok && k < STEPS_TIMED; ++k)
      ok = pkm_advance_fn(m, (k + 1) * STEP, input_callback, NULL, 1) == PKM_OK && pkm_get_state(m, &state) == PKM_OK;
    if (b >= 0) per[b] = bench_now() - t0;
  }
  if (ok) r->median = bench_median(per, (size_t)batches, &r->min);
  ok = ok && pkm_init_pose(m, 0.0, P0, NULL) == PKM_OK;
  for (int k = 0; ok && k <= STEPS_TEST; k += c->one_call ? STEPS_TEST / 3 : 1, ++n) {
    forces(k * STEP, u);
    ok = (k == 0 || pkm_advance_fn(m, k * STEP, input_callback, NULL, 1) == PKM_OK) &&
         pkm_get_outputs(m, u, &o) == PKM_OK;
    times[n] = k * STEP;
    memcpy(rows[n], o.pose, sizeof o.pose);
    rows[n][4] = o.rho[0];
    rows[n][5] = o.constraint_residual;
    r->max_c = fmax(r->max_c, o.constraint_residual);
  }
  if (!ok) fprintf(stderr, "pkm_fmu_bench compare: %s: %s\n", c->name, m ? pkm_last_error(m) : "pkm_create failed");
  pkm_destroy(m);
  return ok && write_rows(dir, c->name, n);
}

static double held[STEPS_TEST][4], ramp[STEPS_TEST][4], slope[STEPS_TEST][4];

/* vr: the recorded x, y, z, phi, rho[1], constraint_residual, then the parameters rk4_step, g, z0, rtol, atol. */
static int run_fmu(const Plant* plant, const fmi2ValueReference* vr, const fmi2ValueReference* all, size_t n_all,
                   int batches, const char* dir, const Case* c, Result* r) {
  const fmi2Real settings[5] = {STEP, 0.0, P0[2], c->rtol, c->rtol / 100.0};
  fmi2FMUstate home = NULL;
  fmi2Component inst = instantiate(plant, FMI2_CS, c->name, c->solver, 5, vr + 6, settings, &home);
  Ticks t = {STEP, STEPS_TIMED, c->ramp ? ramp : held, c->ramp ? slope : NULL, c->outputs < 0 ? all : plant->control,
             c->outputs < 0 ? n_all : (size_t)c->outputs, NULL, NULL};
  double per[MAX_BATCHES];
  int ok = inst != NULL;
  for (int b = -1; ok && b < batches; ++b) { /* one warm-up, then the batches, each from the initialised state */
    double s = -1.0;
    ok = plant->fmu.fmi2SetFMUstate(inst, home) == fmi2OK && (s = run_ticks(plant, inst, &t, 0.0)) >= 0.0;
    if (b >= 0) per[b] = s;
  }
  if (ok) r->median = bench_median(per, (size_t)batches, &r->min);
  /* the untimed 1.5 s run: the pose, rho1 and the constraint residual after every tick */
  t.n = STEPS_TEST, t.out = vr, t.n_out = 6, t.record = rows[1];
  ok = ok && plant->fmu.fmi2SetFMUstate(inst, home) == fmi2OK &&
       plant->fmu.fmi2GetReal(inst, vr, 6, rows[0]) == fmi2OK && run_ticks(plant, inst, &t, 0.0) >= 0.0;
  for (int k = 0; ok && k <= STEPS_TEST; ++k) times[k] = k * STEP, r->max_c = fmax(r->max_c, rows[k][5]);
  if (inst && !free_instance(plant, FMI2_CS, inst, &home)) ok = 0;
  return ok && write_rows(dir, c->name, STEPS_TEST + 1);
}

/* How a case's forces reach the integrator (bench/engines_bench.py's column). */
static const char* forces_of(const Case* c) {
  if (c->fmu) return c->ramp ? "ramp: value and slope each tick" : "midpoint-held";
  return c->solver == RK4 ? "at stage times" : "at solver times";
}

static int compare_run(const Plant* plant, const Options* o) {
  static const char* const names[] = {"x", "y", "z", "phi", "rho[1]", "constraint_residual", "rk4_step", "g", "z0",
                                      "rtol", "atol"};
  fmi2ValueReference vr[11], all[MAX_OUTPUTS];
  const size_t n_all = real_outputs(plant->text, all, MAX_OUTPUTS);
  size_t i;
  int ok = n_all > 0 && lookup_value_references(plant, names, 11, vr);
  for (int k = 0; k <= 2 * STEPS_TEST; ++k) force_table[k] = 0.02 * sin(2.0 * PI * (0.5 * STEP * k) / 1.5);
  for (int k = 0; k < STEPS_TEST; ++k) {
    forces((k + 0.5) * STEP, held[k]);
    forces(k * STEP, ramp[k]);
    forces((k + 1) * STEP, slope[k]);
    for (i = 0; i < 4; ++i) slope[k][i] = (slope[k][i] - ramp[k][i]) / STEP;
  }
  printf("the comparison test (docs/model.md; g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s)) at a 1 ms step; "
         "median of %d batches after 1 warm-up\n\n", o->batches);
  for (i = 0; ok && i < N_CASES; ++i)
    ok = cases[i].fmu ? run_fmu(plant, vr, all, n_all, o->batches, o->out, &cases[i], &results[i])
                      : run_capi(o->batches, o->out, &cases[i], &results[i]);
  if (!ok) return 0;
  printf("%-22s %-68s %12s %12s %12s %14s\n", "case", "what", "median ms/s", "min ms/s", "RT (median)", "max ||C|| (m)");
  for (i = 0; i < N_CASES; ++i)
    printf("%-22s %-68s %12.4f %12.4f %11.0fx %14.2e\n", cases[i].name, cases[i].what, 1e3 * results[i].median,
           1e3 * results[i].min, 1.0 / results[i].median, results[i].max_c);
#define ADDS(i, base) (100.0 * (results[i].median / results[base].median - 1.0)) /* %: case i against base */
  printf("\nreading the 12 controller outputs adds %.1f %% to an RK4 tick (target <= 10 %%), %.1f %% to a CVODE one "
         "restarted; every output %.1f %%, %.1f %%\n", ADDS(7, 5), ADDS(11, 9), ADDS(8, 5), ADDS(12, 9));
#undef ADDS
  printf("target (context): an RK4 tick with the 12 outputs <= 3 us (> 300x real time): %.3f us, %s\n",
         1e3 * results[7].median, results[7].median <= 3e-3 ? "ok" : "OVER");
  if (o->out) {
    FILE* fp = open_csv(o->out, "summary");
    if (!fp) return 0;
    fprintf(fp, "case,what,forces,median_s_per_sim_s,min_s_per_sim_s,max_constraint_residual,target_vs_mujoco\n");
    for (i = 0; i < N_CASES; ++i)
      fprintf(fp, "%s,\"%s\",%s,%.6e,%.6e,%.6e,%g\n", cases[i].name, cases[i].what, forces_of(&cases[i]),
              results[i].median, results[i].min, results[i].max_c, cases[i].target);
    fclose(fp);
  }
  return 1;
}

const Subcommand compare_subcommand = {
    "compare", "one simulated second of the comparison test, C API and FMU (for bench/engines_bench.py)",
    compare_run, 21, MAX_BATCHES, "--out DIR (the runs as CSV)", 0};
