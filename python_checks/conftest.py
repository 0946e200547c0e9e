# SPDX-License-Identifier: BSD-2-Clause
"""Shared fixtures: where the repository, the FMUs and the C API are and
where results go.

The checks know the repository (it is where they are) and the package does
not: the build directory is $PKM_BUILD_DIR, else <repo>/build, which is set
as PKM_BUILD_DIR for everything the checks run (pkm4puu.locate.build_dir,
the example programs). A missing FMU is a failure, not a skip: these checks
exist to test the built FMUs.
"""
import contextlib
import io
import os
import re
from pathlib import Path

import pytest

from pkm4puu import locate

REPO = Path(__file__).resolve().parents[1]


def pytest_configure(config):
    # An exception inside an importer's callback (fmpy's CVode right-hand
    # side calling the FMU) is swallowed by ctypes: make it fail the test.
    config.addinivalue_line("filterwarnings", "error::pytest.PytestUnraisableExceptionWarning")
    # toppra's docstrings hold backslashes that Python 3.11 warns of when it
    # first compiles them (a fresh venv): not this project's to mend.
    config.addinivalue_line("filterwarnings", "ignore:invalid escape sequence:DeprecationWarning:.*/toppra/")
os.environ[locate.BUILD_ENV] = str(Path(os.environ.get(locate.BUILD_ENV) or REPO / "build").resolve())
BUILD = locate.build_dir()
# The C API's header, whose structs capi's binding must match.
PKM_HEADER = REPO / "include" / "pkm4puu" / "pkm.h"


def _require_fmu(name: str) -> Path:
    path = locate.build_path(name, BUILD)
    if not path.is_file():
        pytest.fail(
            f"{path} does not exist: build the FMUs first with ./run_tests.sh "
            f"(or point PKM_BUILD_DIR at the build directory that holds {name})",
            pytrace=False,
        )
    return path


def _built(name: str, what: str):
    """A session fixture: the path of `name` in the build directory, which
    must exist (_require_fmu)."""
    def fixture() -> Path:
        return _require_fmu(name)
    fixture.__doc__ = f"{name}, {what}."
    return pytest.fixture(scope="session")(fixture)


plant_fmu = _built("PKM4PUU.fmu", "the forward-dynamics plant")
inverse_fmu = _built("PKM4PUU_Inverse.fmu", "the algebraic inverse dynamics")
pkm_library = _built(locate.LIBRARY, "the plain C API (pkm.h)")
plant_fmu3 = _built(f"{locate.FMI3_DIR}/PKM4PUU.fmu", "the plant as FMI 3.0 (Co-Simulation and Model Exchange)")
inverse_fmu3 = _built(f"{locate.FMI3_DIR}/PKM4PUU_Inverse.fmu", "the inverse dynamics as FMI 3.0")


@pytest.fixture(scope="session")
def pkm_header() -> Path:
    """The C API's header pkm.h in the source tree."""
    return PKM_HEADER


@pytest.fixture(scope="session")
def results_dir() -> Path:
    path = REPO / "results"
    path.mkdir(parents=True, exist_ok=True)
    return path


@pytest.fixture(scope="session")
def dist_fmus() -> dict:
    """dist/fmi<v>/<id>.fmu: one archive per FMU and FMI version holding every
    platform and the source code (cmake/Platforms.cmake), keyed (version, id)."""
    return {(v, i): _require_fmu(str(locate.dist_fmu_path(i, v, BUILD).relative_to(BUILD)))
            for v in (2, 3) for i in ("PKM4PUU", "PKM4PUU_Inverse")}


def promised_files(help_text: str) -> set:
    """The file names a command's --help promises for --out."""
    out = help_text[help_text.index("--out DIR"):]
    return set(re.findall(r"[\w.]+\.(?:csv|png|gif|json)\b", " ".join(out.split())))


def command_help(command: str) -> str:
    """`pkm4puu COMMAND --help`, run in this process."""
    from pkm4puu import cli
    text = io.StringIO()
    with contextlib.redirect_stdout(text), pytest.raises(SystemExit) as e:
        cli.main([command, "--help"])
    assert e.value.code == 0
    return text.getvalue()
