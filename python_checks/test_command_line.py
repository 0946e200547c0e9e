# SPDX-License-Identifier: BSD-2-Clause
"""The command line `python -m pkm4puu COMMAND` refuses wrong input at once:
an unknown option or an --out that cannot be written ends with exit status
2 and a message naming it, before the command looks for the FMUs (a build
directory that does not exist would be exit status 1) or runs anything.
And the main job's verdict (`python -m pkm4puu verdict`, the checks files
its stages write) passes only when every check passed."""
import math
import os
import subprocess
import sys

import pytest

from pkm4puu import locate
from pkm4puu.validation.checks import check, write_checks
from pkm4puu.validation.cli import writable_dir

# The commands with --build and --out.
REPORTS = ["autotest", "comparison", "engines", "cycle"]


def run_cli(*args, cwd):
    """python -m pkm4puu ARGS in cwd, with a build directory that does not
    exist: a command that got past its arguments would fail with status 1."""
    env = {**os.environ, locate.BUILD_ENV: str(cwd / "no-build")}
    return subprocess.run([sys.executable, "-m", "pkm4puu", *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=120)


def refused(proc, *names):
    """proc ended with status 2, its message naming each of `names`, and
    nothing ran (no progress line, nothing on stdout)."""
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    for name in names:
        assert str(name) in proc.stderr, proc.stderr
    assert proc.stdout == "" and "running" not in proc.stderr, proc.stderr
    return True


@pytest.mark.parametrize("command", REPORTS)
def test_unknown_option_is_refused(tmp_path, command):
    assert refused(run_cli(command, "--out", str(tmp_path / "out"), "--bogus", cwd=tmp_path), "--bogus")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", REPORTS)
def test_out_under_a_file_is_refused(tmp_path, command):
    afile = tmp_path / "a_file"
    afile.write_text("")
    assert refused(run_cli(command, "--out", str(afile / "results"), cwd=tmp_path), "--out", afile / "results")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only directory")
@pytest.mark.parametrize("command", REPORTS)
def test_out_in_a_read_only_directory_is_refused(tmp_path, command):
    ro = tmp_path / "read_only"
    ro.mkdir(mode=0o555)
    try:
        assert refused(run_cli(command, "--out", str(ro / "results"), cwd=tmp_path), "--out", "not writable")
    finally:
        ro.chmod(0o755)


def test_out_that_can_be_created_is_accepted(tmp_path):
    """The check refuses what cannot be written, not what is missing yet
    (and creates nothing itself)."""
    assert writable_dir(str(tmp_path / "a" / "b")) == tmp_path / "a" / "b"
    assert not (tmp_path / "a").exists()
    with pytest.raises(Exception, match="no such directory"):
        writable_dir(str(tmp_path / "a"), must_exist=True)


def test_plot_autotest_refuses_a_results_dir_that_is_not_one(tmp_path):
    afile = tmp_path / "a_file"
    afile.write_text("")
    assert refused(run_cli("plot-autotest", str(afile), cwd=tmp_path), "RESULTS_DIR", afile)
    assert refused(run_cli("plot-autotest", str(tmp_path / "missing"), cwd=tmp_path), tmp_path / "missing")
    assert refused(run_cli("plot-autotest", str(tmp_path), "--bogus", cwd=tmp_path), "--bogus")


def test_unknown_top_level_option_is_refused(tmp_path):
    assert refused(run_cli("--bogus", cwd=tmp_path), "--bogus")


# --- the verdict ------------------------------------------------------------------------
def test_verdict_passes_when_every_check_passed(tmp_path):
    a = write_checks(tmp_path / "a_checks.csv", [check("stage A", "max error", 1e-12, 1e-10, "m")])
    b = write_checks(tmp_path / "b_checks.csv", [check("stage B", "max |delta rho1|", 2e-3, 1e-5, "m", ">")])
    proc = run_cli("verdict", str(a), str(b), cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "stage A: max error" in proc.stdout and "stage B: max |delta rho1|" in proc.stdout
    assert proc.stdout.count("PASS") == 3 and "FAIL" not in proc.stdout  # two lines and the verdict


@pytest.mark.parametrize("measured, relation, bound", [(2e-10, "<=", 1e-10), (math.nan, "<=", 1e-10),
                                                       (1e-6, ">", 1e-5), (math.inf, ">", 1e-5)])
def test_verdict_fails_a_check_beyond_its_bound(tmp_path, measured, relation, bound):
    good = write_checks(tmp_path / "good_checks.csv", [check("stage A", "max error", 1e-12, 1e-10, "m")])
    bad = write_checks(tmp_path / "bad_checks.csv", [check("stage B", "q", measured, bound, "m", relation)])
    proc = run_cli("verdict", str(good), str(bad), cwd=tmp_path)
    assert proc.returncode == 1, proc.stdout
    line = next(line for line in proc.stdout.splitlines() if "stage B: q" in line)
    assert line.endswith("FAIL") and proc.stdout.rstrip().endswith("verdict: FAIL")


def test_verdict_fails_a_missing_or_foreign_file(tmp_path):
    good = write_checks(tmp_path / "good_checks.csv", [check("stage A", "max error", 1e-12, 1e-10, "m")])
    foreign = tmp_path / "foreign.csv"
    foreign.write_text("a,b\n1,2\n")
    empty = write_checks(tmp_path / "empty_checks.csv", [])
    for other, why in ((tmp_path / "missing.csv", "missing"), (foreign, "unreadable"), (empty, "no check")):
        proc = run_cli("verdict", str(good), str(other), cwd=tmp_path)
        assert proc.returncode == 1 and f"{other}: " in proc.stdout and why in proc.stdout, proc.stdout
