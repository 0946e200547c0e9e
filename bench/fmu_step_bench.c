/* pkm_fmu_bench: the cost of one 1-ms communication step of the plant FMU
 * (PKM4PUU.so), driven through the raw FMI 2.0 Co-Simulation functions the
 * way a master would drive it: dlopen, dlsym, fmi2Instantiate, then
 * fmi2SetReal(F[1..4]) + fmi2DoStep every step. Plain C11, no C++.
 *
 *   pkm_fmu_bench [PKM4PUU.so [modelDescription.xml]]
 *
 * Default .so: the build's $<TARGET_FILE:PKM4PUU> (PKM_FMU_PLANT_SO). The
 * GUID and the value references are read at run time from a
 * modelDescription.xml: the second argument if given, else the build's staged
 * copy for the build's binary, else that of the unpacked FMU the .so sits in
 * (<so>/../../../modelDescription.xml, the layout binaries/linux64/<id>.so).
 *
 * Scenario: the home pose (default parameters), F[1..4] = 2.655616050 N (the
 * static forces of MODEL_SPEC) plus 0.01 sin(2 pi t) N on F[1], set before
 * every fmi2DoStep of 1 ms. Cases, for solver = 1 (RK4, rk4_step 1e-3) and
 * solver = 0 (CVODE, rtol 1e-8, atol 1e-10):
 *   (a) fmi2SetReal(4 inputs) + fmi2DoStep
 *   (b) (a) + fmi2GetReal(x, y, z, phi)
 *   (c) (a) + fmi2GetReal of a controller's 12 outputs (pose, rates, rho[1..4])
 *   (d) (b) + fmi2GetReal(every Real output)
 * and what (c) adds to (a), in percent (issue 16's target: at most 10 % with RK4).
 * A batch is 1 s of simulated time (1000 steps) from the home pose (the FMU
 * state saved after initialisation is restored before each batch, outside
 * the timed region, so every batch integrates the same second); one
 * untimed warm-up batch, then 21 timed batches; the median and the minimum
 * time per step are printed. Timing: clock_gettime(CLOCK_MONOTONIC).
 *
 * For profiling (callgrind, perf), two environment variables shrink the run:
 * PKM_FMU_BENCH_SOLVER=0|1 runs that solver only, PKM_FMU_BENCH_BATCHES=n
 * (1..21) times n batches.
 *
 * Exit status: 0, or 1 if anything fails (any FMI call not returning
 * fmi2OK, a missing symbol, an unreadable model description). */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include "fmi2FunctionTypes.h"

#define PKM_HARNESS_NAME "pkm_fmu_bench"
#include "fmu_harness.h"

#ifndef PKM_FMU_PLANT_SO
#define PKM_FMU_PLANT_SO "PKM4PUU.so"
#endif

#define STATIC_FORCE 2.655616050 /* N, MODEL_SPEC "A check anyone can derive" */
#define SINE_AMPLITUDE 0.01      /* N, on F[1] */
#define COMM_STEP 1e-3           /* s */
#define STEPS_PER_BATCH 1000     /* 1 s of simulated time */
#define BATCHES 21
#define MAX_OUTPUTS 256
#define PI 3.14159265358979323846

/* ------------------------------------------------------------------ FMI */



