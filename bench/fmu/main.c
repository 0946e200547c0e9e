/* SPDX-License-Identifier: BSD-2-Clause */
/* pkm_fmu_bench: the FMUs' benchmarks, a subcommand each (plain C11, the built binary through dlopen and the raw FMI
 * functions, as a master drives it). Exit status: 1 if a call fails, 2 for a usage error, never how fast. */
#include "fmu_bench.h"

static const Subcommand* const subcommands[] = {&compare_subcommand, &cost_subcommand, &latency_subcommand,
                                                &jacobian_subcommand, &inverse_subcommand};
#define N_SUBCOMMANDS (sizeof subcommands / sizeof subcommands[0])

static int usage_error(const char* what, const char* arg) {
  fprintf(stderr, "pkm_fmu_bench: %s: %s (see pkm_fmu_bench --help)\n", what, arg);
  return 2;
}

/* The options after the subcommand (--batches, or a word of sub->options); 0, or 2 after a message. */
static int parse_options(const Subcommand* sub, int argc, char** argv, Options* o) {
  for (int i = 2; i < argc; i += 2) {
    const char *opt = argv[i], *value = i + 1 < argc ? argv[i + 1] : NULL, *own = strstr(sub->options, opt);
    char* end = NULL;
    if (strncmp(opt, "--", 2) != 0 || (strcmp(opt, "--batches") != 0 && !(own && own[strlen(opt)] == ' ')))
      return usage_error(opt[0] == '-' ? "unknown option" : "unexpected argument", opt);
    if (!value) return usage_error("missing value after", opt);
    if (strcmp(opt, "--out") == 0) o->out = value;
    if (strcmp(opt, "--mjcf") == 0) o->mjcf = value;
    if (strcmp(opt, "--batches") == 0 && ((o->batches = (int)strtol(value, &end, 10)), *end || o->batches < 1 ||
                                          o->batches > 100000))
      return usage_error("--batches out of range", value);
    if (strcmp(opt, "--seconds") == 0 && (o->seconds = strtod(value, &end), *end || !(o->seconds > 0.0)))
      return usage_error("--seconds must be positive", value);
  }
  return 0;
}

/* The build's binary, its functions and what the subcommand needs of its model description; 0 after a message. */
static int load(const Subcommand* sub, Plant* p) {
  const char* xml = sub->inverse ? PKM_FMU_INVERSE_XML : PKM_FMU_PLANT_XML;
  const char* root = (p->text = read_text(xml)) ? strstr(p->text, "<fmiModelDescription") : NULL;
  int ok;
  p->so = sub->inverse ? PKM_FMU_INVERSE_SO : PKM_FMU_PLANT_SO;
  if (!p->text) return fprintf(stderr, "pkm_fmu_bench: cannot read the model description %s\n", xml), 0;
  if (sub->inverse)
    ok = root && attribute(root, strchr(root, '>'), "guid", p->guid, sizeof p->guid);
  else
    ok = read_controller_interface(p->text, p->guid, sizeof p->guid, p->F, p->control) &&
         lookup_value_reference(p->text, "solver", &p->solver);
  ok = ok && load_fmu(p->so, &p->fmu);
#define PKM_BENCH_LOAD3(name) ok = ok && load_symbol(p->fmu.handle, #name, &p->fmu3.name, sizeof p->fmu3.name);
  if (sub->inverse) PKM_FMI3_FUNCTIONS(PKM_BENCH_LOAD3)
#undef PKM_BENCH_LOAD3
  return ok;
}

int main(int argc, char** argv) {
  const Subcommand* sub = NULL;
  Options o = {NULL, NULL, 0, 3.0};
  Plant plant;
  int ok;
  if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
    FILE* fp = argc < 2 ? stderr : stdout;
    fprintf(fp, "usage: pkm_fmu_bench SUBCOMMAND [--batches N] [options] (the build's FMU binaries)\n\n");
    for (size_t i = 0; i < N_SUBCOMMANDS; ++i)
      fprintf(fp, "  %-9s %s\n            --batches N (default %d)%s%s\n", subcommands[i]->name,
              subcommands[i]->summary, subcommands[i]->default_batches, *subcommands[i]->options ? "; " : "",
              subcommands[i]->options);
    return argc < 2 ? 2 : 0;
  }
  for (size_t i = 0; i < N_SUBCOMMANDS; ++i)
    if (strcmp(argv[1], subcommands[i]->name) == 0) sub = subcommands[i];
  if (!sub) return usage_error("unknown subcommand", argv[1]);
  o.batches = sub->default_batches;
  if (parse_options(sub, argc, argv, &o) != 0) return 2;
  memset(&plant, 0, sizeof plant);
  ok = load(sub, &plant);
  if (ok) {
    printf("pkm_fmu_bench %s: %s\n", sub->name, sub->summary);
    bench_print_machine();
    printf("fmu:     %s\n", plant.so);
  }
  ok = ok && sub->run(&plant, &o);
  if (plant.fmu.handle) dlclose(plant.fmu.handle);
  free((char*)plant.text);
  if (!ok) fprintf(stderr, "pkm_fmu_bench %s: FAILED\n", sub->name);
  return ok ? 0 : 1;
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message) {
  (void)env;
  if (status == fmi3Error || status == fmi3Fatal) fprintf(stderr, "[fmi3] %s: %s\n", category, message);
}

