/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench inverse: the inverse FMU's tick (FMI 2.0 and 3.0, every 1 ms along a smooth loop about the home
 * pose) against MuJoCo's mj_inverse on the same mechanism (built with MuJoCo, given its MJCF). */
#include "fmu_bench.h"
#include "pkm4puu/pkm.h"

#if PKM_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

#define TICKS 1000 /* tabulated motion */
#define REPEAT 4   /* passes over the table per batch */
#define H 1e-3
#define TARGET 0.1 /* tick / mj_inverse */

static const char* const kind_names[4] = {"FMI 2.0 Co-Simulation", "FMI 2.0 Model Exchange", "FMI 3.0 Co-Simulation",
                                          "FMI 3.0 Model Exchange"};
static double motion[TICKS][12]; /* x, y on a circle of 2 mm, z +-5 mm, phi +-0.05 rad; rates, accelerations */
static fmi2ValueReference in[12], out[4];
static const Plant* plant;
static void* c[4];
static double t[5], sum; /* each case's time; the forces' sum keeps the loops' results alive */
#if PKM_HAVE_MUJOCO
static mjModel* mm;
static mjData* md;
#endif

/* A batch of ticks of instance `kind` (kind 4: of mj_inverse): the time per tick, 0 after a message on failure. */
static double time_ticks(int kind) {
  const Fmu* f2 = &plant->fmu;
  const Fmu3* f3 = &plant->fmu3;
  fmi3Boolean event, terminate, early;
  fmi3Float64 reached;
  double F[4] = {0, 0, 0, 0}, *tk = &t[kind];
  void* ci = kind < 4 ? c[kind] : NULL;
  const double t0 = bench_now();
  for (int k = 0; k < REPEAT * TICKS; ++k, *tk += H, sum += F[0]) {
    const double* u = motion[k % TICKS];
    if (kind == FMI2_CS)
      FMI_CHECK(f2->fmi2SetReal(ci, in, 12, u) || f2->fmi2DoStep(ci, *tk, H, fmi2True) ||
                f2->fmi2GetReal(ci, out, 4, F));
    if (kind == FMI2_ME)
      FMI_CHECK(f2->fmi2SetTime(ci, *tk + H) || f2->fmi2SetReal(ci, in, 12, u) || f2->fmi2GetReal(ci, out, 4, F));
    if (kind == FMI3_CS)
      FMI_CHECK(f3->fmi3SetFloat64(ci, in, 12, u, 12) ||
                f3->fmi3DoStep(ci, *tk, H, fmi3True, &event, &terminate, &early, &reached) ||
                f3->fmi3GetFloat64(ci, out, 4, F, 4));
    if (kind == FMI3_ME)
      FMI_CHECK(f3->fmi3SetTime(ci, *tk + H) || f3->fmi3SetFloat64(ci, in, 12, u, 12) ||
                f3->fmi3GetFloat64(ci, out, 4, F, 4));
#if PKM_HAVE_MUJOCO
    if (kind == 4) mj_inverse(mm, md), F[0] = md->qfrc_inverse[0];
#endif
  }
  return (bench_now() - t0) / (REPEAT * TICKS);
}

#if PKM_HAVE_MUJOCO
/* The model of `mjcf` at the table's first motion, the legs' from the C API's inverse dynamics (MuJoCo's joints in
 * the coordinate order of docs/model.md); 0 after a message on failure. */
static int load_mujoco(const char* mjcf) {
  char error[1000] = "";
  pkm_inverse_result r = {.size = sizeof r};
  pkm_model* m = NULL;
  int ok = pkm_create(&m) == PKM_OK &&
           pkm_inverse_dynamics(m, motion[0], motion[0] + 4, motion[0] + 8, NULL, &r) == PKM_OK;
  pkm_destroy(m);
  md = (mm = ok ? mj_loadXML(mjcf, NULL, error, sizeof error) : NULL) ? mj_makeData(mm) : NULL;
  if ((ok = md && mm->nq == 16 && mm->nv == 16)) {
    memcpy(md->qpos, r.q, sizeof r.q), memcpy(md->qvel, r.qd, sizeof r.qd), memcpy(md->qacc, r.qdd, sizeof r.qdd);
  } else {
    fprintf(stderr, "pkm_fmu_bench inverse: cannot load %s %s\n", mjcf, error);
  }
  return ok;
}
#endif

