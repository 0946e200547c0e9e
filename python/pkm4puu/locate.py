# SPDX-License-Identifier: BSD-2-Clause
"""Where the built artifacts are: the build directory and every path the
package looks for inside it, each written once here.

The build directory is the one passed in (a `build` argument, --build on
the command line), else $PKM_BUILD_DIR, else ./build in the current
directory. Nothing is derived from where this package is installed.
"""
import os
from pathlib import Path
from typing import Union

BUILD_ENV = "PKM_BUILD_DIR"
DEFAULT_BUILD = Path("build")  # relative to the current directory

# Build-relative paths.
LIBRARY = "lib/libpkm.so"  # the plain C API, pkm.h
AUTOTEST_PROGRAM = "bin/pkm_autotest"  # the C++ auto-test, the main job's program
BENCH_PROGRAM = "bench/pkm_bench"  # the C++ benchmark (bench/pkm_bench.cpp)
FMU_BENCH_PROGRAM = "bench/pkm_fmu_bench"  # the FMU's C harness; `compare` feeds bench/engines_bench.py
# Within the build directory: the FMI 2.0 archives at the top, the FMI 3.0
# ones in FMI3_DIR, the multi-platform ones in DIST_DIR/fmi<version>.
FMI3_DIR = "fmi3"
DIST_DIR = "dist"

PathLike = Union[str, Path]


def build_dir(build: PathLike = None) -> Path:
    """The build directory: `build` when given, else $PKM_BUILD_DIR, else
    ./build; FileNotFoundError naming both ways to give it when neither was
    given and ./build does not exist."""
    if build is not None:
        return Path(build).resolve()
    if os.environ.get(BUILD_ENV):
        return Path(os.environ[BUILD_ENV]).resolve()
    if DEFAULT_BUILD.is_dir():
        return DEFAULT_BUILD.resolve()
    raise FileNotFoundError(f"no build directory: pass one (--build DIR on the command line) or set {BUILD_ENV}; "
                            f"the default ./{DEFAULT_BUILD} does not exist in {Path.cwd()}")


def build_path(relative: str, build: PathLike = None) -> Path:
    """`relative` (one of the constants above) in the build directory."""
    return build_dir(build) / relative


def fmu_path(model: str, fmi: int = 2, build: PathLike = None) -> Path:
    """<build>/<model>.fmu (FMI 2.0) or <build>/fmi3/<model>.fmu (FMI 3.0)."""
    return build_dir(build) / (FMI3_DIR if fmi == 3 else "") / f"{model}.fmu"


def dist_fmu_path(model: str, fmi: int, build: PathLike = None) -> Path:
    """The archive with every platform and the sources: <build>/dist/fmi<fmi>/<model>.fmu."""
    return build_dir(build) / DIST_DIR / f"fmi{fmi}" / f"{model}.fmu"
