/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench: the plant FMU's benchmarks, one program with a subcommand
 * each (plain C11): the built PKM4PUU.so loaded with dlopen and driven
 * through the raw FMI 2.0 Co-Simulation functions, as a master drives it.
 * Each prints a table; none is a test (the exit status says whether the
 * runs worked, never how fast they were).
 *
 *   pkm_fmu_bench SUBCOMMAND [--fmu PKM4PUU.so] [--xml modelDescription.xml] [--batches N] [its options]
 *   pkm_fmu_bench --help
 *
 * Default .so: the build's $<TARGET_FILE:PKM4PUU> (PKM_FMU_PLANT_SO). The
 * GUID and the value references are read at run time from a
 * modelDescription.xml: --xml if given, else the build's staged copy for the
 * build's binary, else that of the unpacked FMU the .so sits in
 * (<so>/../../../modelDescription.xml, the layout binaries/linux64/<id>.so).
 *
 * Exit status: 0; 1 if a run fails (an FMI call not returning fmi2OK, a
 * missing symbol, an unreadable model description); 2 for a usage error. */
#define _POSIX_C_SOURCE 200809L

#include "bench.h"

static const Subcommand* const subcommands[] = {&step_subcommand, &latency_subcommand, &cost_subcommand,
                                                &compare_subcommand, &jacobian_subcommand};
#define N_SUBCOMMANDS (sizeof subcommands / sizeof subcommands[0])

static void usage(FILE* fp) {
  size_t i;
  fprintf(fp,
          "usage: pkm_fmu_bench SUBCOMMAND [--fmu PKM4PUU.so] [--xml modelDescription.xml] [--batches N] "
          "[options]\n\nsubcommands:\n");
  for (i = 0; i < N_SUBCOMMANDS; ++i)
    fprintf(fp, "  %-8s %s\n           --batches 1..%d (default %d)%s%s\n", subcommands[i]->name,
            subcommands[i]->summary, subcommands[i]->max_batches, subcommands[i]->default_batches,
            *subcommands[i]->options ? "; " : "", subcommands[i]->options);
  fprintf(fp, "\n--fmu: default %s; --xml: default the model description that goes with it\n", PKM_FMU_PLANT_SO);
}

static int usage_error(const char* what, const char* arg) {
  fprintf(stderr, "pkm_fmu_bench: %s: %s (see pkm_fmu_bench --help)\n", what, arg);
  return 2;
}

