# SPDX-License-Identifier: BSD-2-Clause
"""The wheel as a user installs it: `pip install WHEEL` with no extras
(binaries only, no compiler) into a fresh venv, used from an empty folder
with no PKM_* variable set. The library imports (`from pkm4puu import *`,
pkm4puu.identify), the version is the project's, the FMUs and libpkm are
the package's own; the command `pkm4puu` tells its version, every
command's --help works, a command that needs an extra says in one line
which to install (exit status 2, no traceback), the auto-test runs without
matplotlib and writes what its help promises but the figures (and says how
to get them), and an --out that cannot be written fails before anything
runs.

The wheel is the one ctest distribution_wheel built and left in
build/wheel-check/dist (tests/check_wheel.py); when it is missing, or its
Python files are not the source tree's, that script builds it again (its
CMake build is cached there: incremental after the first)."""
import os
import re
import subprocess
import sys
import venv
import zipfile

import pytest

import pkm4puu
from conftest import BUILD, REPO, promised_files
from pkm4puu.cli import COMMANDS

WORK = BUILD / "wheel-check"  # distribution_wheel's --work (tests/CMakeLists.txt)
EXTRA_MODULES = ("matplotlib", "scipy", "pinocchio", "mujoco")  # what the extras install


def source_differs(wheel):
    """The package's Python files where the wheel's are not the source
    tree's (missing, extra or changed); empty when it is current."""
    with zipfile.ZipFile(wheel) as z:
        inside = {n: z.read(n) for n in z.namelist() if n.startswith("pkm4puu/") and n.endswith(".py")}
    source = {str(p.relative_to(REPO / "python")): p for p in (REPO / "python" / "pkm4puu").rglob("*.py")}
    return sorted(n for n in inside.keys() | source.keys()
                  if n not in inside or n not in source or inside[n] != source[n].read_bytes())


@pytest.fixture(scope="module")
def wheel():
    wheels = sorted((WORK / "dist").glob(f"pkm4puu-{pkm4puu.__version__}-*.whl"))
    if len(wheels) != 1 or source_differs(wheels[0]):
        proc = subprocess.run([sys.executable, str(REPO / "tests" / "check_wheel.py"), "--source", str(REPO),
                               "--work", str(WORK), "--version", pkm4puu.__version__], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stdout + proc.stderr
        wheels = sorted((WORK / "dist").glob(f"pkm4puu-{pkm4puu.__version__}-*.whl"))
    assert len(wheels) == 1 and not source_differs(wheels[0]), wheels
    return wheels[0]


def test_the_wheel_carries_the_version_and_the_licence(wheel):
    """Its metadata's version is pkm4puu.__version__ (one source,
    _version.py), its licence BSD-2-Clause, and the project's LICENSE is in
    its .dist-info."""
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        meta = z.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
        licence = next(n for n in names if re.search(r"\.dist-info/(licenses/)?LICENSE$", n))
        assert z.read(licence) == (REPO / "LICENSE").read_bytes()
    assert f"\nVersion: {pkm4puu.__version__}\n" in meta
    assert re.search(r"^License(-Expression)?: BSD-2-Clause$", meta, re.M), meta[:600]


class User:
    """A fresh venv holding the wheel without extras, and an empty folder."""

    def __init__(self, root, wheel):
        self.root = root
        self.bin = root / "venv" / "bin"
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("PKM_") and k != "PYTHONPATH"}
        venv.create(root / "venv", with_pip=True)
        proc = subprocess.run([self.bin / "python", "-m", "pip", "install", "--disable-pip-version-check", "-q",
                               "--only-binary=:all:", str(wheel)], capture_output=True, text=True, env=self.env)
        assert proc.returncode == 0, proc.stderr
        self.cwd = root / "empty"
        self.cwd.mkdir()

    def run(self, *args, program="pkm4puu", timeout=300):
        """The venv's `program` (pkm4puu, python) with args, in the empty folder."""
        return subprocess.run([str(self.bin / program), *map(str, args)], capture_output=True, text=True,
                              cwd=self.cwd, env=self.env, timeout=timeout)


@pytest.fixture(scope="module")
def user(wheel, tmp_path_factory):
    return User(tmp_path_factory.mktemp("wheel-user"), wheel)


def one_line_error(proc):
    """proc's error: exit status 2, one line on stderr, no traceback."""
    assert proc.returncode == 2, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    return proc.stderr.strip()


