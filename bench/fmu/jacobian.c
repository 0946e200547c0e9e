/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench jacobian: the full Jacobian of the state derivative through
 * fmi2GetDirectionalDerivative against the same Jacobians from the C API
 * (pkm_forward_derivatives: state_derivative_jacobians and a copy), in one
 * run.
 *
 *   pkm_fmu_bench jacobian [--batches N] [--fmu SO] [--xml FILE]
 *
 * Scenario: Model Exchange, default parameters, in continuous-time mode at
 * an off-centre, rotated, moving state with the holding forces as inputs.
 * Each evaluation moves x by 1e-12 m * (k % 1024) (a new point each time,
 * so nothing is reused across evaluations) and then:
 *   (a) C API: pkm_forward_derivatives at that state: ydot, A 8x8, B 8x12;
 *   (b) FMI: fmi2SetContinuousStates, then one fmi2GetDirectionalDerivative
 *       per known (unit seed; unknowns der(x)..der(dphi), knowns the 8
 *       states and 12 inputs): 20 calls, the whole A and B;
 *   (c) the FMI overhead: (b) at an unchanged state (the FMU evaluates the
 *       Jacobians once per point, so these calls only copy and check);
 *   (d), (e): (b), (c) with one known per call (seed 1), the other way
 *       importers build a Jacobian column by column.
 * Prints the median and minimum per full Jacobian and (b)/(a) against the
 * target (b) <= 2 (a) + (c), the same for (d) with (e). */
#define _POSIX_C_SOURCE 200809L

#include <math.h>

#include "bench.h"
#include "pkm4puu/pkm.h"

#define EVALS 2000 /* per batch */
#define BATCHES 31 /* at most */
#define N_KNOWNS 20
#define N_UNKNOWNS 8

static const double kState[10] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.0, 0.0};

#define CHECK(call)                                                                                      \
  do {                                                                                                   \
    const fmi2Status check_status_ = (call);                                                             \
    if (check_status_ != fmi2OK) {                                                                       \
      fprintf(stderr, PKM_HARNESS_NAME ": %s:%d: %s returned %s\n", __FILE__, __LINE__, #call,           \
              status_name(check_status_));                                                               \
      return 0;                                                                                          \
    }                                                                                                    \
  } while (0)

typedef struct {
  fmi2ValueReference unknowns[N_UNKNOWNS], knowns[N_KNOWNS];
} References;

typedef enum { CASE_CAPI, CASE_FMI, CASE_OVERHEAD, CASE_SINGLE, CASE_SINGLE_OVERHEAD, N_CASES } Case;

/* The Model Exchange instance in continuous-time mode at kState. */
static fmi2Component instantiate_me(const Plant* plant) {
  static const fmi2CallbackFunctions callbacks = {logger, allocate_memory, free, NULL, NULL};
  const Fmu* f = &plant->fmu;
  fmi2EventInfo info;
  fmi2Component c = f->fmi2Instantiate("jacobian", fmi2ModelExchange, plant->guid, "", &callbacks, fmi2False,
                                       fmi2False);
  int ok = c != NULL;
  ok = ok && f->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK;
  ok = ok && f->fmi2EnterInitializationMode(c) == fmi2OK && f->fmi2ExitInitializationMode(c) == fmi2OK;
  ok = ok && f->fmi2NewDiscreteStates(c, &info) == fmi2OK && f->fmi2EnterContinuousTimeMode(c) == fmi2OK;
  ok = ok && f->fmi2SetContinuousStates(c, kState, 10) == fmi2OK;
  if (!ok) {
    if (c) f->fmi2FreeInstance(c);
    fprintf(stderr, PKM_HARNESS_NAME ": instantiating the Model Exchange plant failed\n");
    return NULL;
  }
  return c;
}

/* One batch of EVALS full Jacobians; J receives the last (8 x 20, row-major). */
static int batch(const Fmu* f, fmi2Component c, pkm_model* m, const References* r, Case kind, double* seconds,
                 double J[N_UNKNOWNS * N_KNOWNS]) {
  double x[10], seed[N_KNOWNS] = {0}, col[N_UNKNOWNS], A[64], B[96], ydot[8];
  double inputs[12] = {STATIC_FORCE, STATIC_FORCE, STATIC_FORCE, STATIC_FORCE};
  const double one = 1.0;
  double t0;
  int k, j, i;
  memcpy(x, kState, sizeof x);
  const int single = kind == CASE_SINGLE || kind == CASE_SINGLE_OVERHEAD;
  const int moving = kind == CASE_FMI || kind == CASE_SINGLE || kind == CASE_CAPI;
  if (!moving) CHECK(f->fmi2SetContinuousStates(c, x, 10));
  t0 = now_seconds();
  for (k = 0; k < EVALS; ++k) {
    if (moving) x[0] = kState[0] + 1e-12 * (double)(k % 1024);
    if (kind == CASE_CAPI) {
      if (pkm_forward_derivatives(m, x, inputs, ydot, A, B) != PKM_OK) {
        fprintf(stderr, PKM_HARNESS_NAME ": pkm_forward_derivatives failed\n");
        return 0;
      }
      continue;
    }
    CHECK(f->fmi2SetContinuousStates(c, x, 10));
    for (j = 0; j < N_KNOWNS; ++j) {
      if (single) {
        CHECK(f->fmi2GetDirectionalDerivative(c, r->unknowns, N_UNKNOWNS, &r->knowns[j], 1, &one, col));
      } else {
        seed[j] = 1.0;
        CHECK(f->fmi2GetDirectionalDerivative(c, r->unknowns, N_UNKNOWNS, r->knowns, N_KNOWNS, seed, col));
        seed[j] = 0.0;
      }
      for (i = 0; i < N_UNKNOWNS; ++i) J[i * N_KNOWNS + j] = col[i];
    }
  }
  *seconds = now_seconds() - t0;
  if (kind == CASE_CAPI) /* the last point's, as the FMI cases leave it */
    for (i = 0; i < N_UNKNOWNS; ++i)
      for (j = 0; j < N_KNOWNS; ++j) J[i * N_KNOWNS + j] = j < 8 ? A[i * 8 + j] : B[i * 12 + j - 8];
  return 1;
}

