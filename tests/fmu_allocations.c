/* SPDX-License-Identifier: BSD-2-Clause */
/* fmu_allocations: no heap allocation in a control tick.
 *
 * The plant FMU (PKM4PUU.so) driven through raw FMI 2.0 Co-Simulation calls
 * while a malloc interposer (alloc_interposer.c) counts every heap
 * allocation of the process. After initialisation, fmi2SetReal,
 * fmi2SetRealInputDerivatives, fmi2DoStep, fmi2GetReal (the 12 controller
 * outputs and every Real output), fmi2GetFMUstate into an existing state and
 * fmi2SetFMUstate must allocate nothing, with either solver (RK4, CVODE),
 * with inputs held over the step and with inputs given with their
 * derivatives (CVODE continues across communication points), with logging
 * on (the end-stop events and the state restores are logged).
 *
 * Scenario per run: the home pose; 150 steps of 1 ms with F[1..4] at the
 * static holding force (docs/model.md) plus 0.5 sin(2 pi 5 t) N on F[1]; then
 * 250 steps with F = 0, a drop onto the lower end stops (contacts located:
 * RK4 splits, CVODE roots, both logged). Every 50 steps the FMU state is
 * saved into one existing state and restored; at step 200 the state saved
 * at initialisation is restored (the first step from there included).
 *
 * Output: the largest number of allocations of one call, per function and
 * run. Exit status 0 if all are zero, 1 otherwise (or if a call fails). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc_interposer.h"
#include "fmi2FunctionTypes.h"

#define PKM_HARNESS_NAME "fmu_allocations"
#include "fmu_harness.h"

#define STEPS 400
#define H 1e-3
#define MAX_OUTPUTS 256

enum { SET_REAL, SET_DERIVATIVES, DO_STEP, GET_CONTROL, GET_ALL, GET_STATE, SET_STATE, N_CALLS };
static const char* call_names[N_CALLS] = {"fmi2SetReal",  "fmi2SetRealInputDerivatives", "fmi2DoStep",
                                          "fmi2GetReal(12 controller outputs)", "fmi2GetReal(every output)",
                                          "fmi2GetFMUstate(existing)", "fmi2SetFMUstate"};

typedef struct {
  fmi2ValueReference F[4], control[12], outputs[MAX_OUTPUTS], solver;
  size_t n_outputs;
  char guid[128];
} Refs;

static void quiet_logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                         fmi2String category, fmi2String message, ...) {
  (void)env, (void)instance, (void)category;
  if (status == fmi2Error || status == fmi2Fatal) fprintf(stderr, "FMU: %s\n", message);
}

static int read_refs(const char* text, Refs* r) {
  const int ok = read_controller_interface(text, r->guid, sizeof r->guid, r->F, r->control) &&
                 lookup_value_reference(text, "solver", &r->solver);
  r->n_outputs = real_outputs(text, r->outputs, MAX_OUTPUTS);
  return ok && r->n_outputs > 12;
}

/* Runs `call`, adds what it allocated to max[which]; 0 if it did not return OK. */
#define COUNTED(which, call)                                                                   \
  do {                                                                                         \
    const long before_ = alloc_count();                                                        \
    const fmi2Status status_ = (call);                                                         \
    const long n_ = alloc_count() - before_;                                                   \
    if (n_ > max[which]) max[which] = n_;                                                      \
    if (status_ != fmi2OK) {                                                                   \
      fprintf(stderr, "fmu_allocations: %s returned %s at step %d\n", call_names[which],       \
              status_name(status_), k);                                                        \
      return 0;                                                                                \
    }                                                                                          \
  } while (0)

