# SPDX-License-Identifier: BSD-2-Clause
"""The Python package pkm4puu (python/pkm4puu): the README's first look runs
as written (the getting-started page's session: test_docs.py), and the wrapper opens the FMUs by name, runs them with named inputs
and outputs, and says clearly what is wrong with a bad request; the library
and the programs import without the extras, the library finds the build
directory from what it is given (not from where it is installed), and the
command pkm4puu runs the programs. One pyproject.toml declares the package;
the development install is its editable install, which builds nothing."""
import os
import re
import subprocess
import sys

from pathlib import Path

import matplotlib
import numpy as np
import pytest

import pkm4puu as pkm
from conftest import REPO
from pkm4puu import capi, locate
from pkm4puu import extras
from pkm4puu.cli import COMMANDS

# The README's first look, run as written.
README_MARKER = "## A first look from Python"


def readme_session():
    text = (REPO / "README.md").read_text()
    m = re.search(re.escape(README_MARKER) + r"\s*```python\n(.*?)```", text, re.S)
    assert m, f"README.md has no python block after {README_MARKER!r}"
    return m.group(1)


def test_readme_first_look_holds_the_platform_at_home(plant_fmu, capsys, monkeypatch):
    """The README's block: the static forces of docs/model.md hold the plant at
    P0, so the last pose it prints is P0 to within the integration's rounding."""
    monkeypatch.setenv("PKM_BUILD_DIR", str(plant_fmu.parent))
    scope = {}
    exec(compile(readme_session(), "README.md first look", "exec"), scope)
    assert scope["run"].t[-1] == pytest.approx(1.0)
    assert np.abs(scope["run"].values[-1] - pkm.P0).max() < 1e-9
    assert capsys.readouterr().out.strip()


def test_open_by_name_and_version(plant_fmu, plant_fmu3):
    assert pkm.find_fmu("PKM4PUU", 2, plant_fmu.parent) == plant_fmu
    assert pkm.find_fmu("PKM4PUU", 3, plant_fmu.parent) == plant_fmu3
    with pytest.raises(ValueError, match="unknown model 'PKM'"):
        pkm.find_fmu("PKM")
    with pytest.raises(ValueError, match="fmi must be 2 or 3"):
        pkm.find_fmu("PKM4PUU", 1)
    with pytest.raises(FileNotFoundError, match="build the FMUs first"):
        pkm.find_fmu("PKM4PUU", 2, REPO / "no-such-build")


@pytest.mark.parametrize("fmi", [2, 3])
def test_simulate_with_named_inputs_and_parameters(plant_fmu, fmi):
    """Holding the static forces at P0 (docs/model.md's check anyone can derive)
    keeps the platform at rest: the pose stays P0 to within the integration's
    rounding, in both FMI versions, through named start values and inputs."""
    hold = dict(zip(pkm.F, [pkm.STATIC_FORCE_P0] * 4))
    with pkm.Fmu.open("PKM4PUU", fmi, plant_fmu.parent, start={**pkm.START_P0, **pkm.RK4}) as plant:
        r = plant.simulate(0.1, pkm.STEP, inputs=hold, outputs=pkm.POSE + ["dz"])
    assert r.values.shape == (101, 5) and r.names == pkm.POSE + ["dz"]
    assert np.abs(r.values[:, :4] - pkm.P0).max() < 1e-9
    assert np.abs(r["dz"]).max() < 1e-8


def test_simulate_refuses_a_stop_time_off_the_step_grid(plant_fmu):
    with pkm.Fmu.open("PKM4PUU", build=plant_fmu.parent) as plant:
        with pytest.raises(ValueError, match="not a whole number of steps"):
            plant.simulate(0.0105, pkm.STEP)
        with pytest.raises(KeyError, match="no variable named 'F5'"):
            plant.simulate(0.001, pkm.STEP, inputs={"F5": 1.0})


LIBRARY_MODULES = ["spec", "interface", "motions", "locate", "fmu", "capi", "linearization", "closed_loop", "drawing",
                   "plots", "program", "extras", "calibration"]
# The programs: the command's module and each command's (the engine
# comparison's runners, engine_comparison, need the extra references).
PROGRAM_MODULES = ["cli"] + [f"cli.{module}" for module, _ in COMMANDS.values()]
EXTRA_MODULES = ["matplotlib", "scipy", "pinocchio", "mujoco"]


