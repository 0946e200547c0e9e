/* SPDX-License-Identifier: BSD-2-Clause */
/* What the C programs that drive a built FMU binary share (the tests
 * fmu_allocations and fmu_alloc_faults, and bench/fmu's pkm_fmu_bench):
 * loading it with dlopen, a logger that stays silent unless the FMU reports
 * an error, reading modelDescription.xml's attributes and value references,
 * the controller's output names, the holding force. Static functions, one
 * copy per file that includes this; define PKM_HARNESS_NAME (the program's
 * name, for messages) first. */
#ifndef PKM_TESTS_FMU_HARNESS_H
#define PKM_TESTS_FMU_HARNESS_H

#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi/fmi_functions.h"

/* Each harness uses some of the functions below. */
#if defined(__GNUC__)
#define PKM_HARNESS_FN static __attribute__((unused))
#else
#define PKM_HARNESS_FN static
#endif

#ifndef PKM_HARNESS_NAME
#error "define PKM_HARNESS_NAME before including fmu_harness.h"
#endif

/* Every FMI 2.0 function the binaries export (src/fmi/fmi_functions.h). */
typedef struct {
  void* handle;
#define PKM_HARNESS_DECLARE(name) name##TYPE* name;
  PKM_FMI2_FUNCTIONS(PKM_HARNESS_DECLARE)
#undef PKM_HARNESS_DECLARE
} Fmu;

/* dlsym returns an object pointer; ISO C has no conversion to a function
 * pointer, POSIX guarantees the representation: copy the bytes. */
PKM_HARNESS_FN int load_symbol(void* handle, const char* name, void* fn_ptr, size_t fn_size) {
  void* p = dlsym(handle, name);
  if (!p) {
    fprintf(stderr, PKM_HARNESS_NAME ": symbol %s not found\n", name);
    return 0;
  }
  if (fn_size != sizeof p) {
    fprintf(stderr, PKM_HARNESS_NAME ": function and object pointers differ in size\n");
    return 0;
  }
  memcpy(fn_ptr, &p, fn_size);
  return 1;
}

PKM_HARNESS_FN int load_fmu(const char* path, Fmu* f) {
  int ok = 1;
  memset(f, 0, sizeof *f);
  f->handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (!f->handle) {
    fprintf(stderr, PKM_HARNESS_NAME ": dlopen(%s): %s\n", path, dlerror());
    return 0;
  }
#define LOAD(name) ok &= load_symbol(f->handle, #name, &f->name, sizeof f->name);
  PKM_FMI2_FUNCTIONS(LOAD)
#undef LOAD
  return ok;
}

PKM_HARNESS_FN const char* status_name(fmi2Status s) {
  switch (s) {
    case fmi2OK: return "fmi2OK";
    case fmi2Warning: return "fmi2Warning";
    case fmi2Discard: return "fmi2Discard";
    case fmi2Error: return "fmi2Error";
    case fmi2Fatal: return "fmi2Fatal";
    case fmi2Pending: return "fmi2Pending";
  }
  return "unknown status";
}

/* Silent unless the FMU reports an error. */
PKM_HARNESS_FN void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...) {
  va_list ap;
  (void)env;
  if (status != fmi2Error && status != fmi2Fatal) return;
  fprintf(stderr, "[%s] %s %s: ", instance ? instance : "?", status_name(status), category ? category : "");
  va_start(ap, message);
  vfprintf(stderr, message ? message : "", ap);
  va_end(ap);
  fputc('\n', stderr);
}

PKM_HARNESS_FN char* read_text(const char* path) {
  FILE* fp = fopen(path, "rb");
  char* text = NULL;
  long n;
  if (!fp) return NULL;
  if (fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) >= 0 && fseek(fp, 0, SEEK_SET) == 0) {
    text = malloc((size_t)n + 1);
    if (text && fread(text, 1, (size_t)n, fp) == (size_t)n) {
      text[n] = '\0';
    } else {
      free(text);
      text = NULL;
    }
  }
  fclose(fp);
  return text;
}

