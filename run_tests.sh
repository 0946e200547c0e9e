#!/usr/bin/env bash
# The test command: builds everything, runs the C++ tests (ctest), then the
# Python checks (pytest) when python_checks/ holds any test_*.py file.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh
# --no-tests=error: a build that registered no test must fail, not pass silently.
ctest --test-dir build --output-on-failure -j2 --no-tests=error
# Only call pytest when there are tests, so its exit code 5 (no tests) cannot occur.
if compgen -G "python_checks/test_*.py" >/dev/null; then
  .venv/bin/python -m pytest -q python_checks
else
  echo "run_tests: no python_checks/test_*.py, pytest skipped" >&2
fi
