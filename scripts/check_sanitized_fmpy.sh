#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The Python fmpy checks of the FMUs (python_checks/test_fmu_*.py: the
# auto-test chain, FMU states, the interface, the flavours, the machine, the
# derivatives, Model Exchange) against FMU binaries built with clang's
# AddressSanitizer and UndefinedBehaviorSanitizer: the archives of the fuzz
# tree (fuzz/run_fuzz.sh --build-only), loaded into an uninstrumented Python
# with the sanitizer runtime preloaded. Any finding aborts the process, so
# the pytest run fails.
#   scripts/check_sanitized_fmpy.sh DIR     (DIR: the fuzz tree, e.g. build/fuzz-build)
# Left out: the files' result writers (they write into results/) and the
# Model Exchange convergence runs at rtol 1e-12 (about 20 s uninstrumented);
# memory leaks are not checked here (Python's own allocations would be
# reported; valgrind's ctest run checks the FMUs for leaks).
# Exit status: pytest's; 77 (skipped) when clang's runtime is missing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
tree="${1:?usage: scripts/check_sanitized_fmpy.sh FUZZ_BUILD_DIR}"
source scripts/sanitizer_env.sh check_sanitized_fmpy
for f in PKM4PUU.fmu PKM4PUU_Inverse.fmu fmi3/PKM4PUU.fmu fmi3/PKM4PUU_Inverse.fmu; do
  [ -f "$tree/$f" ] || { echo "check_sanitized_fmpy: $tree/$f missing (fuzz/run_fuzz.sh --build-only builds it)" >&2; exit 1; }
done
# The instrumented binaries must not run without the runtime: a check that
# the archives under test really are the sanitized ones.
if .venv/bin/python -c "import ctypes, zipfile, tempfile, sys, os
d = tempfile.mkdtemp(); zipfile.ZipFile('$tree/PKM4PUU.fmu').extractall(d)
ctypes.CDLL(os.path.join(d, 'binaries', 'linux64', 'PKM4PUU.so'))" 2>/dev/null; then
  echo "check_sanitized_fmpy: $tree/PKM4PUU.fmu loads without the sanitizer runtime: not an instrumented build" >&2
  exit 1
fi
export LD_PRELOAD="$sanitizer_runtime"
export PKM_BUILD_DIR="$tree"
# Its results for the test command's summary of skipped tests (run_tests.sh).
junit=()
[ -z "${PKM_TEST_RESULTS:-}" ] || junit=(--junitxml="$PKM_TEST_RESULTS/pytest_sanitized.xml")
exec .venv/bin/python -m pytest -q -p no:cacheprovider "${junit[@]}" \
  python_checks/test_fmu_autotest.py python_checks/test_fmu_comparison.py python_checks/test_fmu_derivatives.py \
  python_checks/test_fmu_flavours.py python_checks/test_fmu_instances.py python_checks/test_fmu_interface.py \
  python_checks/test_fmu_machine.py python_checks/test_fmu_model_exchange.py python_checks/test_fmu_state.py \
  -k "not write_results and not converges"
