/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench compare: the cost of one simulated second of the paper's
 * comparison test (docs/model.md "The paper's two tests": from rest at P0, g = 0,
 * F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), F2 = F3 = 0) at a 1 ms step, through
 * this project's plain C API (libpkm.so, pkm.h) and through the plant FMU
 * (raw FMI 2.0 Co-Simulation calls, as a master would).
 * bench/engines_bench.py runs it beside MuJoCo and Pinocchio.
 *
 *   pkm_fmu_bench compare [--out DIR] [--batches N] [--fmu PKM4PUU.so] [--xml modelDescription.xml]
 *
 * Cases (each step is 1 ms of simulated time; 1000 steps = 1 simulated s):
 *   capi_rk4        pkm_advance_fn to the next millisecond, forces from a C
 *                   callback at the integrator's own stage times; RK4,
 *                   rk4_step 1 ms; then pkm_get_state (x, y, z, phi, rates)
 *   capi_cvode      the same with CVODE Adams at its defaults (rtol 1e-8,
 *                   atol 1e-10), not restarted between steps (continuous = 1)
 *   capi_cvode_tight  the same with rtol 1e-12, atol 1e-14
 *   capi_rk4_one_call, capi_cvode_one_call  RK4 and CVODE rtol 1e-12 with the
 *                   simulated second as a single pkm_advance_fn call (no
 *                   per-call overhead; CVODE then takes its own steps instead
 *                   of stopping at every millisecond)
 * The C API's forces F1 = -F4 come from a table at every half millisecond
 * (every RK4 stage time), as MuJoCo's controls come from an array; at other
 * times (CVODE's) the sine is evaluated.
 *   fmu_rk4         fmi2SetReal(F[1..4], held at the step's midpoint value) +
 *                   fmi2DoStep + fmi2GetReal(x, y, z, phi); solver = 1 (RK4,
 *                   rk4_step 1 ms)
 *   fmu_cvode       the same with solver = 0 (CVODE, rtol 1e-8, atol 1e-10;
 *                   the FMU restarts it every communication step)
 *   fmu_rk4_ctrl12  fmu_rk4 reading the 12 controller outputs (x, y, z, phi,
 *                   their rates, rho[1..4]) instead of the pose: a control
 *                   tick
 *   fmu_cvode_ramp_ctrl12  CVODE at its defaults, the forces as a continuous
 *                   ramp: each tick fmi2SetReal(F at t_k) and
 *                   fmi2SetRealInputDerivatives(slope (F(t_k+1) - F(t_k))/h),
 *                   the piecewise-linear interpolation of the sine through the
 *                   tick values, so each tick's value continues the last
 *                   tick's ramp and CVODE keeps its history across ticks;
 *                   + fmi2GetReal of the 12 controller outputs
 * Timing: a batch is 1 simulated second from rest at P0 (the initial state is
 * set up outside the timed region: pkm_init_pose, or fmi2SetFMUstate to the
 * state saved after initialisation); one untimed warm-up batch, then N timed
 * batches (default 21); median and minimum wall time per simulated second
 * (clock_gettime(CLOCK_MONOTONIC)).
 * Accuracy: after timing, one untimed run of the full 1.5 s test records, at
 * every 1 ms point (one-call cases: at 0, 0.5, 1 and 1.5 s, each reached by
 * one call), t, x, y, z, phi, rho1 and ||C(q)|| (pkm_get_outputs'
 * constraint_residual, the FMU's constraint_residual output); the largest
 * ||C(q)|| is printed, and with --out DIR the run is written to
 * DIR/<case>.csv and the summary to DIR/summary.csv. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>

#include "bench.h"
#include "pkm4puu/pkm.h"

#define STEP 1e-3          /* s */
#define STEPS_TIMED 1000   /* 1 simulated second */
#define STEPS_TEST 1500    /* the whole 1.5 s comparison test */
#define AMPLITUDE 0.02     /* N */
#define PERIOD 1.5         /* s */
#define MAX_BATCHES 101
#define NAME PKM_HARNESS_NAME " compare"

static const double P0[4] = {0.0, 0.0, 0.05, 0.0}; /* docs/model.md home pose */

static void forces(double t, double F[4]) {
  const double f = AMPLITUDE * sin(2.0 * PI * t / PERIOD);
  F[0] = f;
  F[1] = 0.0;
  F[2] = 0.0;
  F[3] = -f;
}

typedef struct {
  const char* name;
  const char* what;
  double median_s, min_s; /* per simulated second */
  double max_c;           /* m, over the 1.5 s test */
} Result;

/* One row of the 1.5 s run: t, x, y, z, phi, rho1, ||C||. */
typedef struct {
  double v[7];
} Row;

static Row rows[STEPS_TEST + 1];

static int write_rows(const char* dir, const char* name, int n_rows) {
  char path[1024];
  FILE* fp;
  int k;
  if (!dir) return 1;
  snprintf(path, sizeof path, "%s/%s.csv", dir, name);
  fp = fopen(path, "w");
  if (!fp) {
    fprintf(stderr, NAME ": cannot write %s\n", path);
    return 0;
  }
  fprintf(fp, "t,x,y,z,phi,rho1,constraint_residual\n");
  for (k = 0; k < n_rows; ++k)
    fprintf(fp, "%.6f,%.17g,%.17g,%.17g,%.17g,%.17g,%.6e\n", rows[k].v[0], rows[k].v[1], rows[k].v[2],
            rows[k].v[3], rows[k].v[4], rows[k].v[5], rows[k].v[6]);
  fclose(fp);
  return 1;
}

/* ------------------------------------------------------------ the C API */

/* F1(t) tabulated at every half step t_j = j h/2 (every RK4 stage time at
 * h = 1 ms, and every communication point), as MuJoCo gets its controls from
 * an array; other times (CVODE's own) evaluate the sine. */
#define TABLE_SIZE (2 * STEPS_TEST + 1)
static double force_table[TABLE_SIZE];

static void fill_force_table(void) {
  double F[4];
  int j;
  for (j = 0; j < TABLE_SIZE; ++j) {
    forces(0.5 * STEP * (double)j, F);
    force_table[j] = F[0];
  }
}

static void input_callback(void* user, double t, double F[PKM_PLANT_INPUTS]) {
  const double u = t / (0.5 * STEP);
  const long j = lround(u);
  (void)user;
  if (j >= 0 && j < TABLE_SIZE && fabs(u - (double)j) < 1e-9) {
    F[0] = force_table[j];
    F[3] = -force_table[j];
  } else {
    forces(t, F);
  }
}

#define PKM_CHECK(call)                                                                              \
  do {                                                                                               \
    const pkm_status s_ = (call);                                                                    \
    if (s_ != PKM_OK) {                                                                              \
      fprintf(stderr, NAME ": %s:%d: %s: %s (%s)\n", __FILE__, __LINE__, #call,       \
              pkm_status_string(s_), pkm_last_error(m));                                             \
      pkm_destroy(m);                                                                                \
      return 0;                                                                                      \
    }                                                                                                \
  } while (0)

/* The solver settings of a run, as parameters (pkm_set_parameters). */
typedef struct {
  double solver, rk4_step, rtol, atol;
} Settings;

/* one_call: the timed second is a single pkm_advance_fn(t_end = 1 s) (the
 * integrator's own steps, no stop at every millisecond) instead of 1000 calls. */
static int run_capi(const Settings* settings, int one_call, int batches, const char* out_dir, Result* res) {
  static const char* const names[] = {"g", "solver", "rk4_step", "rtol", "atol"};
  const double values[] = {0.0, settings->solver, settings->rk4_step, settings->rtol, settings->atol};
  pkm_model* m = NULL;
  double per[MAX_BATCHES], u[PKM_PLANT_INPUTS] = {0.0};
  pkm_outputs o = {.size = sizeof(pkm_outputs)};
  pkm_state s = {.size = sizeof(pkm_state)};
  int b, k;
  if (pkm_create(&m) != PKM_OK) {
    fprintf(stderr, NAME ": pkm_create failed\n");
    return 0;
  }
  PKM_CHECK(pkm_set_parameters(m, 5, names, values));
  for (b = -1; b < batches; ++b) {
    double t0;
    PKM_CHECK(pkm_init_pose(m, 0.0, P0, NULL));
    t0 = now_seconds();
    if (one_call) {
      PKM_CHECK(pkm_advance_fn(m, (double)STEPS_TIMED * STEP, input_callback, NULL, 1));
      PKM_CHECK(pkm_get_state(m, &s));
    } else {
      for (k = 0; k < STEPS_TIMED; ++k) {
        PKM_CHECK(pkm_advance_fn(m, (double)(k + 1) * STEP, input_callback, NULL, 1));
        PKM_CHECK(pkm_get_state(m, &s));
      }
    }
    if (b >= 0) per[b] = now_seconds() - t0;
  }
  res->median_s = median_min(per, batches, &res->min_s);
  /* the untimed 1.5 s run: outputs at every millisecond (one_call: at the
   * ends of single calls to 0.5, 1.0 and 1.5 s only) */
  res->max_c = 0.0;
  PKM_CHECK(pkm_init_pose(m, 0.0, P0, NULL));
  {
    const int stride = one_call ? STEPS_TEST / 3 : 1;
    int n_rows = 0;
    for (k = 0; k <= STEPS_TEST; k += stride, ++n_rows) {
      if (k > 0) PKM_CHECK(pkm_advance_fn(m, (double)k * STEP, input_callback, NULL, 1));
      forces((double)k * STEP, u);
      PKM_CHECK(pkm_get_outputs(m, u, &o));
      rows[n_rows].v[0] = (double)k * STEP;
      memcpy(&rows[n_rows].v[1], o.pose, sizeof o.pose);
      rows[n_rows].v[5] = o.rho[0];
      rows[n_rows].v[6] = o.constraint_residual;
      if (o.constraint_residual > res->max_c) res->max_c = o.constraint_residual;
    }
    pkm_destroy(m);
    return write_rows(out_dir, res->name, n_rows);
  }
}

/* ------------------------------------------------------------- the FMU */

/* Beyond the plant's F and controller outputs: the outputs recorded in the
 * 1.5 s run, the parameters set. */
typedef struct {
  fmi2ValueReference rho1, residual;
  fmi2ValueReference settings[3]; /* rk4_step, g, z0 */
} Fmi;

#define FMI_CHECK(call)                                                                              \
  do {                                                                                               \
    if ((call) != fmi2OK) {                                                                          \
      fprintf(stderr, NAME ": %s:%d: %s failed\n", __FILE__, __LINE__, #call);        \
      ok = 0;                                                                                        \
      goto done;                                                                                     \
    }                                                                                                \
  } while (0)

/* The forces of tick k (from t = k h to t + h) as a master gives them: held
 * at the midpoint value, or (ramp) the value at t with the slope to the next
 * tick's value, so the inputs are continuous from tick to tick. */
static void tick_forces(int k, int ramp, double F[4], double dF[4]) {
  const double t = (double)k * STEP;
  int i;
  if (!ramp) {
    forces(t + 0.5 * STEP, F);
    return;
  }
  forces(t, F);
  forces(t + STEP, dF);
  for (i = 0; i < 4; ++i) dF[i] = (dF[i] - F[i]) / STEP;
}

/* n_out: 4 (the pose) or 12 (the controller outputs); ramp: see tick_forces. */
static int run_fmu(const Plant* plant, const Fmi* md, int solver, int ramp, int n_out, int batches,
                   const char* out_dir, Result* res) {
  const Fmu* f = &plant->fmu;
  const fmi2ValueReference* pose_vr = plant->control; /* x, y, z, phi first */
  const fmi2Real settings[3] = {STEP, 0.0, P0[2]};   /* rk4_step, g, z0 (x0, y0, phi0 default to 0) */
  fmi2FMUstate home = NULL;
  fmi2Component c = instantiate_plant(plant, res->name, solver, 3, md->settings, settings, &home);
  const fmi2Integer order[4] = {1, 1, 1, 1};
  double per[MAX_BATCHES], F[4], dF[4], out[12];
  int b, k, ok = 1;

  if (!c) return 0;
  for (b = -1; b < batches; ++b) {
    double t0;
    FMI_CHECK(f->fmi2SetFMUstate(c, home));
    t0 = now_seconds();
    for (k = 0; k < STEPS_TIMED; ++k) {
      tick_forces(k, ramp, F, dF);
      FMI_CHECK(f->fmi2SetReal(c, plant->F, 4, F));
      if (ramp) FMI_CHECK(f->fmi2SetRealInputDerivatives(c, plant->F, 4, order, dF));
      FMI_CHECK(f->fmi2DoStep(c, (double)k * STEP, STEP, fmi2True));
      FMI_CHECK(f->fmi2GetReal(c, pose_vr, (size_t)n_out, out));
    }
    if (b >= 0) per[b] = now_seconds() - t0;
  }
  res->median_s = median_min(per, batches, &res->min_s);
  /* the untimed 1.5 s run */
  res->max_c = 0.0;
  FMI_CHECK(f->fmi2SetFMUstate(c, home));
  for (k = 0; k <= STEPS_TEST; ++k) {
    const double t = (double)k * STEP;
    if (k > 0) {
      tick_forces(k - 1, ramp, F, dF);
      FMI_CHECK(f->fmi2SetReal(c, plant->F, 4, F));
      if (ramp) FMI_CHECK(f->fmi2SetRealInputDerivatives(c, plant->F, 4, order, dF));
      FMI_CHECK(f->fmi2DoStep(c, t - STEP, STEP, fmi2True));
    }
    rows[k].v[0] = t;
    FMI_CHECK(f->fmi2GetReal(c, pose_vr, 4, &rows[k].v[1]));
    FMI_CHECK(f->fmi2GetReal(c, &md->rho1, 1, &rows[k].v[5]));
    FMI_CHECK(f->fmi2GetReal(c, &md->residual, 1, &rows[k].v[6]));
    if (rows[k].v[6] > res->max_c) res->max_c = rows[k].v[6];
  }
done:
  if (!free_plant(plant, c, &home)) ok = 0;
  return ok && write_rows(out_dir, res->name, STEPS_TEST + 1);
}

/* ------------------------------------------------------------------ main */

static int compare_run(const Plant* plant, const Options* o) {
  static const char* const setting_names[] = {"rk4_step", "g", "z0"};
  const char* out_dir = o->out;
  const int batches = o->batches;
  int i, ok, n = 0;
  Result results[9];
  Fmi md;
  /* RK4 at the 1 ms step; CVODE Adams at the default rtol 1e-8, atol 1e-10, and tight */
  const Settings rk4 = {PKM_SOLVER_RK4, STEP, 1e-8, 1e-10}, cvode = {PKM_SOLVER_CVODE, STEP, 1e-8, 1e-10},
                 cvode_tight = {PKM_SOLVER_CVODE, STEP, 1e-12, 1e-14};

  ok = lookup_value_reference(plant->text, "rho[1]", &md.rho1) &&
       lookup_value_reference(plant->text, "constraint_residual", &md.residual) &&
       lookup_value_references(plant, setting_names, 3, md.settings);
  if (!ok) return 0;


  printf("pkm_fmu_bench compare: one simulated second of the comparison test (docs/model.md; g = 0,\n"
         "F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s)) at a 1 ms step; median of %d batches after 1 warm-up\n",
         batches);
  print_machine();
  printf("fmu:     %s\n\n", plant->so);

  fill_force_table();
  results[n] = (Result){"capi_rk4", "C API, RK4 1 ms, forces at stage times", 0, 0, 0};
  ok = ok && run_capi(&rk4, 0, batches, out_dir, &results[n++]);
  results[n] = (Result){"capi_cvode", "C API, CVODE rtol 1e-8 (default)", 0, 0, 0};
  ok = ok && run_capi(&cvode, 0, batches, out_dir, &results[n++]);
  results[n] = (Result){"capi_cvode_tight", "C API, CVODE rtol 1e-12", 0, 0, 0};
  ok = ok && run_capi(&cvode_tight, 0, batches, out_dir, &results[n++]);
  results[n] = (Result){"capi_rk4_one_call", "C API, RK4 1 ms, one call for the second", 0, 0, 0};
  ok = ok && run_capi(&rk4, 1, batches, out_dir, &results[n++]);
  results[n] = (Result){"capi_cvode_one_call", "C API, CVODE rtol 1e-12, one call", 0, 0, 0};
  ok = ok && run_capi(&cvode_tight, 1, batches, out_dir, &results[n++]);
  results[n] = (Result){"fmu_rk4", "plant FMU, RK4 1 ms, midpoint-held F", 0, 0, 0};
  ok = ok && run_fmu(plant, &md, 1, 0, 4, batches, out_dir, &results[n++]);
  results[n] = (Result){"fmu_cvode", "plant FMU, CVODE rtol 1e-8, midpoint-held F", 0, 0, 0};
  ok = ok && run_fmu(plant, &md, 0, 0, 4, batches, out_dir, &results[n++]);
  results[n] = (Result){"fmu_rk4_ctrl12", "plant FMU, RK4 1 ms, held F, 12 outputs", 0, 0, 0};
  ok = ok && run_fmu(plant, &md, 1, 0, 12, batches, out_dir, &results[n++]);
  results[n] = (Result){"fmu_cvode_ramp_ctrl12", "plant FMU, CVODE 1e-8, F as ramp, 12 outputs", 0, 0, 0};
  ok = ok && run_fmu(plant, &md, 0, 1, 12, batches, out_dir, &results[n++]);

  if (ok) {
    printf("%-22s %-44s %14s %14s %16s\n", "case", "what", "median ms/s", "min ms/s", "max ||C|| (m)");
    for (i = 0; i < n; ++i)
      printf("%-22s %-44s %14.4f %14.4f %16.2e\n", results[i].name, results[i].what, 1e3 * results[i].median_s,
             1e3 * results[i].min_s, results[i].max_c);
  }
  if (ok && out_dir) {
    char path[1024];
    FILE* fp;
    snprintf(path, sizeof path, "%s/summary.csv", out_dir);
    fp = fopen(path, "w");
    if (!fp) {
      fprintf(stderr, NAME ": cannot write %s\n", path);
      ok = 0;
    } else {
      fprintf(fp, "case,what,median_s_per_sim_s,min_s_per_sim_s,max_constraint_residual\n");
      for (i = 0; i < n; ++i)
        fprintf(fp, "%s,\"%s\",%.6e,%.6e,%.6e\n", results[i].name, results[i].what, results[i].median_s,
                results[i].min_s, results[i].max_c);
      fclose(fp);
    }
  }
  return ok;
}

const Subcommand compare_subcommand = {"compare",
                                       "one simulated second of the comparison test, C API and FMU; --out for "
                                       "bench/engines_bench.py",
                                       compare_run, 21, MAX_BATCHES, "--out DIR (the runs as CSV)"};
