# SPDX-License-Identifier: BSD-2-Clause
"""bench/pick_place_bench.py runs and prints its rows (a smoke test: the
planning time against its target is the benchmark's to print, not a test's
to judge)."""
import os
import subprocess
import sys

from conftest import REPO
from pkm4puu import locate


def test_pick_place_bench_prints_its_rows():
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    p = subprocess.run([sys.executable, str(REPO / "bench" / "pick_place_bench.py"), "--repeat", "1",
                        "--grids", "200", "400"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    for row in ("toppra's solve of both legs", "plan_cycle, all of it (baseline)", "x the cycle time; target <= 1 s",
                "grid convergence of the cycle time"):
        assert row in p.stdout, p.stdout
