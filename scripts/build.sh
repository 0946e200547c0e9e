#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# Installs what is missing (scripts/setup.sh), then configures and builds
# everything in build/ (Ninja, Release).
#   scripts/build.sh [--configure-only] [-D<cmake option>=<value>...]
# PKM_SETUP=for-build installs only what the build needs (setup.sh
# --for-build); PKM_SETUP=none installs nothing (./run_tests.sh).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
case "${PKM_SETUP:-all}" in
  all) ./scripts/setup.sh ;;
  for-build) ./scripts/setup.sh --for-build ;;
  none) ;;
  *) echo "build: PKM_SETUP=${PKM_SETUP} must be all, for-build or none" >&2; exit 2 ;;
esac
# A build/ configured earlier with another generator would make cmake fail: reset it.
if [ -f build/CMakeCache.txt ] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' build/CMakeCache.txt; then
  echo "build: build/ was not configured with Ninja, reconfiguring" >&2
  rm -rf build/CMakeCache.txt build/CMakeFiles
fi
configure_only=0
if [ "${1:-}" = "--configure-only" ]; then configure_only=1; shift; fi
# The FMU tests, the documentation's build and the benchmarks run Python
# with fmpy, Sphinx, ... from the project's .venv (CMake's find_package(Python3)
# would otherwise take the first python3 on the PATH).
python=()
if [ -x .venv/bin/python ]; then python=(-DPython3_EXECUTABLE="$PWD/.venv/bin/python"); fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${python[@]}" "$@"
if [ "$configure_only" -eq 1 ]; then exit 0; fi
cmake --build build -j2