PROBE = """
import importlib.util, sys
from pathlib import Path
from pkm4puu import *
import pkm4puu, pkm4puu.capi as capi
assert identify is pkm4puu.identify and identify.__module__ == "pkm4puu.calibration.identification"
root = Path(sys.prefix).resolve()
paths = [find_fmu(m, v) for m in ("PKM4PUU", "PKM4PUU_Inverse") for v in (2, 3)] + [capi.library_path()]
outside = [p for p in paths if root not in p.resolve().parents]
assert not outside, f"not inside the venv {root}: {outside}"
lib = capi.load()
print(__version__, lib.ffi.string(lib.pkm_version()).decode())
print(*(m for m in sys.argv[1:] if importlib.util.find_spec(m)))
try:
    identify([0.0, 1.0], [[0.0] * 4] * 2, [[0.0] * 4] * 2)
except ModuleNotFoundError as e:
    print(e)
"""


def test_the_library_without_extras(user):
    """`from pkm4puu import *` with pkm4puu.identify in it, the version
    project()'s and libpkm's, the FMUs and libpkm the venv's own; no extra
    installed, and pkm4puu.identify says which one it needs."""
    proc = user.run("-c", PROBE, *EXTRA_MODULES, program="python")
    assert proc.returncode == 0, proc.stderr
    versions, extras_found, identify_error = proc.stdout.splitlines()
    assert versions.split() == [pkm4puu.__version__] * 2
    assert extras_found == ""
    assert identify_error == "pkm4puu.identify needs scipy (not installed): pip install 'pkm4puu[calibration]'"


def test_version(user):
    for program, args in (("pkm4puu", ()), ("python", ("-m", "pkm4puu"))):
        proc = user.run(*args, "--version", program=program)
        assert proc.returncode == 0 and proc.stdout == f"pkm4puu {pkm4puu.__version__}\n", proc.stderr


def test_every_commands_help_works_without_extras(user):
    """pkm4puu --help lists every command; each command's help works, its
    usage naming the command as invoked."""
    top = user.run("--help")
    assert top.returncode == 0 and top.stdout.startswith("usage: pkm4puu "), top.stderr
    for command in COMMANDS:
        assert re.search(rf"^  {re.escape(command)} ", top.stdout, re.M), top.stdout
        proc = user.run(command, "--help")
        assert proc.returncode == 0, (command, proc.stderr)
        assert proc.stdout.startswith(f"usage: pkm4puu {command} "), proc.stdout
    proc = user.run("-m", "pkm4puu", "identify", "--help", program="python")
    assert proc.returncode == 0 and proc.stdout.startswith("usage: python -m pkm4puu identify "), proc.stdout


@pytest.mark.parametrize("command, args, extra, module", [
    ("engines", [], "references", "pinocchio, mujoco, scipy"),
    ("identify", ["log.csv"], "calibration", "scipy"),
    ("excitation", [], "calibration", "scipy"),
    ("plot-autotest", ["."], "plots", "matplotlib"),
])
def test_a_command_needing_an_extra_names_it_in_one_line(user, command, args, extra, module):
    (user.cwd / "log.csv").write_text("t\n")
    try:
        message = one_line_error(user.run(command, *args))
    finally:
        (user.cwd / "log.csv").unlink()
    assert message == f"pkm4puu {command}: error: needs {module} (not installed): pip install 'pkm4puu[{extra}]'"


def test_the_auto_test_runs_without_the_figures_and_says_how_to_get_them(user, tmp_path):
    """The main command without matplotlib: the checks pass, every promised
    file but the figures is written, nothing into the current folder, and a
    line says which extra draws the figures."""
    promised = promised_files(user.run("autotest", "--help").stdout)
    assert {"fmu_autotest.csv", "fmu_autotest_checks.csv", "fmu_autotest_pose.png"} <= promised
    proc = user.run("autotest", "--out", tmp_path / "res")
    assert proc.returncode == 0, proc.stderr
    assert "figures skipped: matplotlib is not installed (pip install 'pkm4puu[plots]' draws them)" in proc.stderr
    assert {p.name for p in (tmp_path / "res").iterdir()} == {f for f in promised if not f.endswith(".png")}
    assert not any(user.cwd.iterdir())


@pytest.mark.parametrize("command", ["autotest", "comparison", "engines"])
def test_an_out_that_cannot_be_written_fails_at_once(user, tmp_path, command):
    """Under a file (root writes into read-only folders, so that is the
    unwritable place here): exit 2 naming it, before anything runs; --out
    without its value likewise."""
    afile = tmp_path / "a_file"
    afile.write_text("")
    message = one_line_error(user.run(command, "--out", afile / "res")).splitlines()[-1]
    assert message == f"pkm4puu {command}: error: argument --out: {afile / 'res'}: {afile} is not a directory"
    assert "--out: expected one argument" in user.run(command, "--out").stderr
