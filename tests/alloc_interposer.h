/* SPDX-License-Identifier: BSD-2-Clause */
/* The project's one allocation counter: a malloc interposer, linked into
 * the C test harnesses that drive an FMU binary (tests/fmu_allocations.c,
 * tests/fmu_alloc_faults.c) and the core's allocation test
 * (tests/core/allocations.cpp). The program defines
 * malloc, calloc, realloc and the aligned allocators itself (glibc's own
 * implementations, __libc_*, underneath), so every heap allocation of the
 * process -- the FMU's operator new, SUNDIALS' malloc, the C++ runtime
 * linked into the FMU -- passes through here and is counted. One allocation
 * can be made to fail (return NULL, errno = ENOMEM), as an exhausted heap
 * would (single-threaded use only, as the harnesses are; the count itself
 * is atomic). glibc only. */
#ifndef PKM_TESTS_ALLOC_INTERPOSER_H
#define PKM_TESTS_ALLOC_INTERPOSER_H

#ifdef __cplusplus
extern "C" {
#endif

/* Heap allocations so far (every successful or failed request). */
long alloc_count(void);
/* The allocation with number alloc_count() == n (counted from 1) fails;
 * 0: none fails. */
void alloc_fail_at(long n);

#ifdef __cplusplus
}
#endif

#endif
