/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench: what its subcommands share (main.c defines it): the options, the loaded FMU, its instances, the
 * one loop of a master's ticks. Each source file includes it first (it asks for POSIX and GNU functions). */
#ifndef PKM_BENCH_FMU_BENCH_H
#define PKM_BENCH_FMU_BENCH_H

#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>

#define PKM_HARNESS_NAME "pkm_fmu_bench"
#include "fmi3FunctionTypes.h"
#include "fmu_harness.h"
#include "timer.h"

typedef struct {
  const char *out, *mjcf; /* --out (compare), --mjcf (inverse) */
  int batches;
  double seconds; /* --seconds (cost) */
} Options;

typedef struct {
#define PKM_BENCH_DECLARE3(name) name##TYPE* name;
  PKM_FMI3_FUNCTIONS(PKM_BENCH_DECLARE3)
#undef PKM_BENCH_DECLARE3
} Fmu3;

/* The build's FMU binary, loaded (FMI 3.0 too for the inverse FMU), its model description's text and guid; the
 * plant's F[1..4], controller outputs and solver. */
typedef struct {
  Fmu fmu;
  Fmu3 fmu3;
  const char *so, *text;
  char guid[128];
  fmi2ValueReference F[4], control[12], solver;
} Plant;

typedef struct {
  const char *name, *summary;
  int (*run)(const Plant* plant, const Options* options);
  int default_batches;
  const char* options; /* its own options beyond --batches */
  int inverse;         /* drives the inverse FMU (PKM4PUU_Inverse) */
} Subcommand;

extern const Subcommand compare_subcommand, cost_subcommand, latency_subcommand, jacobian_subcommand,
    inverse_subcommand;

enum { FMI2_CS, FMI2_ME, FMI3_CS, FMI3_ME }; /* an instance's interface */

/* An instance of `kind`, initialised (Model Exchange: in continuous-time mode); with FMI 2.0 its solver (if >= 0) and
 * n Real parameters set first and its state then kept in *home (if given). NULL after a message on failure. */
void* instantiate(const Plant* plant, int kind, const char* name, int solver, size_t n, const fmi2ValueReference* vr,
                  const fmi2Real* values, fmi2FMUstate* home);
/* Frees *home (if given), terminates and frees the instance; 0 if a call failed. */
int free_instance(const Plant* plant, int kind, void* c, fmi2FMUstate* home);
/* The value references of names[0..n-1]; 0 after a message if one is missing. */
int lookup_value_references(const Plant* plant, const char* const* names, size_t n, fmi2ValueReference* vr);

/* A master's ticks: each sets F[k] (with dF, their slopes too), DoSteps h and gets the n_out outputs `out`, kept in
 * record ((n + 1) x n_out, the outputs before the first tick first) if given; tick_s (if given): each tick's time. */
typedef struct {
  double h;
  int n;
  double (*F)[4], (*dF)[4];
  const fmi2ValueReference* out;
  size_t n_out;
  double *record, *tick_s;
} Ticks;
/* The ticks from t = 0, from the state home if given (restored untimed): their wall time, < 0 after a message when
 * a call fails. */
double run_ticks(const Plant* plant, fmi2Component c, fmi2FMUstate home, const Ticks* ticks);

/* The one loop of the timed batches: n cases interleaved batch by batch, one warm-up batch of each first; batch(i)
 * runs one of case i, returns its time (<= 0 after a message on failure). Per case median[i], min[i]; 0 on failure. */
int time_cases(int n, int batches, double (*batch)(int i), double* median, double* min);

/* Returns 0 from the calling function, after a message, when an FMI call (or an || of them) does not return OK. */
#define FMI_CHECK(call) \
  do { if ((call) != 0) return fprintf(stderr, "pkm_fmu_bench: %s did not return OK\n", #call), 0; } while (0)

#endif /* PKM_BENCH_FMU_BENCH_H */
