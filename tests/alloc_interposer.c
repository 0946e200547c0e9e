/* SPDX-License-Identifier: BSD-2-Clause */
/* See alloc_interposer.h. */
#define _GNU_SOURCE
#include "alloc_interposer.h"

#include <errno.h>
#include <stddef.h>
#include <string.h>

extern void* __libc_malloc(size_t size);
extern void* __libc_calloc(size_t n, size_t size);
extern void* __libc_realloc(void* p, size_t size);
extern void* __libc_memalign(size_t alignment, size_t size);
extern void __libc_free(void* p);

static long count_;
static long fail_at_;

long alloc_count(void) { return __atomic_load_n(&count_, __ATOMIC_RELAXED); }
void alloc_fail_at(long n) { fail_at_ = n; }

/* Called when the allocation made to fail is requested: a place for a
 * debugger's breakpoint (break pkm_alloc_fault_hook). */
__attribute__((noinline)) void pkm_alloc_fault_hook(void) { __asm__ volatile(""); }

/* Counts one request; 0 if it is the one to fail. */
static int admit(void) {
  const long n = __atomic_add_fetch(&count_, 1, __ATOMIC_RELAXED);
  if (fail_at_ != 0 && n == fail_at_) {
    pkm_alloc_fault_hook();
    errno = ENOMEM;
    return 0;
  }
  return 1;
}

void* malloc(size_t size) { return admit() ? __libc_malloc(size) : NULL; }
void* calloc(size_t n, size_t size) { return admit() ? __libc_calloc(n, size) : NULL; }
void* realloc(void* p, size_t size) { return admit() ? __libc_realloc(p, size) : NULL; }
void free(void* p) { __libc_free(p); }
void* memalign(size_t alignment, size_t size) { return admit() ? __libc_memalign(alignment, size) : NULL; }
void* aligned_alloc(size_t alignment, size_t size) { return memalign(alignment, size); }
void* valloc(size_t size) { return memalign(4096, size); }
int posix_memalign(void** out, size_t alignment, size_t size) {
  void* p = memalign(alignment, size);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
