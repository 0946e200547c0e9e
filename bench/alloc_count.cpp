// The allocation counter of pkm_bench (alloc_count.hpp): operator new, every
// variant, and on glibc the C allocation functions, replaced for the whole
// process.
#include "alloc_count.hpp"

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_news{0};      // operator new / new[], every variant
std::atomic<long> g_mallocs{0};   // malloc family (includes the ones behind operator new)
std::atomic<bool> g_armed{false};  // a window is open: call the breakpoint hook
}  // namespace

// A place for a gdb breakpoint; called for each allocation while armed.
extern "C" __attribute__((noinline)) void pkm_bench_alloc_event(std::size_t bytes) {
  asm volatile("" : : "r"(bytes) : "memory");
}

namespace {
inline void note_alloc(std::atomic<long>& counter, std::size_t bytes) {
  counter.fetch_add(1, std::memory_order_relaxed);
  if (g_armed.load(std::memory_order_relaxed)) pkm_bench_alloc_event(bytes);
}
}  // namespace

#if defined(__GLIBC__) && !defined(PKM_BENCH_NO_MALLOC_HOOK)
// glibc: interpose the C allocation functions (the executable's definitions
// take precedence for every library in the process) and forward to glibc's
// own. This also sees allocations that never pass through operator new
// (Eigen's dynamic storage, SUNDIALS, libc).
#define PKM_BENCH_MALLOC_HOOK 1
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) noexcept {
  note_alloc(g_mallocs, n);
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) noexcept {
  note_alloc(g_mallocs, k * n);
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) noexcept {
  note_alloc(g_mallocs, n);
  return __libc_realloc(p, n);
}
void* memalign(std::size_t al, std::size_t n) noexcept {
  note_alloc(g_mallocs, n);
  return __libc_memalign(al, n);
}
void* aligned_alloc(std::size_t al, std::size_t n) noexcept {
  note_alloc(g_mallocs, n);
  return __libc_memalign(al, n);
}
int posix_memalign(void** out, std::size_t al, std::size_t n) noexcept {
  if (al == 0 || (al & (al - 1)) != 0 || al % sizeof(void*) != 0) return EINVAL;
  note_alloc(g_mallocs, n);
  void* p = __libc_memalign(al, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
}  // extern "C"
#else
#define PKM_BENCH_MALLOC_HOOK 0
#endif

namespace {
void* counted_new(std::size_t n) {
  note_alloc(g_news, n);
  return std::malloc(n ? n : 1);
}
void* counted_new_aligned(std::size_t n, std::align_val_t al) {
  note_alloc(g_news, n);
  std::size_t a = static_cast<std::size_t>(al);
  if (a < sizeof(void*)) a = sizeof(void*);
  void* p = nullptr;
  if (posix_memalign(&p, a, n ? n : 1) != 0) return nullptr;
  return p;
}
}  // namespace

void* operator new(std::size_t n) {
  if (void* p = counted_new(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = counted_new(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted_new(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted_new(n); }
void* operator new(std::size_t n, std::align_val_t al) {
  if (void* p = counted_new_aligned(n, al)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t al) {
  if (void* p = counted_new_aligned(n, al)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_new_aligned(n, al);
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_new_aligned(n, al);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

namespace alloc_count {

bool counts_mallocs() { return PKM_BENCH_MALLOC_HOOK != 0; }

Window::Window() {
  news0_ = g_news.load();
  mallocs0_ = g_mallocs.load();
  g_armed.store(true);
}

void Window::stop() {
  g_armed.store(false);
  news_ = g_news.load() - news0_;
  mallocs_ = g_mallocs.load() - mallocs0_;
}

}  // namespace alloc_count
