#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# Builds the libFuzzer harness fuzz/fmi_fuzzer.cpp with clang under
# AddressSanitizer + UndefinedBehaviorSanitizer (a separate build directory,
# -DPKM_FUZZ=ON; the default gcc build is untouched) and runs it.
#
#   fuzz/run_fuzz.sh [--build-dir DIR] [--seconds N | --runs N] [--jobs N] [-- libFuzzer options...]
#   fuzz/run_fuzz.sh [--build-dir DIR] --build-only
#   fuzz/run_fuzz.sh [--build-dir DIR] --replay [--jobs N]
#   fuzz/run_fuzz.sh [--build-dir DIR] --coverage-report
#
# Defaults: --build-dir build-fuzz, --seconds 60, one job. The corpus grows in
# DIR/corpus (seeded from fuzz/seed_corpus.tar.gz); findings (crash-*, leak-*,
# timeout-*, oom-*) are written to DIR/findings/.
# --build-only builds the harness and, from the same instrumented objects, the
# FMU archives (DIR/<id>.fmu, DIR/fmi3/<id>.fmu) that
# scripts/check_sanitized_fmpy.sh drives through fmpy; no fuzzing.
# --replay runs every input of the seed corpus once (no fuzzing), in N
# processes of about equal shares: the regression check of the test command
# (ctest hardening_fuzz_seeds). A fuzzing run first replays its whole corpus
# too, one input at a time: about 90 s here for the 2,051 seeds, so a
# 45-second run would never get past them.
# --coverage-report builds a source-coverage variant in DIR-cov, replays the
# seed corpus and DIR/corpus through it and prints llvm-cov's region, line
# and branch coverage of src/ (no fuzzing).
# Exit status: 0 no finding, 1 a finding (or a build failure), 77 when clang
# or its libFuzzer runtime is missing (ctest reports the test as skipped;
# scripts/setup.sh installs them).
# At the end it prints the figures: inputs, FMI calls, coverage.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# The seed corpus (fuzz/seed_corpus.tar.gz), unpacked into a fresh DIR.
unpack_seeds() {
  rm -rf "$1" && mkdir -p "$1"
  tar -C "$1" -xzf "$root/fuzz/seed_corpus.tar.gz"
}
build="$root/build-fuzz"
seconds=60
runs=""
jobs=1
coverage=0
build_only=0
replay=0
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --coverage-report) coverage=1; shift ;;
    --build-only) build_only=1; shift ;;
    --replay) replay=1; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "run_fuzz: unknown argument $1" >&2; exit 2 ;;
  esac
done

cxx="$(command -v clang++ || true)"
cc="$(command -v clang || true)"
if [ -z "$cxx" ] || [ -z "$cc" ]; then
  echo "run_fuzz: SKIPPED: clang/clang++ not found (Debian: clang libclang-rt-14-dev; ./scripts/setup.sh installs them)" >&2
  exit 77
fi
if ! echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' |
     "$cxx" -x c++ -fsanitize=fuzzer,address,undefined -o /dev/null - 2>/dev/null; then
  echo "run_fuzz: SKIPPED: $cxx cannot link -fsanitize=fuzzer,address,undefined (Debian: libclang-rt-14-dev)" >&2
  exit 77
fi

mkdir -p "$build"

