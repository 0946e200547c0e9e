/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench jacobian: the full Jacobian [A B] (8 x 20) through fmi2GetDirectionalDerivative against the C API's
 * pkm_forward_derivatives, x moved by 1e-12 m * (k % 1024) per evaluation; at an unchanged state: the FMI overhead. */
#include "fmu_bench.h"
#include "pkm4puu/pkm.h"

#define EVALS 2000 /* per batch */
#define N_KNOWNS 20
#define N_UNKNOWNS 8

static const double kState[10] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.0, 0.0};
static fmi2ValueReference unknowns[N_UNKNOWNS], knowns[N_KNOWNS];

enum { CASE_CAPI, CASE_FMI, CASE_OVERHEAD, CASE_SINGLE, CASE_SINGLE_OVERHEAD, N_CASES };
static const Fmu* f;
static fmi2Component c;
static pkm_model* m;
static double J[N_CASES][N_UNKNOWNS * N_KNOWNS]; /* each case's last full Jacobian (8 x 20, row-major) */

/* One batch of EVALS full Jacobians: the time per Jacobian, 0 on failure. */
static double batch(int kind) {
  double x[10], seed[N_KNOWNS] = {0}, col[N_UNKNOWNS], A[64], B[96], ydot[8], seconds;
  const double inputs[12] = {STATIC_FORCE, STATIC_FORCE, STATIC_FORCE, STATIC_FORCE}, one = 1.0;
  const int single = kind == CASE_SINGLE || kind == CASE_SINGLE_OVERHEAD;
  const int moving = kind == CASE_FMI || kind == CASE_SINGLE || kind == CASE_CAPI;
  memcpy(x, kState, sizeof x);
  if (!moving) FMI_CHECK(f->fmi2SetContinuousStates(c, x, 10));
  seconds = bench_now();
  for (int k = 0; k < EVALS; ++k) {
    if (moving) x[0] = kState[0] + 1e-12 * (double)(k % 1024);
    if (kind == CASE_CAPI) {
      if (pkm_forward_derivatives(m, x, inputs, ydot, A, B) == PKM_OK) continue;
      return fprintf(stderr, "pkm_fmu_bench: pkm_forward_derivatives failed\n"), 0;
    }
    FMI_CHECK(f->fmi2SetContinuousStates(c, x, 10));
    for (int j = 0; j < N_KNOWNS; ++j) {
      seed[j] = 1.0;
      FMI_CHECK(single ? f->fmi2GetDirectionalDerivative(c, unknowns, N_UNKNOWNS, &knowns[j], 1, &one, col)
                       : f->fmi2GetDirectionalDerivative(c, unknowns, N_UNKNOWNS, knowns, N_KNOWNS, seed, col));
      seed[j] = 0.0;
      for (int i = 0; i < N_UNKNOWNS; ++i) J[kind][i * N_KNOWNS + j] = col[i];
    }
  }
  seconds = bench_now() - seconds;
  for (int i = 0; kind == CASE_CAPI && i < N_UNKNOWNS; ++i) /* the last point's, as the FMI cases leave it */
    for (int j = 0; j < N_KNOWNS; ++j) J[kind][i * N_KNOWNS + j] = j < 8 ? A[i * 8 + j] : B[i * 12 + j - 8];
  return seconds / EVALS;
}

static int jacobian_run(const Plant* plant, const Options* o) {
  static const char* const unknown_names[N_UNKNOWNS] = {"der(x)",  "der(y)",  "der(z)",  "der(phi)",
                                                        "der(dx)", "der(dy)", "der(dz)", "der(dphi)"};
  static const char* const known_names[N_KNOWNS] = {"x",     "y",     "z",     "phi",   "dx",    "dy",   "dz",
                                                    "dphi",  "F[1]",  "F[2]",  "F[3]",  "F[4]",  "Fe[1]", "Fe[2]",
                                                    "Fe[3]", "Me_z", "tau[1]", "tau[2]", "tau[3]", "tau[4]"};
  static const char* const names[N_CASES] = {"(a) C API pkm_forward_derivatives",
                                             "(b) FMI: SetContinuousStates + 20 calls, all 20 knowns, unit seed",
                                             "(c) FMI overhead: (b) at an unchanged state",
                                             "(d) FMI: SetContinuousStates + 20 calls, one known each",
                                             "(e) FMI overhead: (d) at an unchanged state"};
  double med[N_CASES], mn[N_CASES], diff = 0.0, scale = 0.0;
  int ok = lookup_value_references(plant, unknown_names, N_UNKNOWNS, unknowns) &&
           lookup_value_references(plant, known_names, N_KNOWNS, knowns);
  f = &plant->fmu;
  ok = ok && pkm_create(&m) == PKM_OK && (c = instantiate(plant, FMI2_ME, "jacobian", -1, 0, NULL, NULL, NULL));
  ok = ok && time_cases(N_CASES, o->batches, batch, med, mn);
  if (c && !free_instance(plant, FMI2_ME, c, NULL)) ok = 0;
  pkm_destroy(m);
  if (!ok) return 0;
  for (int i = 0; i < N_UNKNOWNS * N_KNOWNS; ++i) {
    diff = fmax(diff, fmax(fabs(J[CASE_FMI][i] - J[CASE_CAPI][i]), fabs(J[CASE_SINGLE][i] - J[CASE_CAPI][i])));
    scale = fmax(scale, fabs(J[CASE_CAPI][i]));
  }
  printf("scenario: default parameters, state (");
  for (int i = 0; i < 8; ++i) printf("%.3g%s", kState[i], i < 7 ? ", " : "), ");
  printf("F = %.9f N; x += 1e-12 m * (k %% 1024) per evaluation; %d evaluations a batch, %d batches\n\n", STATIC_FORCE,
         EVALS, o->batches);
  printf("%-66s %10s %10s %9s\n", "per full Jacobian", "median us", "min us", "vs (a)");
  for (int kind = CASE_CAPI; kind < N_CASES; ++kind)
    printf("%-66s %10.3f %10.3f %8.2fx\n", names[kind], 1e6 * med[kind], 1e6 * mn[kind], med[kind] / med[CASE_CAPI]);
  printf("\n");
  for (int kind = CASE_FMI; kind < N_CASES; kind += 2) {
    const double target = 2.0 + med[kind + 1] / med[CASE_CAPI], ratio = med[kind] / med[CASE_CAPI];
    printf("%s/(a) %.2f, target <= 2 + %s/(a) = %.2f  %s; FMI overhead %.3f us a call\n",
           kind == CASE_FMI ? "(b)" : "(d)", ratio, kind == CASE_FMI ? "(c)" : "(e)", target,
           ratio <= target ? "ok" : "OVER", 1e6 * med[kind + 1] / N_KNOWNS);
  }
  printf("(b), (d) against (a) at the last point: largest |difference| %.2e, relative to the largest entry %.2e\n",
         diff, scale > 0.0 ? diff / scale : diff);
  return 1;
}

const Subcommand jacobian_subcommand = {
    "jacobian", "the state derivative's full Jacobian [A B] (8 x 20) through FMI 2.0 Model Exchange against the C API",
    jacobian_run, 31, "", 0};
