#!/usr/bin/env bash
# The test command: builds everything, runs the C++ tests (ctest), then the
# Python checks (pytest) when python_checks/ holds any test_*.py file.
#
# The sanitizer tests (ctest label "sanitized": their own clang build with
# AddressSanitizer and UndefinedBehaviorSanitizer, then the replay of the
# fuzzer's seed corpus and the fmpy checks against the instrumented FMUs)
# are the longest chain, so they start as soon as build/ is configured and
# run beside everything else at a lower priority: they take the cores the
# main build leaves idle, then run beside the tests.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh --configure-only
sanitized_log=build/sanitized_tests.log
# In a process group of its own (setsid), so that a failure before the end
# stops the whole run (ctest, the script, the compilers) and leaves nothing
# behind. A new session is also a new scheduling group where the kernel
# groups sessions (autogroup): its own nice value, not only the processes',
# must be lowered, or it takes half the machine from the main build.
setsid bash -c 'echo 10 >/proc/self/autogroup 2>/dev/null || true
  exec nice -n 10 ctest --test-dir build --output-on-failure --no-tests=error -j2 -L sanitized' \
  >"$sanitized_log" 2>&1 &
sanitized_pid=$!
trap 'kill -- -"$sanitized_pid" 2>/dev/null || true' EXIT
./scripts/build.sh
# --no-tests=error: a build that registered no test must fail, not pass silently.
ctest --test-dir build --output-on-failure -j2 --no-tests=error -LE sanitized
status=0
# Only call pytest when there are tests, so its exit code 5 (no tests) cannot occur.
if compgen -G "python_checks/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q python_checks || status=$?
else
  echo "run_tests: no python_checks/test_*.py, pytest skipped" >&2
fi
echo "run_tests: waiting for the sanitizer tests (log: $sanitized_log)" >&2
if wait "$sanitized_pid"; then
  grep -E "tests passed|Passed|Skipped|Not Run" "$sanitized_log" || true
  echo "run_tests: the sanitizer tests passed (log: $sanitized_log)"
else
  cat "$sanitized_log"
  echo "run_tests: the sanitizer tests FAILED" >&2
  status=1
fi
trap - EXIT
exit "$status"
