#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The platform checks left out of ./run_tests.sh for its time budget: the
# source-code FMU built with `fmpy compile` (the whole core, ~2 min of one
# core) must reproduce the binary FMU's auto-test and refuse solver = 0.
# Needs a build (./run_tests.sh or ./scripts/build.sh) first.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
PKM_COMPILE_SOURCE_FMU=1 .venv/bin/python -m pytest -q python_checks/test_fmu_platforms.py -k compiled
