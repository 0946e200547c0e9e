/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench: what its subcommands (step.c, latency.c, cost.c,
 * compare.c, jacobian.c) share beyond harness.h: the options, the loaded plant FMU with
 * its model description, an instance set up for a solver, and the median of
 * a run's timings. main.c defines these and dispatches. */
#ifndef PKM_BENCH_FMU_BENCH_H
#define PKM_BENCH_FMU_BENCH_H

#define PKM_HARNESS_NAME "pkm_fmu_bench"
#include "harness.h"

#ifndef PKM_FMU_PLANT_SO
#define PKM_FMU_PLANT_SO "PKM4PUU.so"
#endif

#define STATIC_FORCE 2.655616050 /* N, docs/model.md "Bodies" */
#define PI 3.14159265358979323846

/* The command line after the subcommand (main.c parses it). */
typedef struct {
  const char* so;    /* --fmu; default PKM_FMU_PLANT_SO */
  const char* xml;   /* --xml; default derived from so (default_xml_path) */
  int batches;       /* --batches; the subcommand's default if not given */
  double seconds;    /* --seconds (cost) */
  const char* out;   /* --out (compare) */
  int solver;        /* --solver (step); -1: both */
} Options;

/* The plant FMU, loaded, and its model description's text and guid. */
typedef struct {
  Fmu fmu;
  const char* so;
  const char* xml;
  const char* text;
  char guid[128];
  fmi2ValueReference solver;       /* the parameter every subcommand sets */
  fmi2ValueReference F[4];         /* the inputs */
  fmi2ValueReference control[12];  /* a controller's outputs (PKM_CONTROLLER_OUTPUTS): x, y, z, phi first */
} Plant;

/* One subcommand: its entry point and how main.c treats its options. */
typedef struct {
  const char* name;
  const char* summary;
  int (*run)(const Plant* plant, const Options* options);
  int default_batches, max_batches;
  const char* options; /* the subcommand's own options beyond --fmu, --xml, --batches ("--seconds", ...) */
} Subcommand;

extern const Subcommand step_subcommand, latency_subcommand, cost_subcommand, compare_subcommand, jacobian_subcommand;

/* fmi2Instantiate (Co-Simulation) + fmi2SetupExperiment + fmi2SetInteger(solver)
 * + fmi2SetReal of n parameters + Enter/ExitInitializationMode, then, if home
 * is not NULL, fmi2GetFMUstate into it. NULL, with a message, on failure. */
fmi2Component instantiate_plant(const Plant* plant, const char* name, int solver, size_t n,
                                const fmi2ValueReference* vr, const fmi2Real* values, fmi2FMUstate* home);
/* Frees *home (if any), terminates and frees the instance; 0 if a call failed. */
int free_plant(const Plant* plant, fmi2Component c, fmi2FMUstate* home);
/* The value references of names[0..n-1] into vr; 0, with a message, if one is missing. */
int lookup_value_references(const Plant* plant, const char* const* names, size_t n, fmi2ValueReference* vr);
/* Sorts v[0..n-1]; its median, and its minimum in *min_out. */
double median_min(double* v, int n, double* min_out);

#endif /* PKM_BENCH_FMU_BENCH_H */
