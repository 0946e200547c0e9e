#!/usr/bin/env bash
# The main job: builds everything, runs the paper's auto-test into results/,
# then plots the results.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh
build/fmu_src/pkm_autotest --out results
.venv/bin/python scripts/plot_autotest.py results
