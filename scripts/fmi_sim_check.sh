#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The FMI 3.0 FMUs in a second FMI 3.0 importer: installs fmi-sim 0.7.0 (the
# Rust `fmi` crates' simulator) into build/tools/fmi-sim when it is missing,
# then runs python_checks/test_fmu_fmi_sim.py, which fails rather than skips.
# Building fmi-sim takes about 5 minutes on two cores, once; so it is not part
# of the test command. Needs the build (./run_tests.sh or scripts/build.sh)
# and cargo (rustup's, or Rust from https://rustup.rs; Debian's is too old
# for fmi-sim 0.7.0).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
log() { echo "fmi_sim_check: $*" >&2; }

root=build/tools/fmi-sim
if [ ! -x "$root/bin/fmi-sim" ]; then
  cargo=$(command -v cargo || true)
  [ -n "$cargo" ] || [ ! -x "$HOME/.cargo/bin/cargo" ] || cargo="$HOME/.cargo/bin/cargo"
  if [ -z "$cargo" ]; then
    log "ERROR: cargo not found; install Rust (https://rustup.rs: curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal), then run me again"
    exit 1
  fi
  log "building fmi-sim 0.7.0 into $root (about 5 minutes, once)"
  start=$SECONDS
  "$cargo" install fmi-sim --version 0.7.0 --locked --root "$root"
  log "fmi-sim built in $((SECONDS - start)) s"
fi
[ -f build/fmi3/PKM4PUU.fmu ] || { log "ERROR: build/fmi3/PKM4PUU.fmu missing: run scripts/build.sh first"; exit 1; }
PKM_FMI_SIM="$PWD/$root/bin/fmi-sim" PKM_REQUIRE_FMI_SIM=1 .venv/bin/python -m pytest -q -s python_checks/test_fmu_fmi_sim.py
