#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The main job: the paper's auto-test (section 5.1) with the C++ core
# (pkm_autotest) and through the two FMUs, the figures, and the comparison
# test (section 5.2) through the plant FMU; then the verdict, one line per
# check (measured value, bound, PASS/FAIL), and exit status 1 when any
# check fails or a stage fails.
#
# It installs only what it needs (scripts/setup.sh --for-main-job: no test
# toolchain) and builds only its targets: pkm_autotest and the four FMU
# archives (pkm_fmus), in a new build/ configured without the tests,
# benchmarks and other platforms and without link-time optimisation (its
# serial links cost more of a cold build than they save in these runs; the
# checks' bounds hold either way), or in the build/ configured already (by
# ./run_tests.sh, say), as it is. One line per stage with the elapsed time;
# each stage's output goes to its log in results/logs/, whose end is shown
# when the stage fails. Results (CSV, PNG, the stages' checks) in results/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
out=results
logs=$out/logs
mkdir -p "$logs"
# The checks of this run only: a stage that stops early leaves its file
# missing, which the verdict counts as a failure.
checks=("$out/autotest_checks.csv" "$out/fmu_autotest_checks.csv" "$out/comparison_checks.csv")
rm -f "${checks[@]}"
start=$SECONDS
failed=0
echo "main job: logs in $logs/"

# stage LOG WHAT COMMAND...: runs COMMAND with its output in $logs/LOG, on
# one line: the time since the start, WHAT, then ok or FAILED with the
# stage's time; on failure the log's end, and failed=1. Returns COMMAND's status.
stage() {
  local log=$logs/$1 what=$2 t0=$SECONDS status=0
  shift 2
  printf '[%4d s] %-64s' "$((t0 - start))" "$what"
  "$@" >"$log" 2>&1 || status=$?
  if [ "$status" -eq 0 ]; then
    printf ' ok (%d s)\n' "$((SECONDS - t0))"
  else
    printf ' FAILED, exit status %d (%d s)\n' "$status" "$((SECONDS - t0))"
    echo "---- the end of $log ----"
    tail -n 40 "$log"
    echo "----"
    failed=1
  fi
  return "$status"
}
# Setting up and building: a failure stops the job.
stage setup.log "setup: Debian packages, .venv (fmpy, numpy, matplotlib)" ./scripts/setup.sh --for-main-job || exit 1
if [ -f build/CMakeCache.txt ] && grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' build/CMakeCache.txt; then
  printf '[%4d s] %-64s reused\n' "$((SECONDS - start))" "configure build/ (configured before)"
else
  stage configure.log "configure build/ (no tests, benchmarks, other platforms or LTO)" \
    env PKM_SETUP=none ./scripts/build.sh --configure-only \
      -DPKM_BUILD_TESTS=OFF -DPKM_BUILD_BENCHMARKS=OFF -DPKM_PLATFORMS=OFF -DPKM_LTO=OFF || exit 1
fi
stage build.log "build pkm_autotest and the FMUs (pkm_fmus)" \
  cmake --build build -j2 --target pkm_autotest pkm_fmus || exit 1
# The runs: each writes its checks; one that fails (a check or the run)
# does not stop the others.
py=.venv/bin/python
stage cpp_autotest.log "C++ auto-test (pkm_autotest: RK4, CVODE)" build/bin/pkm_autotest --out "$out" || true
stage plot_autotest.log "figures of the C++ auto-test" "$py" -m pkm4puu plot-autotest "$out" || true
stage fmu_autotest.log "auto-test through the FMUs" "$py" -m pkm4puu autotest --build build --out "$out" || true
stage comparison.log "comparison test through the plant FMU" \
  "$py" -m pkm4puu comparison --build build --out "$out" || true
echo "[$(printf '%4d' "$((SECONDS - start))") s] results in $out/"
"$py" -m pkm4puu verdict "${checks[@]}" || failed=1
exit "$failed"
