# SPDX-License-Identifier: BSD-2-Clause
"""bench/calibration_bench.py runs (a smoke test on one second of data; the
timings themselves are the benchmark's to print, not a test's to judge)."""
import os
import subprocess
import sys

from conftest import REPO
from pkm4puu import locate


def test_calibration_bench_prints_its_rows():
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    p = subprocess.run([sys.executable, str(REPO / "bench" / "calibration_bench.py"), "--seconds", "1",
                        "--repeat", "1"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "identify: 1001 samples" in p.stdout
    for row in ("pkm_regressor_joints over the samples (baseline)", "identify, median of later calls"):
        assert row in p.stdout, p.stdout
