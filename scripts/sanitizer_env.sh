# SPDX-License-Identifier: BSD-2-Clause
# Sourced by the scripts that load the ASan + UBSan FMU binaries into an
# uninstrumented process (check_sanitized_fmpy.sh, check_sanitized_fmi_tests.sh):
# finds clang's AddressSanitizer runtime for LD_PRELOAD (exits 77, skipped,
# when it is missing) and sets the options under which any finding aborts.
#   source scripts/sanitizer_env.sh NAME     (NAME: the calling script, for messages)
sanitizer_runtime="$(clang -print-file-name=libclang_rt.asan-x86_64.so 2>/dev/null || true)"
if [ ! -f "$sanitizer_runtime" ]; then
  echo "$1: SKIPPED: clang's AddressSanitizer runtime not found (Debian: clang libclang-rt-14-dev)" >&2
  exit 77
fi
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
