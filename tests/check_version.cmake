# SPDX-License-Identifier: BSD-2-Clause
# ctest distribution_one_version: the version of project() is the Python
# package's (python/pkm4puu/_version.py, which pyproject.toml reads) and
# CHANGELOG.md's latest release.
#   cmake -DVERSION=X.Y.Z -DSOURCE=<repository> -P check_version.cmake
file(STRINGS "${SOURCE}/python/pkm4puu/_version.py" py REGEX "^__version__ = ")
if(NOT py STREQUAL "__version__ = \"${VERSION}\"")
  message(FATAL_ERROR "python/pkm4puu/_version.py says '${py}', project() ${VERSION}")
endif()
file(STRINGS "${SOURCE}/pyproject.toml" dyn REGEX "^dynamic = |^provider = |^input = ")
if(NOT dyn STREQUAL "dynamic = [\"version\"];provider = \"scikit_build_core.metadata.regex\";input = \"python/pkm4puu/_version.py\"")
  message(FATAL_ERROR "pyproject.toml: '${dyn}', expected the version read from python/pkm4puu/_version.py")
endif()
file(STRINGS "${SOURCE}/CHANGELOG.md" releases REGEX "^## \\[[0-9]")
list(GET releases 0 latest)
if(NOT latest MATCHES "^## \\[${VERSION}\\] - [0-9][0-9][0-9][0-9]-[0-9][0-9]-[0-9][0-9]$")
  message(FATAL_ERROR "CHANGELOG.md's latest release is '${latest}', project() ${VERSION}")
endif()
message(STATUS "version ${VERSION}: project(), _version.py (pyproject.toml), CHANGELOG.md")
