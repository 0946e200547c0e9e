# SPDX-License-Identifier: BSD-2-Clause
# The package's version, which pyproject.toml reads: CMake's project() version
# (the ctest distribution_one_version fails when they differ).
__version__ = "0.1.0"