#define CHECK(call)                                                                     \
  do {                                                                                  \
    const fmi2Status check_status_ = (call);                                            \
    if (check_status_ != fmi2OK) {                                                      \
      fprintf(stderr, "pkm_fmu_bench: %s:%d: %s returned %s\n", __FILE__, __LINE__,     \
              #call, status_name(check_status_));                                       \
      return 0;                                                                         \
    }                                                                                   \
  } while (0)

/* ------------------------------------------------- the model description */

typedef struct {
  char guid[128];
  fmi2ValueReference outputs[MAX_OUTPUTS]; /* every Real output */
  size_t n_outputs;
  const char* text;
} ModelDescription;

static int parse_model_description(const char* text, ModelDescription* md) {
  const char* root = strstr(text, "<fmiModelDescription");
  const char* root_end = root ? strchr(root, '>') : NULL;
  const char* p = text;
  md->text = text;
  md->n_outputs = 0;
  if (!root || !root_end || !attribute(root, root_end, "guid", md->guid, sizeof md->guid)) {
    fprintf(stderr, "pkm_fmu_bench: no guid attribute in the model description\n");
    return 0;
  }
  while ((p = strstr(p, "<ScalarVariable")) != NULL) {
    const char* end = strstr(p, "</ScalarVariable>");
    char buf[64];
    if (!end) break;
    if (attribute(p, end, "causality", buf, sizeof buf) && strcmp(buf, "output") == 0) {
      const char* real = strstr(p, "<Real");
      if (real && real < end && attribute(p, end, "valueReference", buf, sizeof buf)) {
        if (md->n_outputs == MAX_OUTPUTS) return 0;
        md->outputs[md->n_outputs++] = (fmi2ValueReference)strtoul(buf, NULL, 10);
      }
    }
    p = end;
  }
  return md->n_outputs > 0;
}

/* ------------------------------------------------------------- the runs */

typedef struct {
  fmi2ValueReference F[4], pose[4], control[12], solver, rk4_step, rtol, atol;
} References;

static int batches = BATCHES; /* PKM_FMU_BENCH_BATCHES */

typedef enum { CASE_STEP, CASE_POSE, CASE_CONTROL, CASE_ALL } Case;

typedef struct {
  double median_us, min_us;
  double pose[4]; /* at the end of the last batch */
} Result;

/* One batch: STEPS_PER_BATCH communication steps from t = 0. */
static int batch(const Fmu* f, fmi2Component c, const References* r, const ModelDescription* md, Case kind,
                 const double* force1, double* seconds, double* pose) {
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
    if (kind == CASE_ALL) CHECK(f->fmi2GetReal(c, md->outputs, md->n_outputs, all));
  }
  t1 = now_seconds();
  *seconds = t1 - t0;
  if (kind == CASE_STEP) CHECK(f->fmi2GetReal(c, r->pose, 4, pose));
  return 1;
}

static int run(const Fmu* f, const ModelDescription* md, const References* r, int solver, Case kind,
               Result* result) {
  static const char* names[] = {"step", "step+pose", "step+control", "step+all"};
  fmi2CallbackFunctions callbacks = {logger, allocate_memory, free, NULL, NULL};
  double force1[STEPS_PER_BATCH], per_step[BATCHES], seconds = 0.0;
  fmi2FMUstate home = NULL;
  fmi2Component c;
  char name[64];
  int k, ok = 1;

  for (k = 0; k < STEPS_PER_BATCH; ++k)
    force1[k] = STATIC_FORCE + SINE_AMPLITUDE * sin(2.0 * PI * (double)k * COMM_STEP);

  snprintf(name, sizeof name, "bench_solver%d_%s", solver, names[kind]);
  c = f->fmi2Instantiate(name, fmi2CoSimulation, md->guid, "", &callbacks, fmi2False, fmi2False);
  if (!c) {
    fprintf(stderr, "pkm_fmu_bench: fmi2Instantiate failed\n");
    return 0;
  }
  {
    const fmi2Integer solver_value = solver;
    const fmi2Real rk4_step = 1e-3, rtol = 1e-8, atol = 1e-10;
    if (f->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        f->fmi2SetInteger(c, &r->solver, 1, &solver_value) != fmi2OK ||
        f->fmi2SetReal(c, &r->rk4_step, 1, &rk4_step) != fmi2OK ||
        f->fmi2SetReal(c, &r->rtol, 1, &rtol) != fmi2OK || f->fmi2SetReal(c, &r->atol, 1, &atol) != fmi2OK ||
        f->fmi2EnterInitializationMode(c) != fmi2OK || f->fmi2ExitInitializationMode(c) != fmi2OK ||
        f->fmi2GetFMUstate(c, &home) != fmi2OK) {
      fprintf(stderr, "pkm_fmu_bench: setting up %s failed\n", name);
      ok = 0;
    }
  }
  /* One warm-up batch, then the timed ones, each from the home pose at t = 0. */
  for (k = -1; ok && k < batches; ++k) {
    ok = f->fmi2SetFMUstate(c, home) == fmi2OK;
    if (!ok) {
      fprintf(stderr, "pkm_fmu_bench: fmi2SetFMUstate failed\n");
      break;
    }
    ok = batch(f, c, r, md, kind, force1, &seconds, result->pose);
    if (ok && k >= 0) per_step[k] = seconds / STEPS_PER_BATCH;
  }
  if (home && f->fmi2FreeFMUstate(c, &home) != fmi2OK) ok = 0;
  if (f->fmi2Terminate(c) != fmi2OK) ok = 0;
  f->fmi2FreeInstance(c);
  if (!ok) return 0;
  qsort(per_step, (size_t)batches, sizeof per_step[0], compare_double);
  result->median_us = 1e6 * per_step[batches / 2];
  result->min_us = 1e6 * per_step[0];
  return 1;
}

