#!/usr/bin/env bash
# The test command: builds everything, runs the C++ tests (ctest), then the
# Python checks (pytest) when python_checks/ holds any test_*.py file.
#
# The short fuzz run (ctest's hardening_fuzz_short: its own clang sanitizer
# build, then 45 s of fuzzing) is the longest chain, so it starts as soon as
# build/ is configured and runs beside everything else at a lower priority:
# it takes the cores the main build leaves idle, then runs beside the tests.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh --configure-only
fuzz='^hardening_fuzz_short$'
fuzz_log=build/hardening_fuzz_short.log
# In a process group of its own (setsid), so that a failure before the end
# stops the whole run (ctest, the script, the compilers) and leaves nothing behind.
setsid nice -n 10 ctest --test-dir build --output-on-failure --no-tests=error -R "$fuzz" >"$fuzz_log" 2>&1 &
fuzz_pid=$!
trap 'kill -- -"$fuzz_pid" 2>/dev/null || true' EXIT
./scripts/build.sh
# --no-tests=error: a build that registered no test must fail, not pass silently.
ctest --test-dir build --output-on-failure -j2 --no-tests=error -E "$fuzz"
status=0
# Only call pytest when there are tests, so its exit code 5 (no tests) cannot occur.
if compgen -G "python_checks/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q python_checks || status=$?
else
  echo "run_tests: no python_checks/test_*.py, pytest skipped" >&2
fi
echo "run_tests: waiting for the short fuzz run (log: $fuzz_log)" >&2
if wait "$fuzz_pid"; then
  echo "run_tests: hardening_fuzz_short passed (log: $fuzz_log)"
else
  cat "$fuzz_log"
  echo "run_tests: hardening_fuzz_short FAILED" >&2
  status=1
fi
trap - EXIT
exit "$status"
