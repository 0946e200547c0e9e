// SPDX-License-Identifier: BSD-2-Clause
// What an FMU binary needs beyond its FMI functions.
#include <cstddef>  // defines __GLIBCXX__ with libstdc++
#if defined(PKM_FMI_FREE_EH_POOL) && defined(__GLIBCXX__)
namespace __gnu_cxx {
void __freeres();  // libstdc++ (eh_alloc.cc): frees the exception-handling emergency pool
}
namespace {
// The FMU binary links libstdc++ statically (-static-libstdc++), and with it
// a private exception-handling emergency pool (72 KiB, malloc'ed when the
// binary is loaded). Nothing would free it: after dlclose it is lost, once
// per load (valgrind: "definitely lost"). Free it when the binary unloads
// (dlclose, or process exit); no code of this binary runs after that.
__attribute__((destructor)) void free_emergency_pool() { __gnu_cxx::__freeres(); }
}  // namespace
#endif
