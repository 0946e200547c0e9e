# SPDX-License-Identifier: BSD-2-Clause
"""Independent models of the 4-PUU mechanism for validation and benchmarks,
built from docs/model.md's numbers only (pkm4puu.spec): Pinocchio
(pinocchio_model.py, the reference) and MuJoCo (mujoco_model.py)."""
