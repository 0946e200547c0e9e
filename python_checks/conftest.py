"""Shared fixtures: where the FMUs are and where results go.

The FMUs are taken from $PKM_BUILD_DIR (default <repo>/build, see
pkm4puu.build_dir). A missing FMU is a failure, not a skip: these checks
exist to test the built FMUs.
"""
from pathlib import Path

import pytest

from pkm4puu.fmu import REPO, build_dir


def _require_fmu(name: str) -> Path:
    path = build_dir() / name
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
pkm_library = _built("lib/libpkm.so", "the plain C API (pkm.h)")
plant_fmu3 = _built("fmi3/PKM4PUU.fmu", "the plant as FMI 3.0 (Co-Simulation and Model Exchange)")
inverse_fmu3 = _built("fmi3/PKM4PUU_Inverse.fmu", "the inverse dynamics as FMI 3.0")


@pytest.fixture(scope="session")
def results_dir() -> Path:
    path = REPO / "results"
    path.mkdir(parents=True, exist_ok=True)
    return path


@pytest.fixture(scope="session")
def dist_fmus() -> dict:
    """dist/fmi<v>/<id>.fmu: one archive per FMU and FMI version holding every
    platform and the source code (cmake/Platforms.cmake), keyed (version, id)."""
    return {(v, i): _require_fmu(f"dist/fmi{v}/{i}.fmu") for v in (2, 3) for i in ("PKM4PUU", "PKM4PUU_Inverse")}