/* The value of attribute `name` ("name=\"") inside [begin, end), copied to out. */
PKM_HARNESS_FN int attribute(const char* begin, const char* end, const char* name, char* out, size_t size) {
  char key[64];
  const char* p = begin;
  size_t klen;
  const char* v;
  const char* q;
  snprintf(key, sizeof key, " %s=\"", name);
  klen = strlen(key);
  p = strstr(p, key);
  if (!p || p >= end) return 0;
  v = p + klen;
  q = strchr(v, '"');
  if (!q || q >= end || (size_t)(q - v) >= size) return 0;
  memcpy(out, v, (size_t)(q - v));
  out[q - v] = '\0';
  return 1;
}

/* The value reference of the ScalarVariable called `name` in the model
 * description `text`; -1 if none. */
PKM_HARNESS_FN long find_value_reference(const char* text, const char* name) {
  const char* p = text;
  while ((p = strstr(p, "<ScalarVariable")) != NULL) {
    const char* end = strstr(p, "</ScalarVariable>");
    char buf[128];
    if (!end) break;
    if (attribute(p, end, "name", buf, sizeof buf) && strcmp(buf, name) == 0 &&
        attribute(p, end, "valueReference", buf, sizeof buf))
      return strtol(buf, NULL, 10);
    p = end;
  }
  return -1;
}

/* find_value_reference into *vr; 0, with a message naming the variable, if
 * there is none. */
PKM_HARNESS_FN int lookup_value_reference(const char* text, const char* name, fmi2ValueReference* vr) {
  const long v = find_value_reference(text, name);
  if (v < 0) {
    fprintf(stderr, PKM_HARNESS_NAME ": no variable %s in the model description\n", name);
    return 0;
  }
  *vr = (fmi2ValueReference)v;
  return 1;
}

#define STATIC_FORCE 2.655616050 /* N, each slider's holding force at the home pose (docs/model.md "Bodies") */
#define PI 3.14159265358979323846

/* The 12 outputs a controller reads every tick: the pose, its rates and the
 * slider positions (an array initialiser). */
#define PKM_CONTROLLER_OUTPUTS \
  { "x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "rho[1]", "rho[2]", "rho[3]", "rho[4]" }

/* The guid of the model description `text` (its root element's attribute)
 * and the value references of F[1..4] and of the controller's 12 outputs
 * (PKM_CONTROLLER_OUTPUTS); 0, with a message, when one is missing. */
PKM_HARNESS_FN int read_controller_interface(const char* text, char* guid, size_t guid_size, fmi2ValueReference F[4],
                                             fmi2ValueReference control[12]) {
  static const char* outputs[12] = PKM_CONTROLLER_OUTPUTS;
  const char* root = text ? strstr(text, "<fmiModelDescription") : NULL;
  int i, ok = 1;
  if (!root || !attribute(root, strchr(root, '>'), "guid", guid, guid_size)) {
    fprintf(stderr, PKM_HARNESS_NAME ": cannot read the model description\n");
    return 0;
  }
  for (i = 0; i < 4; ++i) {
    char name[8];
    snprintf(name, sizeof name, "F[%d]", i + 1);
    ok = ok && lookup_value_reference(text, name, &F[i]);
  }
  for (i = 0; i < 12; ++i) ok = ok && lookup_value_reference(text, outputs[i], &control[i]);
  return ok;
}

/* The value references of every Real output of the model description
 * `text` into vr (at most max); how many, 0 if there are more than max. */
PKM_HARNESS_FN size_t real_outputs(const char* text, fmi2ValueReference* vr, size_t max) {
  const char* p = text;
  size_t n = 0;
  char buf[64];
  while ((p = strstr(p, "<ScalarVariable")) != NULL) {
    const char* end = strstr(p, "</ScalarVariable>");
    const char* real = strstr(p, "<Real");
    if (!end) break;
    if (attribute(p, end, "causality", buf, sizeof buf) && strcmp(buf, "output") == 0 && real && real < end &&
        attribute(p, end, "valueReference", buf, sizeof buf)) {
      if (n == max) return 0;
      vr[n++] = (fmi2ValueReference)strtoul(buf, NULL, 10);
    }
    p = end;
  }
  return n;
}

PKM_HARNESS_FN void* allocate_memory(size_t nobj, size_t size) { return calloc(nobj, size); }

#endif /* PKM_TESTS_FMU_HARNESS_H */
