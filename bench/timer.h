/* SPDX-License-Identifier: BSD-2-Clause */
/* The benchmarks' one timer, for C (pkm_fmu_bench) and C++ (pkm_bench): a
 * monotonic clock, the median, minimum and quantiles of a run's timings, and
 * the machine a table was measured on. */
#ifndef PKM_BENCH_TIMER_H
#define PKM_BENCH_TIMER_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(_WIN32)
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>
#else
#include <sys/utsname.h>
#include <unistd.h>
#endif

/* Seconds on a monotonic clock. */
static inline double bench_now(void) {
#if defined(_WIN32)
  LARGE_INTEGER f, c;
  QueryPerformanceFrequency(&f);
  QueryPerformanceCounter(&c);
  return (double)c.QuadPart / (double)f.QuadPart;
#else
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
}

static inline int bench_compare(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

static inline void bench_sort(double* v, size_t n) { qsort(v, n, sizeof v[0], bench_compare); }

/* Of sorted[0..n-1] (n >= 1): the value with a fraction q of them below it (q = 0.5: the median). */
static inline double bench_quantile(const double* sorted, size_t n, double q) {
  const size_t i = (size_t)(q * (double)n);
  return sorted[i < n ? i : n - 1];
}

/* Sorts v[0..n-1]; its median, and its minimum in *min_out. */
static inline double bench_median(double* v, size_t n, double* min_out) {
  bench_sort(v, n);
  *min_out = v[0];
  return bench_quantile(v, n, 0.5);
}

/* One line: the processor, its cores and the operating system. */
static inline void bench_print_machine(void) {
  char line[512], cpu[256] = "unknown processor", os[256] = "unknown system";
  long cores = 0;
  FILE* fp = fopen("/proc/cpuinfo", "r");
  while (fp && fgets(line, sizeof line, fp))
    if (strncmp(line, "model name", 10) == 0 && sscanf(strchr(line, ':') + 1, " %255[^\r\n]", cpu) == 1) break;
  if (fp) fclose(fp);
#if defined(_WIN32)
  SYSTEM_INFO si;
  GetSystemInfo(&si);
  cores = (long)si.dwNumberOfProcessors;
  snprintf(os, sizeof os, "Windows");
#else
  struct utsname u;
  if (uname(&u) == 0) snprintf(os, sizeof os, "%s %s %s", u.sysname, u.release, u.machine);
  cores = sysconf(_SC_NPROCESSORS_ONLN);
#endif
  printf("machine: %s; %ld cores online; %s\n", cpu, cores, os);
}

#endif /* PKM_BENCH_TIMER_H */