def test_package_imports_without_the_extras():
    """The extras (plots: matplotlib; calibration: scipy; references:
    pinocchio, mujoco) come when used: the library and every command's
    module import with them hidden (a None entry in sys.modules makes an
    import fail), so that `pkm4puu COMMAND --help` works without them."""
    names = ["pkm4puu"] + [f"pkm4puu.{m}" for m in LIBRARY_MODULES + PROGRAM_MODULES]
    code = ("import sys\n"
            f"for name in {EXTRA_MODULES!r}:\n"
            "    sys.modules[name] = None\n"
            f"for name in {names!r}:\n"
            "    __import__(name)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_star_import_holds_identify():
    """`from pkm4puu import *` gives every name of __all__, pkm4puu.identify
    among them: the calibration's identification."""
    from pkm4puu.calibration import identify
    scope = {}
    exec("from pkm4puu import *", scope)
    assert set(pkm.__all__) <= set(scope) and scope["identify"] is identify is pkm.identify
    with pytest.raises(AttributeError, match="no attribute 'identity'"):
        pkm.identity


def test_build_directory_from_argument_environment_or_cwd(tmp_path, monkeypatch):
    """locate.build_dir: the argument, else $PKM_BUILD_DIR, else ./build, and
    an error naming both ways when none is there."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(locate.BUILD_ENV, raising=False)
    with pytest.raises(FileNotFoundError, match=f"--build DIR.*{locate.BUILD_ENV}"):
        locate.build_dir()
    (tmp_path / "build").mkdir()
    assert locate.build_dir() == tmp_path / "build"
    monkeypatch.setenv(locate.BUILD_ENV, str(tmp_path / "env"))
    assert locate.build_dir() == tmp_path / "env"
    assert locate.build_dir(tmp_path / "arg") == tmp_path / "arg"



def test_files_from_the_asked_build_else_the_package_else_cwd_build(tmp_path, monkeypatch):
    """locate.fmu_path and library_path (find_fmu, capi.load): the build
    directory when one is asked for (argument, else $PKM_BUILD_DIR), else the
    package's own copies (a wheel's pkm4puu/fmus and pkm4puu/lib), else
    ./build."""
    pkg, cwd = tmp_path / "pkg", tmp_path / "cwd"
    for rel in ("fmus/fmi2/PKM4PUU.fmu", "fmus/fmi3/PKM4PUU.fmu", locate.LIBRARY):
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_bytes(b"")
    (cwd / "build").mkdir(parents=True)
    monkeypatch.chdir(cwd)
    monkeypatch.delenv(locate.BUILD_ENV, raising=False)
    monkeypatch.setattr(locate, "PACKAGE_DIR", pkg)
    assert pkm.find_fmu("PKM4PUU", 2) == pkg / "fmus/fmi2/PKM4PUU.fmu"
    assert pkm.find_fmu("PKM4PUU", 3) == pkg / "fmus/fmi3/PKM4PUU.fmu"
    assert capi.library_path() == pkg / locate.LIBRARY
    # not packaged: ./build's
    assert locate.fmu_path("PKM4PUU_Inverse", 3) == cwd / "build/fmi3/PKM4PUU_Inverse.fmu"
    # asked for: the build directory's, packaged or not
    assert locate.fmu_path("PKM4PUU", 2, tmp_path / "arg") == tmp_path / "arg/PKM4PUU.fmu"
    monkeypatch.setenv(locate.BUILD_ENV, str(tmp_path / "env"))
    assert locate.fmu_path("PKM4PUU", 3) == tmp_path / "env/fmi3/PKM4PUU.fmu"
    assert capi.library_path() == tmp_path / "env" / locate.LIBRARY
    assert locate.fmu_path("PKM4PUU", 2, tmp_path / "arg") == tmp_path / "arg/PKM4PUU.fmu"


def test_checks_run_the_build_trees_files(plant_fmu, plant_fmu3, pkm_library):
    """This package is the development install (`pip install -e .`): it
    holds no FMUs nor libpkm of its own, so the checks test the build
    tree's ($PKM_BUILD_DIR, conftest.py), whatever is asked."""
    assert not (locate.PACKAGE_DIR / locate.PACKAGED_FMUS).exists()
    assert locate.packaged(locate.LIBRARY) is None
    assert pkm.find_fmu("PKM4PUU", 2) == plant_fmu and pkm.find_fmu("PKM4PUU", 3) == plant_fmu3
    assert capi.library_path() == pkm_library

