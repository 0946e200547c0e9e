/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench compare: one simulated second of the comparison test at 1 ms through the C API and the plant FMU;
 * --out DIR: the untimed runs of the whole test (runs.csv) and the summary as CSV, for bench/engines_bench.py. */
#include "fmu_bench.h"
#include "pkm4puu/pkm.h"

#define STEP 1e-3
#define STEPS_TIMED 1000 /* one simulated second */
#define STEPS_TEST 1500  /* the whole test */
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
static double median[N_CASES], min[N_CASES], max_c[N_CASES]; /* s per simulated second; m */

static double times[STEPS_TEST + 1], rows[STEPS_TEST + 1][6]; /* t; x, y, z, phi, rho1, ||C|| */

static FILE* open_csv(const char* dir, const char* name, const char* header) {
  char path[1024];
  FILE* fp;
  snprintf(path, sizeof path, "%s/%s.csv", dir, name);
  if (!(fp = fopen(path, "w"))) fprintf(stderr, "pkm_fmu_bench: cannot write %s\n", path);
  if (fp) fprintf(fp, "%s\n", header);
  return fp;
}

static double force_table[2 * STEPS_TEST + 1][4]; /* F at t_j = j h/2 */

/* The inputs u[PKM_PLANT_INPUTS] (F[1..4], then the wrench and the torques: zero, as the library passes them). */
static void input_callback(void* user, double t, double u[PKM_PLANT_INPUTS]) {
  const long j = lround(t / (0.5 * STEP));
  (void)user;
  if (j >= 0 && j <= 2 * STEPS_TEST && fabs(t / (0.5 * STEP) - (double)j) < 1e-9)
    memcpy(u, force_table[j], sizeof force_table[j]);
  else
    forces(t, u); /* CVODE's own stage times */
}

static double held[STEPS_TEST][4], ramp[STEPS_TEST][4], slope[STEPS_TEST][4];
static const Plant* plant;
static pkm_model* models[N_CASES]; /* the C API's cases' */
static fmi2Component insts[N_CASES]; /* the FMU's cases', with their state after initialisation and their ticks */
static fmi2FMUstate homes[N_CASES];
static Ticks ticks[N_CASES];

/* Case i's model or instance. vr: the recorded x, y, z, phi, rho[1], constraint_residual, then the parameters
 * rk4_step, g, z0, rtol, atol; all: every Real output. */
static int set_up(int i, const fmi2ValueReference* vr, const fmi2ValueReference* all, size_t n_all) {
  static const char* const names[] = {"g", "solver", "rk4_step", "rtol", "atol"};
  const Case* c = &cases[i];
  const double values[] = {0.0, c->solver, STEP, c->rtol, c->rtol / 100.0};
  const fmi2Real settings[5] = {STEP, 0.0, P0[2], c->rtol, c->rtol / 100.0};
  const Ticks t = {STEP, STEPS_TIMED, c->ramp ? ramp : held, c->ramp ? slope : NULL,
                   c->outputs < 0 ? all : plant->control, c->outputs < 0 ? n_all : (size_t)c->outputs, NULL, NULL};
  ticks[i] = t;
  if (c->fmu)
    return (insts[i] = instantiate(plant, FMI2_CS, c->name, c->solver, 5, vr + 6, settings, &homes[i])) != NULL;
  if (pkm_create(&models[i]) == PKM_OK && pkm_set_parameters(models[i], 5, names, values) == PKM_OK) return 1;
  return fprintf(stderr, "pkm_fmu_bench compare: %s: %s\n", c->name, pkm_last_error(models[i])), 0;
}

/* One timed simulated second of case i from the initial state (set untimed): its wall time, <= 0 on failure. */
static double batch(int i) {
  pkm_state state = {.size = sizeof(pkm_state)};
  double t0;
  int ok;
  if (cases[i].fmu) return run_ticks(plant, insts[i], homes[i], &ticks[i]);
  ok = pkm_init_pose(models[i], 0.0, P0, NULL) == PKM_OK;
  t0 = bench_now();
  for (int k = cases[i].one_call ? STEPS_TIMED - 1 : 0; ok && k < STEPS_TIMED; ++k)
    ok = pkm_advance_fn(models[i], (k + 1) * STEP, input_callback, NULL, 1) == PKM_OK &&
         pkm_get_state(models[i], &state) == PKM_OK;
  if (ok) return bench_now() - t0;
  return fprintf(stderr, "pkm_fmu_bench compare: %s: %s\n", cases[i].name, pkm_last_error(models[i])), 0.0;
}

/* Case i's untimed run of the whole 1.5 s test: the pose, rho1 and the constraint residual after every tick (the
 * one-call cases: every 0.5 s), as rows of `runs` if given. */