/* One run; max[] receives the largest allocation count of one call per function. */
static int run(const Fmu* f, const Refs* r, int solver, int with_derivatives, long max[N_CALLS]) {
  fmi2CallbackFunctions cb = {quiet_logger, allocate_memory, free, NULL, NULL};
  const long before_instantiation = alloc_count();
  fmi2Component c = f->fmi2Instantiate("alloc", fmi2CoSimulation, r->guid, "", &cb, fmi2False, fmi2True);
  fmi2FMUstate home = NULL, saved = NULL;
  const fmi2Integer s = solver;
  const fmi2Integer order[4] = {1, 1, 1, 1};
  double y[MAX_OUTPUTS];
  double tm = 0.0; /* the master's time */
  int k = -1, i;
  if (!c) return 0;
  if (f->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
      f->fmi2SetInteger(c, &r->solver, 1, &s) != fmi2OK || f->fmi2EnterInitializationMode(c) != fmi2OK ||
      f->fmi2ExitInitializationMode(c) != fmi2OK || f->fmi2GetFMUstate(c, &home) != fmi2OK ||
      f->fmi2GetFMUstate(c, &saved) != fmi2OK) {
    fprintf(stderr, "fmu_allocations: initialisation failed\n");
    return 0;
  }
  /* The control: instantiation allocates (the instance itself), so the
   * interposer must have seen something, or it counts nothing at all. */
  if (alloc_count() == before_instantiation) {
    fprintf(stderr, "fmu_allocations: the malloc interposer saw no allocation in fmi2Instantiate\n");
    return 0;
  }
  for (k = 0; k < STEPS; ++k) {
    const double t = k * H;
    double u[4], du[4] = {0.0, 0.0, 0.0, 0.0};
    for (i = 0; i < 4; ++i) u[i] = k < 150 ? STATIC_FORCE : 0.0;
    if (k < 150) {
      u[0] += 0.5 * sin(2.0 * PI * 5.0 * t);
      du[0] = 0.5 * 2.0 * PI * 5.0 * cos(2.0 * PI * 5.0 * t);
    }
    if (k == 200) {
      COUNTED(SET_STATE, f->fmi2SetFMUstate(c, home));
      tm = 0.0;
    }
    COUNTED(SET_REAL, f->fmi2SetReal(c, r->F, 4, u));
    if (with_derivatives) COUNTED(SET_DERIVATIVES, f->fmi2SetRealInputDerivatives(c, r->F, 4, order, du));
    COUNTED(DO_STEP, f->fmi2DoStep(c, tm, H, fmi2True));
    tm += H;
    COUNTED(GET_CONTROL, f->fmi2GetReal(c, r->control, 12, y));
    COUNTED(GET_ALL, f->fmi2GetReal(c, r->outputs, r->n_outputs, y));
    if (k % 50 == 49) {
      COUNTED(GET_STATE, f->fmi2GetFMUstate(c, &saved));
      COUNTED(SET_STATE, f->fmi2SetFMUstate(c, saved));
    }
  }
  f->fmi2FreeFMUstate(c, &home);
  f->fmi2FreeFMUstate(c, &saved);
  f->fmi2Terminate(c);
  f->fmi2FreeInstance(c);
  return 1;
}

int main(int argc, char** argv) {
  const char* so = argc > 1 ? argv[1] : PKM_FMU_PLANT_SO;
  const char* xml = argc > 2 ? argv[2] : PKM_FMU_PLANT_XML;
  char* text = read_text(xml);
  static Refs r;
  Fmu f;
  int solver, deriv, call, failed = 0;
  if (!text || !read_refs(text, &r) || !load_fmu(so, &f)) {
    fprintf(stderr, "fmu_allocations: cannot load %s with %s\n", so, xml);
    return 1;
  }
  printf("%-8s %-12s %-38s %s\n", "solver", "inputs", "call", "max allocations per call");
  for (solver = 1; solver >= 0; --solver) {
    for (deriv = 0; deriv <= 1; ++deriv) {
      long max[N_CALLS] = {0};
      if (!run(&f, &r, solver, deriv, max)) return 1;
      for (call = 0; call < N_CALLS; ++call) {
        if (call == SET_DERIVATIVES && !deriv) continue;
        printf("%-8s %-12s %-38s %ld\n", solver ? "RK4" : "CVODE", deriv ? "value+slope" : "held",
               call_names[call], max[call]);
        if (max[call] != 0) failed = 1;
      }
    }
  }
  free(text);
  if (failed) {
    fprintf(stderr, "fmu_allocations: FAILED: a call after initialisation allocated\n");
    return 1;
  }
  printf("no allocation after initialisation\n");
  return 0;
}