/* The options after the subcommand; 0 if fine, else 2 after a message. */
static int parse_options(const Subcommand* sub, int argc, char** argv, Options* o) {
  int i;
  o->so = PKM_FMU_PLANT_SO;
  o->xml = NULL;
  o->batches = sub->default_batches;
  o->seconds = 3.0;
  o->out = NULL;
  o->solver = -1;
  for (i = 2; i < argc; ++i) {
    const char* opt = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : NULL;
    const size_t len = strlen(opt);
    /* the subcommand's own option: the first word of sub->options */
    const int own = len > 2 && strncmp(sub->options, opt, len) == 0 && sub->options[len] == ' ';
    char* end = NULL;
    /* an option of another subcommand is as unknown here as a misspelt one */
    if (strncmp(opt, "--", 2) != 0 ||
        (strcmp(opt, "--fmu") != 0 && strcmp(opt, "--xml") != 0 && strcmp(opt, "--batches") != 0 && !own))
      return usage_error(opt[0] == '-' ? "unknown option" : "unexpected argument", opt);
    if (!value) return usage_error("missing value after", opt);
    ++i;
    if (strcmp(opt, "--fmu") == 0) {
      o->so = value;
    } else if (strcmp(opt, "--xml") == 0) {
      o->xml = value;
    } else if (strcmp(opt, "--out") == 0) {
      o->out = value;
    } else if (strcmp(opt, "--batches") == 0) {
      const long n = strtol(value, &end, 10);
      if (*end || n < 1 || n > sub->max_batches) return usage_error("--batches out of range", value);
      o->batches = (int)n;
    } else if (strcmp(opt, "--seconds") == 0) {
      o->seconds = strtod(value, &end);
      if (*end || !(o->seconds > 0.0)) return usage_error("--seconds must be positive", value);
    } else if (strcmp(opt, "--solver") == 0) {
      if (strcmp(value, "0") != 0 && strcmp(value, "1") != 0) return usage_error("--solver must be 0 or 1", value);
      o->solver = value[0] - '0';
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  const Subcommand* sub = NULL;
  Options o;
  Plant plant;
  char *xml_path = NULL, *text = NULL;
  size_t i;
  int status;
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (i = 0; i < N_SUBCOMMANDS; ++i)
    if (strcmp(argv[1], subcommands[i]->name) == 0) sub = subcommands[i];
  if (!sub) return usage_error("unknown subcommand", argv[1]);
  if (parse_options(sub, argc, argv, &o) != 0) return 2;

  memset(&plant, 0, sizeof plant);
  plant.so = o.so;
  plant.xml = o.xml ? o.xml : (xml_path = default_xml_path(o.so));
  if (!plant.xml) {
    fprintf(stderr, "pkm_fmu_bench: cannot derive the model description path from %s\n", o.so);
    return 1;
  }
  plant.text = text = read_text(plant.xml);
  if (!read_controller_interface(text, plant.guid, sizeof plant.guid, plant.F, plant.control) ||
      !lookup_value_reference(text, "solver", &plant.solver) || !load_fmu(o.so, &plant.fmu)) {
    status = 1;
  } else {
    status = exit_status(sub->run(&plant, &o));
    dlclose(plant.fmu.handle);
  }
  free(text);
  free(xml_path);
  return status;
}

/* ------------------------------------------------ shared by the subcommands */

fmi2Component instantiate_plant(const Plant* plant, const char* name, int solver, size_t n,
                                const fmi2ValueReference* vr, const fmi2Real* values, fmi2FMUstate* home) {
  static const fmi2CallbackFunctions callbacks = {logger, allocate_memory, free, NULL, NULL};
  const Fmu* f = &plant->fmu;
  const fmi2Integer s = solver;
  fmi2Component c = f->fmi2Instantiate(name, fmi2CoSimulation, plant->guid, "", &callbacks, fmi2False, fmi2False);
  int ok = c != NULL;
  ok = ok && f->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK;
  ok = ok && f->fmi2SetInteger(c, &plant->solver, 1, &s) == fmi2OK;
  ok = ok && (n == 0 || f->fmi2SetReal(c, vr, n, values) == fmi2OK);
  ok = ok && f->fmi2EnterInitializationMode(c) == fmi2OK && f->fmi2ExitInitializationMode(c) == fmi2OK;
  ok = ok && (!home || f->fmi2GetFMUstate(c, home) == fmi2OK);
  if (!ok) {
    if (c) f->fmi2FreeInstance(c);
    fprintf(stderr, "pkm_fmu_bench: instantiating and initialising %s failed\n", name);
    return NULL;
  }
  return c;
}

int free_plant(const Plant* plant, fmi2Component c, fmi2FMUstate* home) {
  const Fmu* f = &plant->fmu;
  int ok = 1;
  if (home && *home && f->fmi2FreeFMUstate(c, home) != fmi2OK) ok = 0;
  if (f->fmi2Terminate(c) != fmi2OK) ok = 0;
  f->fmi2FreeInstance(c);
  return ok;
}

int lookup_value_references(const Plant* plant, const char* const* names, size_t n, fmi2ValueReference* vr) {
  size_t i;
  for (i = 0; i < n; ++i)
    if (!lookup_value_reference(plant->text, names[i], &vr[i])) return 0;
  return 1;
}

double median_min(double* v, int n, double* min_out) {
  qsort(v, (size_t)n, sizeof v[0], compare_double);
  *min_out = v[0];
  return v[n / 2];
}
