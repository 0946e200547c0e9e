// Heap-allocation counting for pkm_bench (bench/alloc_count.cpp replaces
// operator new, every variant, and on glibc the malloc family): a window
// counts the allocations between its construction and stop().
//
// To find where an allocation comes from: run under gdb with
//   break pkm_bench_alloc_event
// (it is called for every allocation while a window is open).
#pragma once

#include <cstddef>

namespace alloc_count {

/// True where the malloc family is counted too (glibc), not only operator new.
bool counts_mallocs();

class Window {
 public:
  Window();
  void stop();
  long news() const { return news_; }
  long mallocs() const { return mallocs_; }

 private:
  long news0_ = 0, mallocs0_ = 0, news_ = 0, mallocs_ = 0;
};

}  // namespace alloc_count
