#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The test command: builds everything, runs the C++ tests (ctest), then the
# Python checks (pytest) when python_checks/ holds any test_*.py file.
#
# The sanitizer tests (ctest label "sanitized": their own clang build with
# AddressSanitizer and UndefinedBehaviorSanitizer, then the replay of the
# fuzzer's seed corpus, the fmpy checks and the C++ FMI tests against the
# instrumented FMUs) are the longest chain, so they start as soon as build/
# is configured and run beside everything else at a lower priority: they
# take the cores the main build leaves idle, then run beside the tests.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
# What the build needs first (Debian packages, fmpy's FMI headers); the rest
# of the Python requirements (the checks' numpy, SciPy, MuJoCo, Pinocchio,
# ...) install beside the build, which does not need them.
# Every platform: the Windows and aarch64 FMUs, built and tested under wine
# and qemu-user (cmake/Platforms.cmake). The tests and benchmarks are turned
# on by name, and link-time optimisation: a build/ that the main job
# configured has them off.
PKM_SETUP=for-build ./scripts/build.sh --configure-only -DPKM_PLATFORMS=ON -DPKM_BUILD_TESTS=ON \
  -DPKM_BUILD_BENCHMARKS=ON -DPKM_LTO=ON
setup_log=build/setup.log
./scripts/setup.sh >"$setup_log" 2>&1 &
setup_pid=$!
sanitized_log=build/sanitized_tests.log
# Every suite's results (JUnit XML: ctest's, pytest's, and those of the
# sanitized checks' own pytest and googletest runs, which write here when
# PKM_TEST_RESULTS is set) for the summary of skipped tests at the end
# (scripts/skipped_tests.py). An earlier run's are removed first: a part
# that did not run shows as such.
export PKM_TEST_RESULTS="$PWD/build/test_results"
results=$PKM_TEST_RESULTS
rm -rf "$results"
mkdir -p "$results"
# In a process group of its own (setsid), so that a failure before the end
# stops the whole run (ctest, the script, the compilers) and leaves nothing
# behind. A new session is also a new scheduling group where the kernel
# groups sessions (autogroup): its own nice value, not only the processes',
# must be lowered, or it takes half the machine from the main build.
# The fmpy checks and the C++ FMI tests against the instrumented binaries
# need the Python requirements and this build's test programs: they wait
# for the marker file written when both are there.
ready=build/.main_build_done
rm -f "$ready"
setsid bash -c 'echo 10 >/proc/self/autogroup 2>/dev/null || true
  late="hardening_sanitized_fmpy|hardening_sanitized_fmi_tests"
  nice -n 10 ctest --test-dir build --output-on-failure --no-tests=error -j2 -L sanitized -E "$late" \
    --output-junit "$PKM_TEST_RESULTS/ctest_sanitized.xml" || exit 1
  while [ ! -f "$0" ]; do sleep 2; done
  exec nice -n 10 ctest --test-dir build --output-on-failure --no-tests=error -j2 -R "$late" \
    --output-junit "$PKM_TEST_RESULTS/ctest_sanitized_late.xml"' \
  "$ready" >"$sanitized_log" 2>&1 &
sanitized_pid=$!
trap 'kill -- -"$sanitized_pid" 2>/dev/null || true; kill "$setup_pid" 2>/dev/null || true' EXIT
PKM_SETUP=none ./scripts/build.sh
if ! wait "$setup_pid"; then
  cat "$setup_log" >&2
  echo "run_tests: scripts/setup.sh FAILED (log: $setup_log)" >&2
  exit 1
fi
cat "$setup_log" >&2
touch "$ready"
# --no-tests=error: a build that registered no test must fail, not pass silently.
ctest --test-dir build --output-on-failure -j2 --no-tests=error -LE sanitized --output-junit "$results/ctest.xml"
status=0
# Only call pytest when there are tests, so its exit code 5 (no tests) cannot occur.
if compgen -G "python_checks/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q python_checks --junitxml="$results/pytest.xml" || status=$?
else
  echo "run_tests: no python_checks/test_*.py, pytest skipped" >&2
fi
echo "run_tests: waiting for the sanitizer tests (log: $sanitized_log)" >&2
if wait "$sanitized_pid"; then
  grep -E "tests passed|Passed|Skipped|Not Run|check_sanitized_fmi_tests" "$sanitized_log" || true
  echo "run_tests: the sanitizer tests passed (log: $sanitized_log)"
else
  cat "$sanitized_log"
  echo "run_tests: the sanitizer tests FAILED" >&2
  status=1
fi
trap - EXIT
# What did not run, and why (a check whose tool is missing skips, and says so here).
.venv/bin/python scripts/skipped_tests.py ctest="$results/ctest.xml" pytest="$results/pytest.xml" \
  "ctest sanitized=$results/ctest_sanitized.xml" "ctest sanitized checks=$results/ctest_sanitized_late.xml" \
  "pytest sanitized=$results/pytest_sanitized.xml" "gtest sanitized=$results/gtest_sanitized" >&2
exit "$status"