static int jacobian_run(const Plant* plant, const Options* o) {
  static const char* const unknowns[N_UNKNOWNS] = {"der(x)",  "der(y)",  "der(z)",  "der(phi)",
                                                   "der(dx)", "der(dy)", "der(dz)", "der(dphi)"};
  static const char* const knowns[N_KNOWNS] = {"x",     "y",     "z",     "phi",   "dx",    "dy",   "dz",
                                               "dphi",  "F[1]",  "F[2]",  "F[3]",  "F[4]",  "Fe[1]", "Fe[2]",
                                               "Fe[3]", "Me_z", "tau[1]", "tau[2]", "tau[3]", "tau[4]"};
  static const char* const names[N_CASES] = {"(a) C API pkm_forward_derivatives",
                                             "(b) FMI: SetContinuousStates + 20 calls, all 20 knowns, unit seed",
                                             "(c) FMI overhead: (b) at an unchanged state",
                                             "(d) FMI: SetContinuousStates + 20 calls, one known each",
                                             "(e) FMI overhead: (d) at an unchanged state"};
  References r;
  const Fmu* f = &plant->fmu;
  double per[N_CASES][BATCHES], med[N_CASES], mn[N_CASES], J[N_CASES][N_UNKNOWNS * N_KNOWNS], diff = 0.0,
         scale = 0.0, seconds = 0.0;
  pkm_model* m = NULL;
  fmi2Component c;
  int kind, b, i, ok = 1;

  if (!lookup_value_references(plant, unknowns, N_UNKNOWNS, r.unknowns) ||
      !lookup_value_references(plant, knowns, N_KNOWNS, r.knowns))
    return 0;
  if (pkm_create(&m) != PKM_OK) {
    fprintf(stderr, PKM_HARNESS_NAME ": pkm_create failed\n");
    return 0;
  }
  c = instantiate_me(plant);
  if (!c) {
    pkm_destroy(m);
    return 0;
  }
  /* One warm-up batch of each, then the batches interleaved. */
  for (b = -1; ok && b < o->batches; ++b)
    for (kind = CASE_CAPI; ok && kind < N_CASES; ++kind) {
      ok = batch(f, c, m, &r, (Case)kind, &seconds, J[kind]);
      if (ok && b >= 0) per[kind][b] = seconds / EVALS;
    }
  if (f->fmi2Terminate(c) != fmi2OK) ok = 0;
  f->fmi2FreeInstance(c);
  pkm_destroy(m);
  if (!ok) return 0;
  for (kind = CASE_CAPI; kind < N_CASES; ++kind) {
    med[kind] = 1e6 * median_min(per[kind], o->batches, &mn[kind]);
    mn[kind] *= 1e6;
  }
  for (i = 0; i < N_UNKNOWNS * N_KNOWNS; ++i) {
    const double d = fmax(fabs(J[CASE_FMI][i] - J[CASE_CAPI][i]), fabs(J[CASE_SINGLE][i] - J[CASE_CAPI][i]));
    if (d > diff) diff = d;
    if (fabs(J[CASE_CAPI][i]) > scale) scale = fabs(J[CASE_CAPI][i]);
  }

  printf("pkm_fmu_bench jacobian: the full Jacobian [A B] (8 x 20) of the state derivative, FMI 2.0 Model Exchange\n");
  print_machine();
  printf("fmu:     %s\n", plant->so);
  printf("scenario: default parameters, state (%.3g, %.3g, %.3g, %.3g, %.3g, %.3g, %.3g, %.3g), F = %.9f N; "
         "x += 1e-12 m * (k %% 1024) per evaluation; %d evaluations a batch, %d batches\n\n",
         kState[0], kState[1], kState[2], kState[3], kState[4], kState[5], kState[6], kState[7], STATIC_FORCE,
         EVALS, o->batches);
  printf("%-66s %10s %10s %9s\n", "per full Jacobian", "median us", "min us", "vs (a)");
  for (kind = CASE_CAPI; kind < N_CASES; ++kind)
    printf("%-66s %10.3f %10.3f %8.2fx\n", names[kind], med[kind], mn[kind], med[kind] / med[CASE_CAPI]);
  printf("\n");
  for (kind = CASE_FMI; kind < N_CASES; kind += 2) {
    const double target = 2.0 + med[kind + 1] / med[CASE_CAPI];
    const double ratio = med[kind] / med[CASE_CAPI];
    printf("%s/(a) %.2f, target <= 2 + %s/(a) = %.2f  %s; FMI overhead %.3f us a call\n", kind == CASE_FMI ? "(b)" : "(d)",
           ratio, kind == CASE_FMI ? "(c)" : "(e)", target, ratio <= target ? "ok" : "OVER",
           med[kind + 1] / N_KNOWNS);
  }
  printf("(b), (d) against (a) at the last point: largest |difference| %.2e, relative to the largest entry %.2e\n",
         diff, scale > 0.0 ? diff / scale : diff);
  return 1;
}

const Subcommand jacobian_subcommand = {"jacobian",
                                        "the full Jacobian through fmi2GetDirectionalDerivative vs the C API",
                                        jacobian_run, BATCHES, BATCHES, ""};
