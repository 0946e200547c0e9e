#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The C++ FMI tests (tests/fmi: state machine, variables, FMU states,
# stepping, logging, bad inputs and parameters, singularities, threads,
# Model Exchange, derivatives, the machine, the auto-test chain) against the
# FMU binaries built with clang's AddressSanitizer and
# UndefinedBehaviorSanitizer: the test programs of the gcc build, each run
# once with PKM_FMU_BINARIES pointing at the sanitized tree's binaries
# (fuzz/run_fuzz.sh --build-only) and the sanitizer runtime preloaded. Any
# finding aborts the program, so its run fails.
#   scripts/check_sanitized_fmi_tests.sh FUZZ_TREE BUILD_DIR
# Left out, for time (instrumented, they take 100 times as long):
# tests/fmi/threads.cpp (160 s; concurrency is ThreadSanitizer's field, not
# AddressSanitizer's) and Stepping.AStepTooLongForCvodeIsDiscarded (18 s of
# CVODE up to its step limit; the fuzzer's seed corpus reaches that path);
# and tests/fmi/binary.cpp and model_description.cpp (the binaries as files
# and the variable tables: nothing of the instrumented code runs).
# Leaks are not checked here (the test programs are not instrumented);
# valgrind's ctest run checks the FMUs for leaks.
# Exit status: 0 all passed, 1 a failure, 77 (skipped) when clang's runtime
# is missing.
set -euo pipefail
tree="${1:?usage: scripts/check_sanitized_fmi_tests.sh FUZZ_TREE BUILD_DIR}"
build="${2:?usage: scripts/check_sanitized_fmi_tests.sh FUZZ_TREE BUILD_DIR}"
source "$(dirname "${BASH_SOURCE[0]}")/sanitizer_env.sh" check_sanitized_fmi_tests
binaries="$tree/fmu-binaries"
programs=()
for exe in "$build"/tests/fmi_*; do
  case "$(basename "$exe")" in
    fmi_binary | fmi_model_description | fmi_threads | *[!a-z_]*) continue ;;
  esac
  [ -x "$exe" ] && programs+=("$exe")
done
[ "${#programs[@]}" -gt 0 ] || { echo "check_sanitized_fmi_tests: no tests/fmi_* programs in $build" >&2; exit 1; }
# The test programs must really load the instrumented binaries: without the
# runtime, loading them fails.
if PKM_FMU_BINARIES="$binaries" "$build/tests/fmi_state_machine" --gtest_filter='*' >/dev/null 2>&1; then
  echo "check_sanitized_fmi_tests: the tests pass without the sanitizer runtime: $binaries is not an instrumented build (or PKM_FMU_BINARIES is ignored)" >&2
  exit 1
fi
logs="$tree/fmi-tests"
rm -rf "$logs" && mkdir -p "$logs"
export LD_PRELOAD="$sanitizer_runtime" PKM_FMU_BINARIES="$binaries"
export GTEST_FILTER='-Stepping.AStepTooLongForCvodeIsDiscarded'
# Their results for the test command's summary of skipped tests (run_tests.sh).
[ -z "${PKM_TEST_RESULTS:-}" ] || export GTEST_OUTPUT="xml:$PKM_TEST_RESULTS/gtest_sanitized/"
echo "check_sanitized_fmi_tests: ${#programs[@]} programs against $binaries (logs: $logs)" >&2
# Two at a time; each program's log is printed if it fails.
printf '%s\n' "${programs[@]}" | xargs -P 2 -I{} bash -c '
  log="$0/$(basename "{}").log"
  if "{}" --gtest_brief=1 >"$log" 2>&1; then
    echo "  passed: $(basename "{}") ($(grep -Eo "[0-9]+ tests?" "$log" | tail -1))"
  else
    echo "  FAILED: $(basename "{}"); its log:"; tail -80 "$log"; exit 255
  fi' "$logs" || { echo "check_sanitized_fmi_tests: FAILED" >&2; exit 1; }
echo "check_sanitized_fmi_tests: all ${#programs[@]} programs passed against the instrumented binaries" >&2
