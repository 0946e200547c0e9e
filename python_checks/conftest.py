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


@pytest.fixture(scope="session")
def plant_fmu() -> Path:
    """PKM4PUU.fmu, the forward-dynamics plant."""
    return _require_fmu("PKM4PUU.fmu")


@pytest.fixture(scope="session")
def inverse_fmu() -> Path:
    """PKM4PUU_Inverse.fmu, the algebraic inverse dynamics."""
    return _require_fmu("PKM4PUU_Inverse.fmu")


@pytest.fixture(scope="session")
def results_dir() -> Path:
    path = REPO / "results"
    path.mkdir(parents=True, exist_ok=True)
    return path


@pytest.fixture(scope="session")
def pkm_library() -> Path:
    """fmu_src/libpkm.so, the plain C API (pkm.h)."""
    return _require_fmu("fmu_src/libpkm.so")


@pytest.fixture(scope="session")
def plant_fmu3() -> Path:
    """fmi3/PKM4PUU.fmu, the plant as FMI 3.0 (Co-Simulation and Model Exchange)."""
    return _require_fmu("fmi3/PKM4PUU.fmu")


@pytest.fixture(scope="session")
def inverse_fmu3() -> Path:
    """fmi3/PKM4PUU_Inverse.fmu, the inverse dynamics as FMI 3.0."""
    return _require_fmu("fmi3/PKM4PUU_Inverse.fmu")


@pytest.fixture(scope="session")
def dist_fmus() -> dict:
    """dist/fmi<v>/<id>.fmu: one archive per FMU and FMI version holding every
    platform and the source code (cmake/Platforms.cmake), keyed (version, id)."""
    return {(v, i): _require_fmu(f"dist/fmi{v}/{i}.fmu") for v in (2, 3) for i in ("PKM4PUU", "PKM4PUU_Inverse")}