static int record(int i, const fmi2ValueReference* vr, FILE* runs) {
  pkm_model* m = models[i];
  pkm_outputs o = {.size = sizeof(pkm_outputs)};
  double u[PKM_PLANT_INPUTS] = {0.0};
  Ticks t = ticks[i];
  int n = 0, ok = 1;
  if (cases[i].fmu) {
    t.n = STEPS_TEST, t.out = vr, t.n_out = 6, t.record = rows[0];
    ok = run_ticks(plant, insts[i], homes[i], &t) >= 0.0;
    for (n = 0; n <= STEPS_TEST; ++n) times[n] = n * STEP;
  } else {
    ok = pkm_init_pose(m, 0.0, P0, NULL) == PKM_OK;
    for (int k = 0; ok && k <= STEPS_TEST; k += cases[i].one_call ? STEPS_TEST / 3 : 1, ++n) {
      forces(k * STEP, u);
      ok = (k == 0 || pkm_advance_fn(m, k * STEP, input_callback, NULL, 1) == PKM_OK) &&
           pkm_get_outputs(m, u, &o) == PKM_OK;
      times[n] = k * STEP;
      memcpy(rows[n], o.pose, sizeof o.pose);
      rows[n][4] = o.rho[0];
      rows[n][5] = o.constraint_residual;
    }
    if (!ok) fprintf(stderr, "pkm_fmu_bench compare: %s: %s\n", cases[i].name, pkm_last_error(m));
  }
  for (int k = 0; ok && k < n; ++k) max_c[i] = fmax(max_c[i], rows[k][5]);
  for (int k = 0; ok && runs && k < n; ++k)
    fprintf(runs, "%s,%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.6e\n", cases[i].name, times[k], rows[k][0], rows[k][1],
            rows[k][2], rows[k][3], rows[k][4] - rows[0][4], rows[k][5]);
  return ok;
}

/* How a case's forces reach the integrator (bench/engines_bench.py's column). */
static const char* forces_of(const Case* c) {
  if (c->fmu) return c->ramp ? "ramp: value and slope each tick" : "midpoint-held";
  return c->solver == RK4 ? "at stage times" : "at solver times";
}

static int compare_run(const Plant* p, const Options* o) {
  static const char* const names[] = {"x", "y", "z", "phi", "rho[1]", "constraint_residual", "rk4_step", "g", "z0",
                                      "rtol", "atol"};
  FILE* runs = o->out ? open_csv(o->out, "runs", "case,t,x,y,z,phi,delta_rho1,constraint") : NULL;
  fmi2ValueReference vr[11], all[MAX_OUTPUTS];
  const size_t n_all = real_outputs(p->text, all, MAX_OUTPUTS);
  size_t i;
  int ok = n_all > 0 && lookup_value_references(p, names, 11, vr) && (runs || !o->out);
  plant = p;
  for (int k = 0; k <= 2 * STEPS_TEST; ++k) forces(0.5 * STEP * k, force_table[k]);
  for (int k = 0; k < STEPS_TEST; ++k) /* held at the midpoint; the ramp's value and slope */
    for (i = 0; i < 4; ++i)
      held[k][i] = force_table[2 * k + 1][i], ramp[k][i] = force_table[2 * k][i],
      slope[k][i] = (force_table[2 * k + 2][i] - ramp[k][i]) / STEP;
  printf("the comparison test (docs/model.md; g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s)) at a 1 ms step; "
         "median of %d batches after 1 warm-up, the cases interleaved\n\n", o->batches);
  for (i = 0; ok && i < N_CASES; ++i) ok = set_up((int)i, vr, all, n_all);
  ok = ok && time_cases(N_CASES, o->batches, batch, median, min);
  for (i = 0; ok && i < N_CASES; ++i) ok = record((int)i, vr, runs);
  if (runs) fclose(runs);
  for (i = 0; i < N_CASES; ++i) {
    if (insts[i] && !free_instance(p, FMI2_CS, insts[i], &homes[i])) ok = 0;
    pkm_destroy(models[i]);
  }
  if (!ok) return 0;
  printf("%-22s %-68s %12s %12s %12s %14s\n", "case", "what", "median ms/s", "min ms/s", "RT (median)", "max ||C|| (m)");
  for (i = 0; i < N_CASES; ++i)
    printf("%-22s %-68s %12.4f %12.4f %11.0fx %14.2e\n", cases[i].name, cases[i].what, 1e3 * median[i], 1e3 * min[i],
           1.0 / median[i], max_c[i]);
#define ADDS(i, base) (100.0 * (median[i] / median[base] - 1.0)) /* %: case i against base */
  printf("\nreading the 12 controller outputs adds %.1f %% to an RK4 tick (target <= 10 %%), %.1f %% to a CVODE one "
         "restarted; every output %.1f %%, %.1f %%\n", ADDS(7, 5), ADDS(11, 9), ADDS(8, 5), ADDS(12, 9));
#undef ADDS
  printf("target (context): an RK4 tick with the 12 outputs <= 3 us (> 300x real time): %.3f us, %s\n",
         1e3 * median[7], median[7] <= 3e-3 ? "ok" : "OVER");
  if (o->out) {
    FILE* fp = open_csv(o->out, "summary", "case,what,forces,median_s_per_sim_s,min_s_per_sim_s,target_vs_mujoco");
    if (!fp) return 0;
    for (i = 0; i < N_CASES; ++i)
      fprintf(fp, "%s,\"%s\",%s,%.6e,%.6e,%g\n", cases[i].name, cases[i].what, forces_of(&cases[i]), median[i],
              min[i], cases[i].target);
    fclose(fp);
  }
  return 1;
}

const Subcommand compare_subcommand = {
    "compare", "one simulated second of the comparison test, C API and FMU (for bench/engines_bench.py)",
    compare_run, 21, "--out DIR (the runs as CSV)", 0};
