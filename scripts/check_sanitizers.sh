#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The whole C++ suite (the core, the C API and the FMI tests, dlopen'd FMU
# binaries included) built with AddressSanitizer and
# UndefinedBehaviorSanitizer (-DPKM_SANITIZE=ON, in its own build
# directory): every googletest program the build makes, found by its name
# (core_*, capi_*, fmi_*), so a new one is run without a list to keep. Any
# finding fails.
#   scripts/check_sanitizers.sh [--build-dir DIR]     (default build-sanitize)
# Excluded: FmuBinaries.NeedOnlyTheSystemRuntime (instrumented binaries need
# libasan by design) and the fmpy-driven cases (an uninstrumented Python
# would have to preload libasan); fmu_allocations and fmu_alloc_faults
# (malloc interposers, which ASan's allocator replaces).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-sanitize
if [[ "${1:-}" == "--build-dir" ]]; then build="$2"; fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPKM_SANITIZE=ON -DPKM_LTO=OFF \
      -DPKM_BUILD_BENCHMARKS=OFF -DPKM_PLATFORMS=OFF >/dev/null
cmake --build "$build" -j2
mapfile -t programs < <(find "$build/tests" -maxdepth 1 -type f -executable \( -name 'core_*' -o -name 'capi_*' \
                          -o -name 'fmi_*' \) | sort)
if ((${#programs[@]} == 0)); then echo "check_sanitizers: no test program in $build/tests" >&2; exit 1; fi
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for t in "${programs[@]}"; do
  echo "check_sanitizers: ${t##*/}"
  "$t" --gtest_brief=1 --gtest_filter='-FmuBinaries.NeedOnlyTheSystemRuntime:*Fmpy*'
done
echo "check_sanitizers: no finding in ${#programs[@]} test programs"
