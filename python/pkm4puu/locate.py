# SPDX-License-Identifier: BSD-2-Clause
"""Where the FMUs and libpkm are: the package's own copies (an installed
wheel holds them), or a build directory's, each path written once here.

A file is looked for in the build directory when one is asked for (a
`build` argument, --build on the command line, or $PKM_BUILD_DIR), else
in the package itself (pkm4puu/fmus/fmi<v>/<model>.fmu and
pkm4puu/lib/libpkm.so or its platform's name, which the wheel built from the repository's
pyproject.toml holds), else in ./build of the current directory (the
development install, `pip install -e .`, holds none). Nothing outside the
package is derived from where it is installed, and nothing here knows the
build tree's programs (who runs one finds it).
"""
import os
import sys
from pathlib import Path
from typing import Optional, Union

BUILD_ENV = "PKM_BUILD_DIR"
DEFAULT_BUILD = Path("build")  # relative to the current directory

# The plain C API's shared library (pkm.h) by platform, as the build names it.
LIBRARY_NAME = {"win32": "pkm.dll", "darwin": "libpkm.dylib"}.get(sys.platform, "libpkm.so")
# Build-relative paths.
LIBRARY = f"lib/{LIBRARY_NAME}"
CDEF = "lib/pkm_cdef.h"  # pkm.h preprocessed for cffi, beside the library (the Python binding, capi.py)
# Within the build directory: the FMI 2.0 archives at the top, the FMI 3.0
# ones in FMI3_DIR, the multi-platform ones in DIST_DIR/fmi<version>.
FMI3_DIR = "fmi3"
DIST_DIR = "dist"

PathLike = Union[str, Path]

# The package's own copies (the wheel's; PKM_WHEEL in cmake/Install.cmake):
# LIBRARY and PACKAGED_FMUS/fmi<version>/<model>.fmu under PACKAGE_DIR.
PACKAGE_DIR = Path(__file__).resolve().parent
PACKAGED_FMUS = "fmus"


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
    """`relative` in the build directory."""
    return build_dir(build) / relative


def asked_build(build: PathLike = None) -> Optional[Path]:
    """The build directory when one is asked for (`build`, else
    $PKM_BUILD_DIR), else None."""
    if build is not None or os.environ.get(BUILD_ENV):
        return build_dir(build)
    return None


def packaged(relative: str) -> Optional[Path]:
    """`relative` in the installed package when the package holds it (a
    wheel's), else None."""
    path = PACKAGE_DIR / relative
    return path if path.is_file() else None


def _find(packaged_relative: str, build_relative: str, build: PathLike) -> Path:
    """The build directory's file when one is asked for, else the package's
    own, else ./build's (see the module's doc)."""
    asked = asked_build(build)
    if asked is not None:
        return asked / build_relative
    return packaged(packaged_relative) or build_dir() / build_relative


def fmu_path(model: str, fmi: int = 2, build: PathLike = None) -> Path:
    """The archive of `model` for FMI `fmi`: <build>/<model>.fmu (FMI 2.0)
    or <build>/fmi3/<model>.fmu (FMI 3.0) when a build directory is asked
    for, else the package's pkm4puu/fmus/fmi<fmi>/<model>.fmu when it holds
    it, else ./build's."""
    in_build = str(Path(FMI3_DIR if fmi == 3 else "", f"{model}.fmu"))
    return _find(f"{PACKAGED_FMUS}/fmi{fmi}/{model}.fmu", in_build, build)


def library_path(build: PathLike = None) -> Path:
    """libpkm (LIBRARY) as fmu_path finds an archive: the asked-for build
    directory's, else the package's, else ./build's."""
    return _find(LIBRARY, LIBRARY, build)


def dist_fmu_path(model: str, fmi: int, build: PathLike = None) -> Path:
    """The archive with every platform and the sources: <build>/dist/fmi<fmi>/<model>.fmu."""
    return build_dir(build) / DIST_DIR / f"fmi{fmi}" / f"{model}.fmu"
