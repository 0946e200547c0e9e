# SPDX-License-Identifier: BSD-2-Clause
"""bench/library_bench.py runs and prints its rows (smoke tests: the timings
against their targets are the benchmark's to print, not a test's to judge;
the sizes it prints are checked against what they count)."""
import os
import re
import subprocess
import sys

from conftest import REPO
from pkm4puu import locate


def library_bench(*args):
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    p = subprocess.run([sys.executable, str(REPO / "bench" / "library_bench.py"), *args], capture_output=True,
                       text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_identify_prints_its_rows_and_sizes():
    out = library_bench("identify", "--seconds", "1", "--repeat", "1")
    for row in ("pkm_regressor_joints over the samples (baseline)", "identify, median of later calls"):
        assert row in out, out
    # Its figures: 1 s at 1 kHz is 1001 samples; the regressor's 14 parameters
    # (the spec's bodies: m_slider, m_rod, I_rod[1..3], m_platform,
    # Izz_platform; the payload's mass, first moments and Izz; rotor_inertia,
    # friction_viscous, friction_coulomb) less the 2 that the payload, rigid
    # on the platform, adds to the platform's: 12 base parameters; stacked,
    # 1001 samples x 4 legs x 14 x 8 bytes = 0.45 MB (printed to 0.1 MB).
    head = re.search(r"identify: (\d+) samples .*?, (\d+) base parameters", out)
    assert head and (int(head.group(1)), int(head.group(2))) == (1001, 14 - 2), out
    stacked = re.search(r"memory: the stacked regressor \(baseline\)\s+([0-9.]+) MB", out)
    assert stacked and abs(float(stacked.group(1)) - 1001 * 4 * 14 * 8 / 1e6) <= 0.05, out


def test_plan_prints_its_rows():
    out = library_bench("plan", "--repeat", "1", "--grids", "200", "400")
    for row in ("toppra's solve of both legs", "plan_cycle, all of it (baseline)", "x the cycle time; target <= 1 s",
                "grid convergence of the cycle time"):
        assert row in out, out


def test_a_wrong_argument_is_a_usage_error():
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    for args in (["plan", "--repeat", "0"], ["identify", "--seconds", "-1"], ["fly"]):
        p = subprocess.run([sys.executable, str(REPO / "bench" / "library_bench.py"), *args], capture_output=True,
                           text=True, env=env, timeout=60)
        assert p.returncode == 2 and "library_bench: error:" in p.stderr and not p.stdout, (args, p.stderr)
