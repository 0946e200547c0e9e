/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_inverse_bench: the inverse FMU's tick against MuJoCo's
 * mj_inverse on the same mechanism, both timed here in C in the same run.
 *
 * The tick (PKM4PUU_Inverse.so loaded with dlopen, raw FMI calls, as a
 * computed-force controller drives it every 1 ms): set the 12 motion inputs
 * (pose, its rates and accelerations), advance (Co-Simulation: DoStep of
 * 1 ms; Model Exchange: SetTime), get the 4 forces F[1..4]; for FMI 2.0 and
 * 3.0, Co-Simulation and Model Exchange. The motion is a smooth loop about
 * the home pose tabulated beforehand (1000 ticks, different inputs at
 * every tick, so every get computes).
 *
 * mj_inverse (built only where the MuJoCo wheel's libmujoco and headers
 * were found, PKM_HAVE_MUJOCO): the MJCF that
 * pkm4puu.references.mujoco_model writes (the engines'
 * benchmarks' model), at the state bench/fmu/mujoco_inverse_model.py writes
 * beside it (the auto-test path at t = 1 s: qpos, qvel, qacc of its 16
 * coordinates). mj_inverse's work does not depend on the values.
 *
 *   pkm_fmu_inverse_bench [--fmu SO] [--xml modelDescription.xml] [--mjcf FILE --state FILE] [--batches N]
 *
 * Prints median and minimum per tick over the batches and the ratio
 * tick / mj_inverse with the target (0.1x). Exit status 0; 1 if an FMI call
 * fails or a file cannot be read; 2 for a usage error. Never a test of
 * speed: the ratio is printed, not asserted. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>

#define PKM_HARNESS_NAME "pkm_fmu_inverse_bench"
#include "harness.h"
#include "fmi3FunctionTypes.h"

#if PKM_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

#define TICKS 1000    /* tabulated motion */
#define REPEAT 4      /* passes over the table per batch: 4000 ticks */
#define H 1e-3        /* s */
#define TARGET 0.1    /* tick / mj_inverse */
#define PI 3.14159265358979323846

typedef struct {
  void* handle;
#define DECLARE3(name) name##TYPE* name;
  PKM_FMI3_FUNCTIONS(DECLARE3)
#undef DECLARE3
} Fmu3;

static int load_fmu3(void* handle, Fmu3* f) {
  int ok = 1;
  f->handle = handle;
#define LOAD3(name) ok &= load_symbol(handle, #name, &f->name, sizeof f->name);
  PKM_FMI3_FUNCTIONS(LOAD3)
#undef LOAD3
  return ok;
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
  (void)env;
  if (status == fmi3Error || status == fmi3Fatal) fprintf(stderr, "[fmi3] %s: %s\n", category, message);
}

/* The motion: x, y on a circle of 2 mm, z +-5 mm about 0.05 m, phi +-0.05
 * rad, one period per table (1 s), with its exact rates and accelerations. */
static double motion[TICKS][12];
static void tabulate_motion(void) {
  int k;
  for (k = 0; k < TICKS; ++k) {
    const double w = 2.0 * PI, t = k * H, s = sin(w * t), c = cos(w * t);
    const double a[4] = {0.002, 0.002, 0.005, 0.05};
    const double p[4] = {a[0] * s, a[1] * c, 0.05 + a[2] * s, a[3] * s};
    const double v[4] = {a[0] * w * c, -a[1] * w * s, a[2] * w * c, a[3] * w * c};
    int i;
    for (i = 0; i < 4; ++i) {
      motion[k][i] = p[i];
      motion[k][4 + i] = v[i];
      motion[k][8 + i] = -w * w * (p[i] - (i == 2 ? 0.05 : 0.0));
    }
  }
}

typedef struct {
  double median, min;
} Figure;

static Figure summarise(double* v, int n) {
  Figure f;
  qsort(v, (size_t)n, sizeof v[0], compare_double);
  f.min = v[0];
  f.median = v[n / 2];
  return f;
}

typedef enum { FMI2_CS, FMI2_ME, FMI3_CS, FMI3_ME } Kind;
static const char* const kind_names[4] = {"FMI 2.0 Co-Simulation", "FMI 2.0 Model Exchange",
                                          "FMI 3.0 Co-Simulation", "FMI 3.0 Model Exchange"};

typedef struct {
  const Fmu* f2;
  const Fmu3* f3;
  const char* guid;
  fmi2ValueReference in[12], out[4];
} Inverse;

/* One tick: set the 12 inputs of table row k, advance, get the 4 forces. */
static int tick(const Inverse* x, Kind kind, void* c, int k, double t, double F[4]) {
  const fmi3ValueReference* in3 = x->in;
  const fmi3ValueReference* out3 = x->out;
  switch (kind) {
    case FMI2_CS:
      return x->f2->fmi2SetReal(c, x->in, 12, motion[k]) == fmi2OK &&
             x->f2->fmi2DoStep(c, t, H, fmi2True) == fmi2OK && x->f2->fmi2GetReal(c, x->out, 4, F) == fmi2OK;
    case FMI2_ME:
      return x->f2->fmi2SetTime(c, t + H) == fmi2OK && x->f2->fmi2SetReal(c, x->in, 12, motion[k]) == fmi2OK &&
             x->f2->fmi2GetReal(c, x->out, 4, F) == fmi2OK;
    case FMI3_CS: {
      fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
      fmi3Float64 reached = 0.0;
      return x->f3->fmi3SetFloat64(c, in3, 12, motion[k], 12) == fmi3OK &&
             x->f3->fmi3DoStep(c, t, H, fmi3True, &event, &terminate, &early, &reached) == fmi3OK &&
             x->f3->fmi3GetFloat64(c, out3, 4, F, 4) == fmi3OK;
    }
    case FMI3_ME:
      return x->f3->fmi3SetTime(c, t + H) == fmi3OK && x->f3->fmi3SetFloat64(c, in3, 12, motion[k], 12) == fmi3OK &&
             x->f3->fmi3GetFloat64(c, out3, 4, F, 4) == fmi3OK;
  }
  return 0;
}

static void* instantiate(const Inverse* x, Kind kind) {
  static const fmi2CallbackFunctions callbacks = {logger, allocate_memory, free, NULL, NULL};
  const Fmu* f2 = x->f2;
  const Fmu3* f3 = x->f3;
  if (kind == FMI2_CS || kind == FMI2_ME) {
    fmi2Component c = f2->fmi2Instantiate("inverse", kind == FMI2_CS ? fmi2CoSimulation : fmi2ModelExchange, x->guid,
                                          "", &callbacks, fmi2False, fmi2False);
    int ok = c != NULL;
    ok = ok && f2->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK;
    ok = ok && f2->fmi2EnterInitializationMode(c) == fmi2OK && f2->fmi2ExitInitializationMode(c) == fmi2OK;
    if (ok && kind == FMI2_ME) {
      fmi2EventInfo info;
      memset(&info, 0, sizeof info);
      ok = f2->fmi2NewDiscreteStates(c, &info) == fmi2OK && f2->fmi2EnterContinuousTimeMode(c) == fmi2OK;
    }
    if (!ok && c) f2->fmi2FreeInstance(c);
    return ok ? c : NULL;
  } else {
    fmi3Instance c = kind == FMI3_CS ? f3->fmi3InstantiateCoSimulation("inverse", x->guid, NULL, fmi3False, fmi3False,
                                                                      fmi3False, fmi3False, NULL, 0, NULL, logger3, NULL)
                                     : f3->fmi3InstantiateModelExchange("inverse", x->guid, NULL, fmi3False, fmi3False,
                                                                       NULL, logger3);
    int ok = c != NULL;
    ok = ok && f3->fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK &&
         f3->fmi3ExitInitializationMode(c) == fmi3OK;
    if (ok && kind == FMI3_ME) {
      fmi3Boolean a = fmi3False, b = fmi3False, d = fmi3False, e = fmi3False, g = fmi3False;
      fmi3Float64 next = 0.0;
      ok = f3->fmi3UpdateDiscreteStates(c, &a, &b, &d, &e, &g, &next) == fmi3OK &&
           f3->fmi3EnterContinuousTimeMode(c) == fmi3OK;
    }
    if (!ok && c) f3->fmi3FreeInstance(c);
    return ok ? c : NULL;
  }
}

static void free_instance(const Inverse* x, Kind kind, void* c) {
  if (kind == FMI2_CS || kind == FMI2_ME) {
    x->f2->fmi2Terminate(c);
    x->f2->fmi2FreeInstance(c);
  } else {
    x->f3->fmi3Terminate(c);
    x->f3->fmi3FreeInstance(c);
  }
}

/* One batch of ticks of `kind` on instance c from time *t; the time per
 * tick, or -1 on a failed call (with a message). */
static double time_ticks(const Inverse* x, Kind kind, void* c, double* t, double* sum_F) {
  double F[4] = {0, 0, 0, 0};
  const double t0 = now_seconds();
  int r, k;
  for (r = 0; r < REPEAT; ++r)
    for (k = 0; k < TICKS; ++k, *t += H) {
      if (!tick(x, kind, c, k, *t, F)) {
        fprintf(stderr, "pkm_fmu_inverse_bench: a tick (%s) failed at t = %g s\n", kind_names[kind], *t);
        return -1.0;
      }
      *sum_F += F[0];
    }
  return (now_seconds() - t0) / (REPEAT * TICKS);
}

#if PKM_HAVE_MUJOCO
/* The model of `mjcf` at the state in `state` (48 numbers: qpos, qvel,
 * qacc) into *m, *d; 0 (with a message) on failure. */
static int load_mujoco(const char* mjcf, const char* state, mjModel** m, mjData** d) {
  char error[1000] = "";
  FILE* fp = fopen(state, "r");
  int i, ok;
  *m = mj_loadXML(mjcf, NULL, error, sizeof error);
  *d = *m ? mj_makeData(*m) : NULL;
  ok = *m && *d && fp && (*m)->nq == 16 && (*m)->nv == 16;
  for (i = 0; ok && i < 48; ++i) {
    double v;
    ok = fscanf(fp, "%lf", &v) == 1;
    if (ok) (i < 16 ? (*d)->qpos : i < 32 ? (*d)->qvel : (*d)->qacc)[i % 16] = v;
  }
  if (fp) fclose(fp);
  if (!ok) fprintf(stderr, "pkm_fmu_inverse_bench: cannot load %s / %s %s\n", mjcf, state, error);
  return ok;
}

/* One batch of mj_inverse calls: the time per call. */
static double time_mj_inverse(const mjModel* m, mjData* d, double* sum) {
  const double t0 = now_seconds();
  int r;
  for (r = 0; r < REPEAT * TICKS; ++r) {
    mj_inverse(m, d);
    *sum += d->qfrc_inverse[0];
  }
  return (now_seconds() - t0) / (REPEAT * TICKS);
}
#endif

int main(int argc, char** argv) {
  const char* so = PKM_FMU_INVERSE_SO;
  const char* xml = PKM_FMU_INVERSE_XML;
  const char* mjcf = PKM_MUJOCO_MJCF;
  const char* state = PKM_MUJOCO_STATE;
  int batches = 101, i, k, ok = 1;
  static const char* const inputs[12] = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"};
  static const char* const outputs[4] = {"F[1]", "F[2]", "F[3]", "F[4]"};
  char guid[128];
  char* text;
  Fmu f2;
  Fmu3 f3;
  Inverse x;
  Figure fig[4], mj = {0.0, 0.0};
  double sum = 0.0;
  int have_mj = 0;
  for (i = 1; i < argc; ++i) {
    const char* v = i + 1 < argc ? argv[i + 1] : NULL;
    if (strcmp(argv[i], "--help") == 0) {
      printf("usage: pkm_fmu_inverse_bench [--fmu SO] [--xml FILE] [--mjcf FILE --state FILE] [--batches 1..1000]\n");
      return 0;
    }
    if (!v) return fprintf(stderr, "pkm_fmu_inverse_bench: missing value after %s\n", argv[i]), 2;
    if (strcmp(argv[i], "--fmu") == 0) so = v;
    else if (strcmp(argv[i], "--xml") == 0) xml = v;
    else if (strcmp(argv[i], "--mjcf") == 0) mjcf = v;
    else if (strcmp(argv[i], "--state") == 0) state = v;
    else if (strcmp(argv[i], "--batches") == 0) {
      batches = atoi(v);
      if (batches < 1 || batches > 1000) return fprintf(stderr, "pkm_fmu_inverse_bench: --batches 1..1000\n"), 2;
    } else {
      return fprintf(stderr, "pkm_fmu_inverse_bench: unknown option %s\n", argv[i]), 2;
    }
    ++i;
  }
  text = read_text(xml);
  {
    const char* root = text ? strstr(text, "<fmiModelDescription") : NULL;
    if (!root || !attribute(root, strchr(root, '>'), "guid", guid, sizeof guid)) {
      fprintf(stderr, "pkm_fmu_inverse_bench: cannot read %s\n", xml);
      free(text);
      return 1;
    }
  }
  for (i = 0; i < 12; ++i) ok = ok && lookup_value_reference(text, inputs[i], &x.in[i]);
  for (i = 0; i < 4; ++i) ok = ok && lookup_value_reference(text, outputs[i], &x.out[i]);
  free(text);
  if (!ok || !load_fmu(so, &f2) || !load_fmu3(f2.handle, &f3)) return exit_status(0);
  x.f2 = &f2;
  x.f3 = &f3;
  x.guid = guid;
  tabulate_motion();

  print_machine();
  printf("inverse FMU: %s\n", so);
  printf("tick = set the 12 motion inputs, advance (CS: DoStep 1 ms; ME: SetTime), get F[1..4];\n");
  printf("median and min per call over %d batches of %d calls, the cases interleaved batch by batch\n\n", batches,
         REPEAT * TICKS);
  {
    double* per = malloc(sizeof(double) * 5 * (size_t)batches); /* [case][batch]; case 4: mj_inverse */
    void* c[4] = {NULL, NULL, NULL, NULL};
    double t[4] = {0.0, 0.0, 0.0, 0.0};
    int b;
#if PKM_HAVE_MUJOCO
    mjModel* mm = NULL;
    mjData* md = NULL;
    have_mj = load_mujoco(mjcf, state, &mm, &md);
    ok = have_mj;
#else
    (void)mjcf;
    (void)state;
#endif
    ok = ok && per != NULL;
    for (k = 0; ok && k < 4; ++k) {
      c[k] = instantiate(&x, (Kind)k);
      if (!c[k]) fprintf(stderr, "pkm_fmu_inverse_bench: instantiating (%s) failed\n", kind_names[k]);
      ok = c[k] != NULL;
    }
    for (b = 0; ok && b < batches; ++b) {
      for (k = 0; ok && k < 4; ++k) ok = (per[k * batches + b] = time_ticks(&x, (Kind)k, c[k], &t[k], &sum)) > 0.0;
#if PKM_HAVE_MUJOCO
      if (ok) per[4 * batches + b] = time_mj_inverse(mm, md, &sum);
#endif
    }
    for (k = 0; ok && k < 4; ++k) fig[k] = summarise(per + k * batches, batches);
    if (ok && have_mj) mj = summarise(per + 4 * batches, batches);
    for (k = 0; k < 4; ++k)
      if (c[k]) free_instance(&x, (Kind)k, c[k]);
#if PKM_HAVE_MUJOCO
    if (md) mj_deleteData(md);
    if (mm) mj_deleteModel(mm);
#endif
    free(per);
  }
  if (ok) {
    printf("   %-40s %12s %12s %15s\n", "evaluation", "median/call", "min/call", "/ mj_inverse");
    if (have_mj)
      printf("   %-40s %9.1f ns %9.1f ns %15s\n", "MuJoCo mj_inverse (same mechanism)", mj.median * 1e9, mj.min * 1e9,
             "1.00x (medians, mins)");
    for (k = 0; k < 4; ++k) {
      printf("   %-40s %9.1f ns %9.1f ns", kind_names[k], fig[k].median * 1e9, fig[k].min * 1e9);
      if (have_mj)
        printf(" %7.3fx %6.3fx  target <= %gx: %s", fig[k].median / mj.median, fig[k].min / mj.min, TARGET,
               fig[k].median <= TARGET * mj.median ? "ok" : "OVER");
      printf("\n");
    }
    if (!have_mj) printf("   (mj_inverse: not built here, MuJoCo's library and headers were not found)\n");
  }
  if (!(sum == sum)) printf("(non-finite forces)\n"); /* keeps the loops' results alive */
  dlclose(f2.handle);
  return exit_status(ok);
}
