# SPDX-License-Identifier: BSD-2-Clause
"""The reports that check the built FMUs and C API against the paper and
against independent models, and what they share; run them as `python -m
pkm4puu COMMAND` (pkm4puu.__main__). Not the library: the programs here
write files, draw figures (matplotlib, the extra `plots`) and need the
extra `references` for the independent models.

autotest, comparison (the paper's tests through the FMUs), plot_cpp_autotest
(figures of the C++ auto-test's CSV files), engine_comparison (against the
references), references (the independent Pinocchio and MuJoCo models,
imported on demand), plots and drawing (figures and the mechanism's
points), cli (what the report programs and the examples share)."""
