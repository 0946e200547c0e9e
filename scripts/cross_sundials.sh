#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# A static SUNDIALS CVODE for a cross target, built from Debian's source
# package (`apt-get source sundials`: 6.4.1 on Debian 12, the version the
# native build links through libsundials-dev) with the project's toolchain
# file; nothing of SUNDIALS is kept in the repository.
#
#   scripts/cross_sundials.sh <win64|aarch64> PREFIX
#
# Installs into PREFIX (include/, lib/libsundials_*.a and SUNDIALS' CMake
# package lib/cmake/sundials/SUNDIALSConfig.cmake, through which the cross
# build finds SUNDIALS::cvode_static: the toolchain files put PREFIX on
# CMAKE_FIND_ROOT_PATH, cmake/Sundials.cmake). The cache key (this
# script and the toolchain files) is written to PREFIX/.pkm-key; when it
# matches, nothing is done, so a rerun costs nothing. The source is fetched
# once into PREFIX/../src. Needs a deb-src entry (scripts/setup.sh adds one).
#
# Why not Debian's arm64 libsundials-dev through multiarch for aarch64: it
# depends on the arm64 MPI, PETSc, hypre and gfortran development packages
# (hundreds of MB; gfortran:arm64 cannot sit beside the native one), while
# this build of CVODE alone takes ~20 s and is the same path as Windows.
set -euo pipefail
log() { echo "cross_sundials: $*" >&2; }
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
toolchains="$repo/cmake/toolchains"

target=${1:-}
prefix=${2:-}
case "$target" in
  win64) toolchain="$toolchains/mingw-w64-x86_64.cmake" ;;
  aarch64) toolchain="$toolchains/aarch64-linux-gnu.cmake" ;;
  *) echo "usage: $0 <win64|aarch64> PREFIX" >&2; exit 2 ;;
esac
[ -n "$prefix" ] || { echo "usage: $0 <win64|aarch64> PREFIX" >&2; exit 2; }
mkdir -p "$prefix"
prefix=$(cd "$prefix" && pwd)
work=$(dirname "$prefix")

key=$(cat "${BASH_SOURCE[0]}" "$toolchain" "$toolchains/cross_common.cmake" | sha256sum | cut -c1-16)
# What the build uses: the package and the static CVODE it names (which
# holds the serial vector, the dense solvers and the nonlinear solvers too).
complete() {
  [ "$(cat "$prefix/.pkm-key" 2>/dev/null)" = "$key" ] && [ -f "$prefix/include/cvode/cvode.h" ] &&
    [ -f "$prefix/lib/cmake/sundials/SUNDIALSConfig.cmake" ] && [ -f "$prefix/lib/libsundials_cvode.a" ]
}
if complete; then
  log "$target: static CVODE cached in $prefix"
  exit 0
fi

# 1. The source, once (shared by the targets). The build runs both targets'
#    scripts at once (ninja -j2): a lock makes the second wait for the first
#    one's download instead of finding a half-unpacked tree.
src_parent="$work/src"
mkdir -p "$src_parent"
exec 9>"$work/.source.lock"
flock 9
src=$(find "$src_parent" -mindepth 1 -maxdepth 1 -type d -name 'sundials-*' | head -n1)
if [ -z "$src" ] || [ ! -f "$src/CMakeLists.txt" ]; then
  log "apt-get source sundials (into $src_parent)"
  (cd "$src_parent" && apt-get source -q sundials >/dev/null) \
    || { log "ERROR: apt-get source sundials failed: no deb-src entry? (scripts/setup.sh adds one)"; exit 1; }
  src=$(find "$src_parent" -mindepth 1 -maxdepth 1 -type d -name 'sundials-*' | head -n1)
  [ -n "$src" ] && [ -f "$src/CMakeLists.txt" ] || { log "ERROR: no SUNDIALS source after apt-get source"; exit 1; }
fi
flock -u 9

# 2. CVODE alone, static and position-independent (it goes into the FMU's
#    shared library). mingw: ~32 -Woverflow warnings in sundials_hashmap.h
#    (a 64-bit constant in a 32-bit long, in the logger's hash table), kept
#    in build.log: third-party code, not this project's.
bdir="$work/build-$target"
rm -rf "$bdir" "$prefix"
cmake -S "$src" -B "$bdir" -G Ninja \
  -DCMAKE_TOOLCHAIN_FILE="$toolchain" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib \
  -DCMAKE_POSITION_INDEPENDENT_CODE=ON -DBUILD_STATIC_LIBS=ON -DBUILD_SHARED_LIBS=OFF \
  -DBUILD_CVODE=ON -DBUILD_ARKODE=OFF -DBUILD_CVODES=OFF -DBUILD_IDA=OFF -DBUILD_IDAS=OFF -DBUILD_KINSOL=OFF \
  -DBUILD_FORTRAN_MODULE_INTERFACE=OFF -DENABLE_MPI=OFF -DENABLE_OPENMP=OFF -DENABLE_PTHREAD=OFF \
  -DSUNDIALS_INDEX_SIZE=64 -DSUNDIALS_PRECISION=double \
  -DEXAMPLES_ENABLE_C=OFF -DEXAMPLES_ENABLE_CXX=OFF -DEXAMPLES_INSTALL=OFF -DBUILD_BENCHMARKS=OFF \
  >"$work/configure-$target.log" 2>&1 \
  || { tail -n 40 "$work/configure-$target.log" >&2; log "ERROR: configure failed"; exit 1; }
cmake --build "$bdir" -j"${PKM_CROSS_JOBS:-2}" >"$work/build-$target.log" 2>&1 \
  || { tail -n 40 "$work/build-$target.log" >&2; log "ERROR: build failed ($work/build-$target.log)"; exit 1; }
cmake --install "$bdir" >"$work/install-$target.log" 2>&1 \
  || { tail -n 20 "$work/install-$target.log" >&2; log "ERROR: install failed"; exit 1; }
rm -rf "$bdir"
echo "$key" >"$prefix/.pkm-key"
complete || { log "ERROR: install incomplete in $prefix (expected SUNDIALSConfig.cmake and libsundials_cvode.a)"; exit 1; }
log "$target: static CVODE installed in $prefix"
