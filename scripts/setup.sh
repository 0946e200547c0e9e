#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# Installs what building and testing need, and only what is missing:
# Debian packages (apt-get) and the Python virtualenv .venv with
# python_checks/requirements.txt, and this project's package python/pkm4puu.
# Idempotent and non-interactive (CI-safe).
#   scripts/setup.sh                everything
#   scripts/setup.sh --for-build    what configuring and building need: the
#                                   Debian packages (doxygen for the docs
#                                   among them) and, in .venv, fmpy (its FMI
#                                   headers) and docs/requirements.txt (the
#                                   ctest docs_build); ./run_tests.sh installs
#                                   the rest while it builds
#   scripts/setup.sh --for-main-job what ./run_autotest.sh needs: the
#                                   compiler, CMake, Ninja, Eigen, SUNDIALS and
#                                   Python, and in .venv fmpy, numpy,
#                                   matplotlib (and scikit-build-core) and
#                                   pkm4puu; a
#                                   later full run still installs the rest
#                                   (its stamp file is not written here)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
log() { echo "setup: $*" >&2; }
mode=all
case "${1:-}" in
  --for-build) mode=build ;;
  --for-main-job) mode=main-job ;;
  "") ;;
  *) log "unknown argument $1"; exit 2 ;;
esac

# 1. Debian packages.
packages=(build-essential cmake ninja-build libeigen3-dev libsundials-dev python3 python3-venv)
if [ "$mode" != main-job ]; then
  packages+=(libgtest-dev python3-pip
             doxygen  # the documentation site's C API page (docs/build_docs.py)
             clang libclang-rt-14-dev valgrind  # hardening: libFuzzer + sanitizers (fuzz/), memcheck
             # every platform (cmake/Platforms.cmake): Windows x64 built with mingw-w64 and run
             # under wine, Linux aarch64 built with gcc and run under qemu-user; dpkg-dev
             # unpacks `apt-get source sundials` (scripts/cross_sundials.sh)
             g++-mingw-w64-x86-64-posix gcc-mingw-w64-x86-64-posix wine wine64
             g++-aarch64-linux-gnu gcc-aarch64-linux-gnu qemu-user dpkg-dev)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
sudo=()
if [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null 2>&1; then
  sudo=(sudo -n)
fi
export DEBIAN_FRONTEND=noninteractive
# The source packages of the mirror apt already uses (deb-src entries made
# from its deb entries), for `apt-get source sundials`; added only when apt
# has no deb-src entry at all.
need_update=0
if [ "$mode" != main-job ]; then  # the cross builds' SUNDIALS only
  if ! ./scripts/deb_src.sh --check; then
    log "adding deb-src entries for apt's own mirrors"
    ./scripts/deb_src.sh | "${sudo[@]}" tee /etc/apt/sources.list.d/pkm-deb-src.sources >/dev/null
    need_update=1
  fi
  if [ -z "$(apt-cache showsrc sundials 2>/dev/null)" ]; then
    need_update=1
  fi
fi
if [ "${#missing[@]}" -eq 0 ] && [ "$need_update" -eq 0 ]; then
  log "all Debian packages present, nothing missing"
else
  if [ "$(id -u)" -ne 0 ] && [ "${#sudo[@]}" -eq 0 ]; then
    log "ERROR: not root and no sudo; install these packages by hand: ${missing[*]}"
    exit 1
  fi
  "${sudo[@]}" apt-get update -q
  if [ "${#missing[@]}" -gt 0 ]; then
    log "installing missing Debian packages: ${missing[*]}"
    "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
fi

# 2. Python virtualenv, on Debian's python3 (the one installed above) when present.
py=/usr/bin/python3
[ -x "$py" ] || py=python3
if [ ! -x .venv/bin/python ]; then
  log "creating .venv with $py"
  "$py" -m venv .venv
fi
req=python_checks/requirements.txt
stamp=.venv/.requirements.stamp
# install_pinned NAME...: installs each NAME at its pin in $req unless that
# version is installed already (the pins are read from $req, never copied).
install_pinned() {
  local pins=() name pin
  for name in "$@"; do
    pin="$(grep -E "^${name}(\[[^]]*\])?==" "$req")" || { log "ERROR: no pin for $name in $req"; exit 1; }
    pins+=("$pin")
  done
  # The pins whose version is not the installed one (a missing package included).
  mapfile -t pins < <(.venv/bin/python - "${pins[@]}" <<'PY'
import sys
from importlib.metadata import PackageNotFoundError, version
for pin in sys.argv[1:]:
    name, wanted = pin.split("==")
    try:
        ok = version(name.split("[")[0]) == wanted
    except PackageNotFoundError:
        ok = False
    if not ok:
        print(pin)
PY
  )
  if [ "${#pins[@]}" -gt 0 ]; then
    log "installing ${pins[*]} (the rest of $req comes with scripts/setup.sh)"
    # --no-compile: Python compiles the modules it imports when it first does,
    # not every module of numpy and matplotlib now (a third of the install).
    .venv/bin/pip install --disable-pip-version-check -q --no-compile "${pins[@]}"
  fi
}
# install_docs: docs/requirements.txt (Sphinx and its extensions, ctest
# docs_build) unless every pin of it is installed already.
install_docs() {
  local docs_req=docs/requirements.txt
  if ! .venv/bin/python - "$docs_req" <<'PY'
import sys
from importlib.metadata import PackageNotFoundError, version
ok = True
for line in open(sys.argv[1]):
    line = line.split("#")[0].strip()
    if not line:
        continue
    name, wanted = line.split("==")
    try:
        ok &= version(name) == wanted
    except PackageNotFoundError:
        ok = False
sys.exit(0 if ok else 1)
PY
  then
    log "installing the documentation's requirements from $docs_req"
    .venv/bin/pip install --disable-pip-version-check -q --no-compile -r "$docs_req"
  fi
}
case "$mode" in
  build)
    install_pinned fmpy
    install_docs
    log "done (for the build)"
    exit 0 ;;
  main-job) install_pinned fmpy numpy matplotlib scikit-build-core ;;  # scikit-build-core: pkm4puu's install below
  *)
    if [ ! -f "$stamp" ] || [ "$req" -nt "$stamp" ]; then
      log "installing Python requirements from $req"
      .venv/bin/pip install --disable-pip-version-check -q -r "$req"
      touch "$stamp"
    else
      log "Python requirements up to date"
    fi
    install_docs ;;
esac
# 3. This project's Python package (python/pkm4puu), editable: the checks,
# examples and benchmarks import it, and it follows the working tree.
# pyproject.toml's editable override builds nothing (PKM_PYTHON_ONLY): the
# package finds libpkm and the FMUs in build/. Installed again when
# pyproject.toml changed since (its metadata: dependencies, extras, command).
pkg_stamp=.venv/.pkm4puu.stamp
if ! .venv/bin/python -c "import pkm4puu, sys; sys.exit(pkm4puu.__file__ != '$PWD/python/pkm4puu/__init__.py')" 2>/dev/null \
   || [ ! -f "$pkg_stamp" ] || [ pyproject.toml -nt "$pkg_stamp" ]; then
  log "installing the pkm4puu package (editable, nothing built)"
  .venv/bin/pip install --disable-pip-version-check -q --no-deps --no-build-isolation -e .
  touch "$pkg_stamp"
else
  log "pkm4puu package installed"
fi
log "done ($mode)"
