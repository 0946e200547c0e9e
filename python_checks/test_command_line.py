# SPDX-License-Identifier: BSD-2-Clause
"""The command pkm4puu refuses wrong input at once: an unknown option, an
--out that cannot be written, a number that is not one of the kind asked
for (0, NaN, negative), an unknown model parameter, a log that is no file
end with exit status 2 and one line naming the value, before the command
looks for the FMUs (a build directory that does not exist would be exit
status 1) or runs anything; a drive log with a bad row ends with status 1
naming the row. And the main job's verdict (`pkm4puu verdict`, the checks
files its stages write) passes only when every check passed."""
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from pkm4puu import cli, locate
from pkm4puu.cli.checks import check, write_checks
from pkm4puu.program import writable_dir

# The commands with --build and --out.
REPORTS = ["autotest", "comparison", "engines", "cycle"]


# Runs a command as a user who obeys file permissions, root included.
WITHOUT_PRIVILEGES = Path(__file__).resolve().parents[1] / "tests" / "without_privileges.sh"


def run_cli(*args, cwd, unprivileged=False):
    """python -m pkm4puu ARGS in cwd, with a build directory that does not
    exist: a command that got past its arguments would fail with status 1.
    `unprivileged`: through WITHOUT_PRIVILEGES (root without its capabilities)."""
    env = {**os.environ, locate.BUILD_ENV: str(cwd / "no-build")}
    runner = [str(WITHOUT_PRIVILEGES)] if unprivileged else []
    return subprocess.run([*runner, sys.executable, "-m", "pkm4puu", *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=120)


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


@pytest.mark.parametrize("command", REPORTS)
def test_out_in_a_read_only_directory_is_refused(tmp_path, command):
    """As an ordinary user and as root (who, without its capabilities, meets
    the read-only directory as everyone else does)."""
    ro = tmp_path / "read_only"
    ro.mkdir(mode=0o555)
    try:
        proc = run_cli(command, "--out", str(ro / "results"), cwd=tmp_path, unprivileged=True)
        assert refused(proc, "--out", f"{ro / 'results'}: {ro} is not writable")
    finally:
        ro.chmod(0o755)


@pytest.mark.parametrize("command", REPORTS)
def test_out_where_the_file_system_refuses_even_root_is_refused(tmp_path, command):
    """/proc takes no new files from anyone, root included, though root passes
    every permission check: the refusal comes before any run all the same."""
    assert refused(run_cli(command, "--out", "/proc/pkm4puu_results", cwd=tmp_path), "--out",
                   "/proc/pkm4puu_results: /proc is not writable")


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


# --- bad values, one line each (in-process: the usage is `pkm4puu COMMAND`) ---------------
def command(capsys, *args):
    """(exit status, stdout, stderr) of `pkm4puu ARGS`, run in this process."""
    try:
        status = cli.main([str(a) for a in args])
    except SystemExit as e:
        status = e.code
    out, err = capsys.readouterr()
    return status, out, err


def one_line(status, out, err, wanted_status=2):
    """The single line of err, after checking the status and that nothing ran."""
    assert status == wanted_status and out == "", (status, out, err)
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    return err.strip()


def write_log(path, rows):
    header = ["t"] + [f"rho[{i}]" for i in range(1, 5)] + [f"F[{i}]" for i in range(1, 5)]
    path.write_text("\n".join(",".join(map(str, r)) for r in [header, *rows]) + "\n")
    return path


@pytest.fixture
def log(tmp_path):
    """A CSV log of the right columns (too short to identify: only the
    arguments are under test)."""
    return write_log(tmp_path / "log.csv", [[k * 1e-3, *[0.06] * 4, *[2.7] * 4] for k in range(5)])


@pytest.mark.parametrize("args, message", [
    (["--cutoff", "0"], "argument --cutoff: '0' is not a finite number > 0"),
    (["--cutoff", "nan"], "argument --cutoff: 'nan' is not a finite number > 0"),
    (["--cutoff=-inf"], "argument --cutoff: '-inf' is not a finite number > 0"),
    (["--trim", "-5"], "argument --trim: '-5' is not an integer >= 0"),
    (["--trim", "2.5"], "argument --trim: '2.5' is not an integer >= 0"),
    (["--model", "beta[0]=0.1"], "--model beta[0]=0.1: 'beta[0]' is no parameter of the model: beta is a vector, "
                                 "beta[1] to beta[4]"),
    (["--model", "I_rod[7]=1e-6"], "--model I_rod[7]=1e-06: 'I_rod[7]' is no parameter of the model: I_rod is a "
                                   "vector, I_rod[1] to I_rod[3]"),
    (["--model", "m_rod[1]=0.05"], "--model m_rod[1]=0.05: 'm_rod[1]' is no parameter of the model: m_rod is a "
                                   "number, without an index"),
    (["--model", "m_sliders=0.1"], "--model m_sliders=0.1: 'm_sliders' is no parameter of the model"),
    (["--model", "m_rod=nan"], "argument --model: 'm_rod=nan': 'nan' is not a finite number"),
    (["--model", "m_rod"], "argument --model: 'm_rod' is not NAME=VALUE"),
])
def test_identify_names_a_bad_argument(capsys, log, args, message, pkm_library):
    assert one_line(*command(capsys, "identify", log, *args)) == f"pkm4puu identify: error: {message}"


def test_identify_names_a_log_that_is_no_file(capsys, tmp_path):
    assert one_line(*command(capsys, "identify", tmp_path)) == \
        f"pkm4puu identify: error: argument LOG.csv: {tmp_path}: is a directory, not a file"
    assert one_line(*command(capsys, "identify", tmp_path / "absent.csv")) == \
        f"pkm4puu identify: error: argument LOG.csv: {tmp_path / 'absent.csv'}: no such file"


def test_identify_refuses_an_out_it_cannot_write_before_reading_the_log(capsys, log, tmp_path):
    assert one_line(*command(capsys, "identify", log, "--out", tmp_path)) == \
        f"pkm4puu identify: error: argument --out: {tmp_path}: is a directory"
    assert one_line(*command(capsys, "identify", log, "--out", log / "start.json")) == \
        f"pkm4puu identify: error: argument --out: {log / 'start.json'}: {log} is not a directory"


@pytest.mark.parametrize("row, message", [
    ([0.002, 0.06, 0.06, 0.06, 0.06, 2.7], "4: 6 field(s), the header has 9"),
    ([0.002, 0.06, 0.06, 0.06, "x", 2.7, 2.7, 2.7, 2.7], "4: column rho[4]: 'x' is not a number"),
])
def test_identify_names_a_bad_row_of_the_log(capsys, tmp_path, row, message, pkm_library):
    bad = write_log(tmp_path / "bad.csv", [[0.0, *[0.06] * 4, *[2.7] * 4], [0.001, *[0.06] * 4, *[2.7] * 4], row])
    assert one_line(*command(capsys, "identify", bad), wanted_status=1) == \
        f"pkm4puu identify: error: {bad}:{message}"


@pytest.mark.parametrize("args, message", [
    (["--speed", "nan"], "argument --speed: 'nan' is not a finite number > 0"),
    (["--period", "0"], "argument --period: '0' is not a finite number > 0"),
    (["--harmonics", "0"], "argument --harmonics: '0' is not an integer >= 1"),
    (["--stop-margin", "-0.001"], "argument --stop-margin: '-0.001' is not a finite number >= 0"),
    (["--z", "0.07", "0.05"], "--z 0.07 0.05: LO must be below HI"),
    (["--model", "beta[5]=0"], "--model beta[5]=0: 'beta[5]' is no parameter of the model: beta is a vector, "
                               "beta[1] to beta[4]"),
])
def test_excitation_names_a_bad_argument(capsys, args, message, pkm_library):
    assert one_line(*command(capsys, "excitation", *args)) == f"pkm4puu excitation: error: {message}"


def test_version_and_usage_name_the_command(capsys):
    status, out, err = command(capsys, "--version")
    assert status == 0 and out == f"pkm4puu {cli.__version__}\n"
    status, out, err = command(capsys, "autotest", "--help")
    assert status == 0 and out.startswith("usage: pkm4puu autotest [-h] [--build DIR] [--out DIR]")


class Stop(Exception):
    pass


def test_engines_runs_on_the_packages_own_files_without_a_build(capsys, monkeypatch, tmp_path, plant_fmu,
                                                                 inverse_fmu, pkm_library):
    """A wheel's package holds the FMUs and libpkm: `pkm4puu engines` with no
    --build, no $PKM_BUILD_DIR and no ./build runs on them (its help says
    so). The package here is a folder of the build's files; the run is
    stopped where the computing starts, with what it was given."""
    from pkm4puu.cli import engine_comparison
    pkg, empty = tmp_path / "pkg", tmp_path / "empty"
    for target, source in ((pkg / "fmus" / "fmi2" / plant_fmu.name, plant_fmu),
                           (pkg / "fmus" / "fmi2" / inverse_fmu.name, inverse_fmu),
                           (pkg / locate.LIBRARY, pkm_library),
                           (pkg / locate.CDEF, pkm_library.with_name(Path(locate.CDEF).name))):
        target.parent.mkdir(parents=True, exist_ok=True)
        target.symlink_to(source)
    empty.mkdir()
    monkeypatch.setattr(locate, "PACKAGE_DIR", pkg)
    monkeypatch.delenv(locate.BUILD_ENV)
    monkeypatch.chdir(empty)
    seen = {}

    def run_all(build, plant, inverse, log=None):
        seen.update(build=build, plant=plant, inverse=inverse)
        raise Stop

    monkeypatch.setattr(engine_comparison, "run_all", run_all)
    with pytest.raises(Stop):
        cli.main(["engines", "--out", str(tmp_path / "out")])
    assert seen == {"build": None, "plant": pkg / "fmus" / "fmi2" / plant_fmu.name,
                    "inverse": pkg / "fmus" / "fmi2" / inverse_fmu.name}
    assert str(pkg / locate.LIBRARY) in capsys.readouterr().out