/* ------------------------------------------------------------ the machine */

/* ------------------------------------------------------------------ main */

int main(int argc, char** argv) {
  static const char* force_names[] = {"F[1]", "F[2]", "F[3]", "F[4]"};
  static const char* pose_names[] = {"x", "y", "z", "phi"};
  static const char* control_names[] = PKM_CONTROLLER_OUTPUTS;
  static const char* case_names[] = {"(a) SetReal(F) + DoStep", "(b) (a) + GetReal(x,y,z,phi)",
                                     "(c) (a) + GetReal(12 controller outputs)", "(d) (b) + GetReal(all outputs)"};
  const char* so = argc > 1 ? argv[1] : PKM_FMU_PLANT_SO;
  char* xml_path = argc > 2 ? NULL : default_xml_path(so);
  const char* xml = argc > 2 ? argv[2] : xml_path;
  static ModelDescription md;
  References r;
  Fmu f;
  char* text;
  const char* env_solver = getenv("PKM_FMU_BENCH_SOLVER");
  const char* env_batches = getenv("PKM_FMU_BENCH_BATCHES");
  int i, solver, kind, ok = 1, first_solver = 1, last_solver = 0;

  if (env_solver && *env_solver) {
    first_solver = last_solver = atoi(env_solver);
    if (first_solver != 0 && first_solver != 1) {
      fprintf(stderr, "pkm_fmu_bench: PKM_FMU_BENCH_SOLVER must be 0 or 1\n");
      return 1;
    }
  }
  if (env_batches && *env_batches) {
    batches = atoi(env_batches);
    if (batches < 1 || batches > BATCHES) {
      fprintf(stderr, "pkm_fmu_bench: PKM_FMU_BENCH_BATCHES must be in 1..%d\n", BATCHES);
      return 1;
    }
  }

  if (!xml) {
    fprintf(stderr, "pkm_fmu_bench: cannot derive the model description path from %s\n", so);
    return 1;
  }
  text = read_text(xml);
  if (!text) {
    fprintf(stderr, "pkm_fmu_bench: cannot read %s\n", xml);
    return 1;
  }
  if (!parse_model_description(text, &md)) return 1;
  for (i = 0; i < 4; ++i) ok &= lookup_value_reference(md.text, force_names[i], &r.F[i]) & lookup_value_reference(md.text, pose_names[i], &r.pose[i]);
  for (i = 0; i < 12; ++i) ok &= lookup_value_reference(md.text, control_names[i], &r.control[i]);
  ok &= lookup_value_reference(md.text, "solver", &r.solver) & lookup_value_reference(md.text, "rk4_step", &r.rk4_step) & lookup_value_reference(md.text, "rtol", &r.rtol) &
        lookup_value_reference(md.text, "atol", &r.atol);
  if (!ok || !load_fmu(so, &f)) return 1;

  printf("pkm_fmu_bench: FMI 2.0 Co-Simulation, one communication step of the plant FMU\n");
  print_machine();
  printf("fmu:     %s\n", so);
  printf("xml:     %s\n", xml);
  printf("guid:    %s; %zu Real outputs\n", md.guid, md.n_outputs);
  printf("scenario: home pose, F[1..4] = %.9f N, + %.2f sin(2 pi t) N on F[1]; step %.0f ms; "
         "%d timed batches of %d steps (1 s simulated, from the home pose each) after 1 warm-up batch\n\n",
         STATIC_FORCE, SINE_AMPLITUDE, COMM_STEP * 1e3, batches, STEPS_PER_BATCH);
  printf("%-34s %-34s %10s %10s %12s %12s\n", "solver", "per step", "median us", "min us", "RT (median)",
         "RT (min)");

  for (solver = first_solver; ok && solver >= last_solver; --solver) {
    const char* solver_name = solver == 1 ? "RK4 (rk4_step 1e-3)" : "CVODE (rtol 1e-8, atol 1e-10)";
    double step_us = 0.0;
    for (kind = CASE_STEP; ok && kind <= CASE_ALL; ++kind) {
      Result res;
      ok = run(&f, &md, &r, solver, (Case)kind, &res);
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
  free(text);
  free(xml_path);
  dlclose(f.handle);
  return exit_status(ok);
}
