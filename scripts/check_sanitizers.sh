#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The C++ FMI tests (dlopen'd FMU binaries: life cycle, misuse, bad input,
# singularities, threads, Model Exchange) against FMU binaries and tests
# built with AddressSanitizer and UndefinedBehaviorSanitizer
# (-DPKM_SANITIZE=ON, in its own build directory). Any finding fails.
#   scripts/check_sanitizers.sh [--build-dir DIR]     (default build-sanitize)
# Excluded: FmuBinaries.NeedOnlyTheSystemRuntime (instrumented binaries need
# libasan by design) and the fmpy-driven cases (an uninstrumented Python
# would have to preload libasan).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-sanitize
if [[ "${1:-}" == "--build-dir" ]]; then build="$2"; fi
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPKM_SANITIZE=ON -DPKM_LTO=OFF \
      -DPKM_BUILD_BENCHMARKS=OFF >/dev/null
targets=(fmi_state_machine fmi_bad_arguments fmi_variables fmi_fmu_states_restored fmi_fmu_states_refused fmi_stepping
         fmi_logging fmi_binary fmi_model_exchange fmi_machine fmi_bad_inputs_and_parameters fmi_singularities fmi_threads)
cmake --build "$build" -j2 --target "${targets[@]}"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
for t in "${targets[@]}"; do
  "$build/tests/$t" --gtest_brief=1 --gtest_filter='-FmuBinaries.NeedOnlyTheSystemRuntime:*Fmpy*'
done
echo "check_sanitizers: no finding in ${#targets[@]} test programs"