void* instantiate(const Plant* plant, int kind, const char* name, int solver, size_t n, const fmi2ValueReference* vr,
                  const fmi2Real* values, fmi2FMUstate* home) {
  static const fmi2CallbackFunctions callbacks = {logger, allocate_memory, free, NULL, NULL};
  const Fmu* f2 = &plant->fmu;
  const Fmu3* f3 = &plant->fmu3;
  const fmi2Integer s = solver;
  fmi2EventInfo info;
  fmi3Boolean a, b, d, e, g;
  fmi3Float64 next;
  void* c;
  int ok;
  if (kind <= FMI2_ME) {
    c = f2->fmi2Instantiate(name, kind == FMI2_CS ? fmi2CoSimulation : fmi2ModelExchange, plant->guid, "", &callbacks,
                            fmi2False, fmi2False);
    ok = c && !f2->fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) &&
         (solver < 0 || !f2->fmi2SetInteger(c, &plant->solver, 1, &s)) &&
         (n == 0 || !f2->fmi2SetReal(c, vr, n, values)) && !f2->fmi2EnterInitializationMode(c) &&
         !f2->fmi2ExitInitializationMode(c) &&
         (kind == FMI2_CS || (!f2->fmi2NewDiscreteStates(c, &info) && !f2->fmi2EnterContinuousTimeMode(c))) &&
         (!home || !f2->fmi2GetFMUstate(c, home));
  } else {
    c = kind == FMI3_CS
            ? f3->fmi3InstantiateCoSimulation(name, plant->guid, NULL, fmi3False, fmi3False, fmi3False, fmi3False, NULL,
                                              0, NULL, logger3, NULL)
            : f3->fmi3InstantiateModelExchange(name, plant->guid, NULL, fmi3False, fmi3False, NULL, logger3);
    ok = c && !f3->fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) &&
         !f3->fmi3ExitInitializationMode(c) &&
         (kind == FMI3_CS ||
          (!f3->fmi3UpdateDiscreteStates(c, &a, &b, &d, &e, &g, &next) && !f3->fmi3EnterContinuousTimeMode(c)));
  }
  if (ok) return c;
  if (c) kind <= FMI2_ME ? f2->fmi2FreeInstance(c) : f3->fmi3FreeInstance(c);
  fprintf(stderr, "pkm_fmu_bench: instantiating and initialising %s failed\n", name);
  return NULL;
}

int free_instance(const Plant* plant, int kind, void* c, fmi2FMUstate* home) {
  int ok = !(home && *home && plant->fmu.fmi2FreeFMUstate(c, home) != fmi2OK);
  ok = (kind <= FMI2_ME ? plant->fmu.fmi2Terminate(c) == fmi2OK : plant->fmu3.fmi3Terminate(c) == fmi3OK) && ok;
  kind <= FMI2_ME ? plant->fmu.fmi2FreeInstance(c) : plant->fmu3.fmi3FreeInstance(c);
  return ok;
}

int lookup_value_references(const Plant* plant, const char* const* names, size_t n, fmi2ValueReference* vr) {
  for (size_t i = 0; i < n; ++i)
    if (!lookup_value_reference(plant->text, names[i], &vr[i])) return 0;
  return 1;
}

int time_cases(int n, int batches, double (*batch)(int i), double* median, double* min) {
  double* per = malloc(sizeof(double) * (size_t)n * (size_t)batches); /* [case][batch] */
  int ok = per != NULL;
  for (int b = -1; ok && b < batches; ++b)
    for (int i = 0; ok && i < n; ++i) {
      const double s = batch(i);
      ok = s > 0.0;
      if (b >= 0) per[i * batches + b] = s;
    }
  for (int i = 0; ok && i < n; ++i) median[i] = bench_median(per + i * batches, (size_t)batches, &min[i]);
  free(per);
  return ok;
}

double run_ticks(const Plant* plant, fmi2Component c, fmi2FMUstate home, const Ticks* t) {
  static const fmi2Integer order[4] = {1, 1, 1, 1};
  const Fmu* f = &plant->fmu;
  double y[256], *out = t->record ? t->record : y, start;
  int k = 0;
  fmi2Status s = home ? f->fmi2SetFMUstate(c, home) : fmi2OK;
  if (s == fmi2OK && t->record) s = f->fmi2GetReal(c, t->out, t->n_out, t->record);
  start = bench_now();
  for (; s == fmi2OK && k < t->n; ++k) {
    const double tick = t->tick_s ? bench_now() : 0.0;
    s = f->fmi2SetReal(c, plant->F, 4, t->F[k]);
    if (s == fmi2OK && t->dF) s = f->fmi2SetRealInputDerivatives(c, plant->F, 4, order, t->dF[k]);
    if (s == fmi2OK) s = f->fmi2DoStep(c, k * t->h, t->h, fmi2True);
    if (s == fmi2OK && t->n_out) s = f->fmi2GetReal(c, t->out, t->n_out, out + (t->record ? (k + 1) * t->n_out : 0));
    if (t->tick_s) t->tick_s[k] = bench_now() - tick;
  }
  if (s == fmi2OK) return bench_now() - start;
  fprintf(stderr, "pkm_fmu_bench: a call of tick %d of %d (0: the start) returned %s\n", k, t->n, status_name(s));
  return -1.0;
}
