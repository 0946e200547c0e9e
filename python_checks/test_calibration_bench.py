# SPDX-License-Identifier: BSD-2-Clause
"""bench/calibration_bench.py runs (a smoke test on one second of data; the
timings themselves are the benchmark's to print, not a test's to judge; the
sizes it prints are checked against what they count)."""
import os
import re
import subprocess
import sys

from conftest import REPO
from pkm4puu import locate


def test_calibration_bench_prints_its_rows():
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    p = subprocess.run([sys.executable, str(REPO / "bench" / "calibration_bench.py"), "--seconds", "1",
                        "--repeat", "1"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    for row in ("pkm_regressor_joints over the samples (baseline)", "identify, median of later calls"):
        assert row in p.stdout, p.stdout
    # Its figures: 1 s at 1 kHz is 1001 samples; the regressor's 14 parameters
    # (the spec's bodies: m_slider, m_rod, I_rod[1..3], m_platform,
    # Izz_platform; the payload's mass, first moments and Izz; rotor_inertia,
    # friction_viscous, friction_coulomb) less the 2 that the payload, rigid
    # on the platform, adds to the platform's: 12 base parameters; stacked,
    # 1001 samples x 4 legs x 14 x 8 bytes = 0.45 MB (printed to 0.1 MB).
    head = re.search(r"identify: (\d+) samples .*?, (\d+) base parameters", p.stdout)
    assert head and (int(head.group(1)), int(head.group(2))) == (1001, 14 - 2), p.stdout
    stacked = re.search(r"memory: the stacked regressor \(baseline\)\s+([0-9.]+) MB", p.stdout)
    assert stacked and abs(float(stacked.group(1)) - 1001 * 4 * 14 * 8 / 1e6) <= 0.05, p.stdout
