#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# The source-code FMU's checks alone (./run_tests.sh runs them too, where
# CMake and a C++ compiler are): built with `fmpy compile` (the whole core,
# about 80 s of CPU), it must reproduce the binary FMU's auto-test and
# refuse solver = 0. Needs a build with the merged archives
# (./run_tests.sh, or scripts/build.sh -DPKM_PLATFORMS=ON) first.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
.venv/bin/python -m pytest -q -rs python_checks/test_fmu_platforms.py -k compiled