static int inverse_run(const Plant* p, const Options* o) {
  static const char* const inputs[12] = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"};
  static const char* const outputs[4] = {"F[1]", "F[2]", "F[3]", "F[4]"};
  double med[5] = {0}, mn[5] = {0}; /* the four instances, then mj_inverse */
  int b, k, have_mj = 0, ok = lookup_value_references(p, inputs, 12, in) && lookup_value_references(p, outputs, 4, out);
  plant = p;
  for (k = 0; k < TICKS; ++k) { /* one period per table, with the exact rates and accelerations */
    const double w = 2.0 * PI, s = sin(w * k * H), co = cos(w * k * H), a[4] = {0.002, 0.002, 0.005, 0.05};
    const double q[4] = {a[0] * s, a[1] * co, a[2] * s, a[3] * s}, v[4] = {a[0] * w * co, -a[1] * w * s, a[2] * w * co,
                                                                           a[3] * w * co};
    for (b = 0; b < 4; ++b)
      motion[k][b] = q[b] + (b == 2 ? 0.05 : 0.0), motion[k][4 + b] = v[b], motion[k][8 + b] = -w * w * q[b];
  }
#if PKM_HAVE_MUJOCO
  if (ok && o->mjcf) ok = have_mj = load_mujoco(o->mjcf);
#endif
  printf("tick = set the 12 motion inputs, advance (CS: DoStep 1 ms; ME: SetTime), get F[1..4];\n"
         "median and min per call over %d batches of %d calls, the cases interleaved batch by batch\n\n",
         o->batches, REPEAT * TICKS);
  for (k = 0; ok && k < 4; ++k) ok = (c[k] = instantiate(p, k, kind_names[k], -1, 0, NULL, NULL, NULL)) != NULL;
  ok = ok && time_cases(4 + have_mj, o->batches, time_ticks, med, mn);
  for (k = 0; k < 4; ++k)
    if (c[k]) free_instance(p, k, c[k], NULL);
#if PKM_HAVE_MUJOCO
  if (md) mj_deleteData(md);
  if (mm) mj_deleteModel(mm);
#endif
  if (!ok) return 0;
  printf("   %-40s %12s %12s %15s\n", "evaluation", "median/call", "min/call", "/ mj_inverse");
  if (have_mj)
    printf("   %-40s %9.1f ns %9.1f ns %15s\n", "MuJoCo mj_inverse (same mechanism)", med[4] * 1e9, mn[4] * 1e9,
           "1.00x (medians, mins)");
  for (k = 0; k < 4; ++k) {
    printf("   %-40s %9.1f ns %9.1f ns", kind_names[k], med[k] * 1e9, mn[k] * 1e9);
    if (have_mj)
      printf(" %7.3fx %6.3fx  target <= %gx: %s", med[k] / med[4], mn[k] / mn[4], TARGET,
             med[k] <= TARGET * med[4] ? "ok" : "OVER");
    printf("\n");
  }
  if (!have_mj)
    printf("   (no mj_inverse: %s)\n", PKM_HAVE_MUJOCO ? "give --mjcf (bench/engines_bench.py does)"
                                                    : "built without MuJoCo's library and headers");
  if (!(sum == sum)) printf("(non-finite forces)\n"); /* keeps the loops' results alive */
  return 1;
}

const Subcommand inverse_subcommand = {"inverse", "the inverse FMU's tick against MuJoCo's mj_inverse", inverse_run,
                                       101, "--mjcf FILE (MuJoCo's model of the mechanism)", 1};
