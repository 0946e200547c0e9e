#!/usr/bin/env bash
# The test command: builds everything, runs the C++ tests (ctest), then the
# Python checks (pytest) when python_checks/ holds any test_*.py file, with
# the short fuzz run beside them.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh
# --no-tests=error: a build that registered no test must fail, not pass silently.
# The short fuzz run (its own sanitizer build, then 45 s of fuzzing: about
# 3 minutes, mostly on one core) runs beside the Python checks instead of
# after everything else, which keeps the command within its time budget.
fuzz='^hardening_fuzz_short$'
ctest --test-dir build --output-on-failure -j2 --no-tests=error -E "$fuzz"
fuzz_log=build/hardening_fuzz_short.log
ctest --test-dir build --output-on-failure --no-tests=error -R "$fuzz" >"$fuzz_log" 2>&1 &
fuzz_pid=$!
status=0
# Only call pytest when there are tests, so its exit code 5 (no tests) cannot occur.
if compgen -G "python_checks/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q python_checks || status=$?
else
  echo "run_tests: no python_checks/test_*.py, pytest skipped" >&2
fi
if wait "$fuzz_pid"; then
  echo "run_tests: hardening_fuzz_short passed (log: $fuzz_log)"
else
  cat "$fuzz_log"
  echo "run_tests: hardening_fuzz_short FAILED" >&2
  status=1
fi
exit "$status"