if [ "$coverage" -eq 1 ]; then
  cov="$build-cov"
  mkdir -p "$cov"
  profdata="$(command -v llvm-profdata || command -v llvm-profdata-14 || true)"
  llvmcov="$(command -v llvm-cov || command -v llvm-cov-14 || true)"
  if [ -z "$profdata" ] || [ -z "$llvmcov" ]; then echo "run_fuzz: llvm-profdata/llvm-cov not found" >&2; exit 77; fi
  if [ ! -f "$cov/CMakeCache.txt" ]; then
    CC="$cc" CXX="$cxx" cmake -S "$root" -B "$cov" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPKM_FUZZ=ON \
      -DPKM_BUILD_TESTS=OFF -DPKM_BUILD_BENCHMARKS=OFF -DPKM_LTO=OFF -DPKM_PLATFORMS=OFF \
      -DCMAKE_CXX_FLAGS="-fprofile-instr-generate -fcoverage-mapping" \
      -DCMAKE_EXE_LINKER_FLAGS="-fprofile-instr-generate" >"$cov/configure.log" 2>&1 || {
      cat "$cov/configure.log" >&2; exit 1; }
  fi
  cmake --build "$cov" --target pkm_fmi_fuzzer -j"$(nproc)" >"$cov/build.log" 2>&1 || { tail -50 "$cov/build.log" >&2; exit 1; }
  rm -f "$cov"/*.profraw
  dirs=("$cov/seeds")
  unpack_seeds "$cov/seeds"
  [ -d "$build/corpus" ] && dirs+=("$build/corpus")
  LLVM_PROFILE_FILE="$cov/replay.profraw" "$cov/fuzz/pkm_fmi_fuzzer" -runs=0 "${dirs[@]}" >"$cov/replay.log" 2>&1 || {
    tail -30 "$cov/replay.log" >&2; exit 1; }
  "$profdata" merge -sparse "$cov/replay.profraw" -o "$cov/replay.profdata"
  "$llvmcov" report "$cov/fuzz/pkm_fmi_fuzzer" -instr-profile="$cov/replay.profdata" \
    "$root"/src/fmi/*.cpp "$root"/src/models/*/*.cpp "$root"/src/pkm4puu/*/*.cpp
  exit 0
fi
if [ ! -f "$build/CMakeCache.txt" ]; then
  # Line tables only (enough for symbolised stack traces): the largest file
  # compiles in 50 s instead of RelWithDebInfo's 59 s. -O1 saved a little
  # more to build but tripled the time to replay the seed corpus.
  CC="$cc" CXX="$cxx" cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPKM_FUZZ=ON \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DPKM_BUILD_TESTS=OFF -DPKM_BUILD_BENCHMARKS=OFF -DPKM_LTO=OFF -DPKM_PLATFORMS=OFF \
    >"$build/configure.log" 2>&1 || { cat "$build/configure.log" >&2; exit 1; }
fi
cmake --build "$build" --target pkm_fmi_fuzzer pkm_fmus -j"$(nproc)" >"$build/build.log" 2>&1 || {
  tail -50 "$build/build.log" >&2; exit 1; }
if [ "$build_only" -eq 1 ]; then
  echo "run_fuzz: built $build/fuzz/pkm_fmi_fuzzer and the instrumented FMUs in $build" >&2
  exit 0
fi

mkdir -p "$build/corpus" "$build/findings"
if [ "$replay" -eq 1 ]; then
  seeds_dir="$build/seeds"
  unpack_seeds "$seeds_dir"
  mapfile -t inputs < <(find "$seeds_dir" -type f | sort)
  rm -f "$build"/replay-*.log
  echo "run_fuzz: replaying ${#inputs[@]} seed inputs in $jobs process(es) (logs: $build/replay-*.log)" >&2
  pids=()
  for ((j = 0; j < jobs; j++)); do
    share=()
    for ((i = j; i < ${#inputs[@]}; i += jobs)); do share+=("${inputs[i]}"); done
    "$build/fuzz/pkm_fmi_fuzzer" -timeout=30 -rss_limit_mb=2048 -artifact_prefix="$build/findings/" \
      "${share[@]}" >"$build/replay-$j.log" 2>&1 &
    pids+=($!)
  done
  failed=0
  for ((j = 0; j < jobs; j++)); do
    if ! wait "${pids[j]}"; then
      failed=1
      echo "run_fuzz: FINDING while replaying share $j; the end of its log:" >&2
      tail -60 "$build/replay-$j.log" >&2
    fi
  done
  ran=$(cat "$build"/replay-*.log | grep -c '^Executed ' || true)
  echo "run_fuzz: $ran of ${#inputs[@]} seed inputs ran$([ "$failed" -eq 0 ] && echo ", no finding")" >&2
  if [ "$failed" -ne 0 ] || [ "$ran" -ne "${#inputs[@]}" ]; then exit 1; fi
  exit 0
fi
# Seeds: fuzz/seed_corpus.tar.gz, the corpus of a 30-minute run merged by
# libFuzzer (-merge=1), so that a short run starts from deep coverage.
[ -z "$(ls -A "$build/corpus")" ] && unpack_seeds "$build/corpus"
seeds=()
limit=(-max_total_time="$seconds")
[ -n "$runs" ] && limit=(-runs="$runs")
log="$build/fuzz.log"
echo "run_fuzz: $build/fuzz/pkm_fmi_fuzzer ${limit[*]}, $jobs job(s), corpus $build/corpus (log: $log)" >&2
set +e
if [ "$jobs" -gt 1 ]; then
  # Parallel jobs: -fork keeps one corpus and stops at the first finding.
  "$build/fuzz/pkm_fmi_fuzzer" "$build/corpus" "${seeds[@]}" "${limit[@]}" -fork="$jobs" -ignore_crashes=0 \
    -timeout=30 -rss_limit_mb=2048 -max_len=2048 -print_final_stats=1 -artifact_prefix="$build/findings/" \
    "${extra[@]}" >"$log" 2>&1
else
  "$build/fuzz/pkm_fmi_fuzzer" "$build/corpus" "${seeds[@]}" "${limit[@]}" \
    -timeout=30 -rss_limit_mb=2048 -max_len=2048 -print_final_stats=1 -artifact_prefix="$build/findings/" \
    "${extra[@]}" >"$log" 2>&1
fi
status=$?
set -e
# Figures: libFuzzer's last status line, its final stats, the harness's call count.
grep -E "^#[0-9]+.*(DONE|pulse|REDUCE|NEW)" "$log" | tail -1 >&2 || true
grep -E "^stat::|PKM_FUZZ_CALLS" "$log" >&2 || true
# Crashes, leaks, timeouts (> 30 s) and out-of-memory are findings; libFuzzer's
# slow-unit-* files (> 10 s) are not (CVODE giving up after its step limit is slow).
findings=$(find "$build/findings" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
if [ "$status" -ne 0 ] || [ "$findings" -ne 0 ]; then
  echo "run_fuzz: FINDING (exit $status, $findings file(s) in $build/findings); the end of the log:" >&2
  tail -60 "$log" >&2
  exit 1
fi
echo "run_fuzz: no finding" >&2
