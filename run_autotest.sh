#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The main job: builds everything, runs the paper's auto-test into results/,
# then plots the results; then runs the auto-test (section 5.1) and the
# comparison test (section 5.2) through the FMUs built in build/, which print
# their tables of max errors and write their CSV and PNG files to results/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"
./scripts/build.sh
build/bin/pkm_autotest --out results
.venv/bin/python -m pkm4puu plot-autotest results
.venv/bin/python -m pkm4puu autotest --build build --out results
.venv/bin/python -m pkm4puu comparison --build build --out results