def run_cli(*args, **kwargs):
    return subprocess.run([sys.executable, "-m", "pkm4puu", *args], capture_output=True, text=True, **kwargs)


def test_command_line_lists_and_dispatches_the_programs():
    """The command pkm4puu (console command, or python -m pkm4puu): its help
    lists every command, each command's help is its program's with the
    usage naming the command as invoked, and a wrong command fails with the
    list."""
    proc = run_cli("--help")
    assert proc.returncode == 0, proc.stderr
    for command in COMMANDS:
        assert command in proc.stdout
        sub = run_cli(command, "--help")
        assert sub.returncode == 0 and sub.stdout.startswith(f"usage: python -m pkm4puu {command} "), sub.stderr
    console = Path(sys.executable).parent / "pkm4puu"
    sub = subprocess.run([console, "comparison", "--help"], capture_output=True, text=True)
    assert sub.returncode == 0 and sub.stdout.startswith("usage: pkm4puu comparison "), sub.stderr
    bad = run_cli("no-such-command")
    assert bad.returncode == 2 and "invalid choice: 'no-such-command'" in bad.stderr
    assert run_cli().returncode == 2


def test_version():
    for proc in (run_cli("--version"), subprocess.run([Path(sys.executable).parent / "pkm4puu", "--version"],
                                                        capture_output=True, text=True)):
        assert proc.returncode == 0 and proc.stdout == f"pkm4puu {pkm.__version__}\n", proc.stderr


def test_command_line_without_a_build_says_how_to_give_one(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != locate.BUILD_ENV}
    proc = run_cli("comparison", cwd=tmp_path, env=env)
    assert proc.returncode == 1
    assert "--build DIR" in proc.stderr and locate.BUILD_ENV in proc.stderr, proc.stderr
    assert not (tmp_path / "results").exists()


def test_one_pyproject_declares_the_installed_package():
    """pyproject.toml is the one declaration: the installed package's
    metadata (this development install's) has its version, licence,
    dependencies, extras and console command; the extras' install commands
    (extras.install_command) name its extras."""
    import tomllib
    from importlib.metadata import distribution
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    dist = distribution("pkm4puu")
    assert dist.version == pkm.__version__ and dist.metadata["License"] == project["license"]["text"]
    extras_declared = project["optional-dependencies"]
    declared = set(project["dependencies"]) | {f'{d}; extra == "{x}"' for x, ds in extras_declared.items() for d in ds}
    assert set(dist.requires) == declared
    assert {(e.name, e.value) for e in dist.entry_points if e.group == "console_scripts"} == \
        set(project["scripts"].items()) == {("pkm4puu", "pkm4puu.cli:main")}
    assert extras.install_command(["matplotlib"]) == "pip install 'pkm4puu[plots]'"
    assert extras.install_command(["scipy"]) == "pip install 'pkm4puu[calibration]'"
    assert extras.install_command(["pinocchio", "mujoco"]) == "pip install 'pkm4puu[references]'"
    assert not (REPO / "python" / "pyproject.toml").exists()


def test_the_development_install_builds_nothing(tmp_path):
    """The package runs from the source tree (the editable install), and
    pyproject.toml's editable override configures CMake with PKM_PYTHON_ONLY,
    under which it enables no language and writes no build rule: `pip
    install -e .` compiles nothing."""
    import tomllib
    assert Path(pkm.__file__) == REPO / "python" / "pkm4puu" / "__init__.py"
    skbuild = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["scikit-build"]
    editable, = (o for o in skbuild["overrides"] if o["if"] == {"state": "editable"})
    assert editable["cmake"]["define"] == {"PKM_PYTHON_ONLY": "ON"} and editable["build"]["targets"] == []
    assert skbuild["cmake"]["define"]["PKM_PYTHON_ONLY"] == "OFF"  # the wheel's
    proc = subprocess.run(["cmake", "-S", REPO, "-B", tmp_path, "-G", "Ninja", "-DPKM_PYTHON_ONLY=ON"],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    cache = (tmp_path / "CMakeCache.txt").read_text()
    assert "CMAKE_CXX_COMPILER" not in cache and "CMAKE_C_COMPILER" not in cache
    rules = re.findall(r"^build (\S+):", (tmp_path / "build.ninja").read_text(), re.M)
    assert not [r for r in rules if r.endswith((".o", ".so", ".a", ".fmu"))], rules
