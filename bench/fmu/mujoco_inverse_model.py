# SPDX-License-Identifier: BSD-2-Clause
"""Writes what pkm_fmu_inverse_bench's mj_inverse case loads: the MJCF of
the mechanism as pkm4puu.references.mujoco_model builds it for
the engines' benchmarks (spec gravity, no machine), and a state on the
auto-test path at t = 1 s: qpos (the spec's closed-form leg inverse
kinematics and the pose), qvel and qacc (the legs' by central differences
of that closed form along the path, the platform's exact), 48 numbers.

usage: python bench/fmu/mujoco_inverse_model.py MJCF STATE
"""
import sys

import numpy as np

from pkm4puu import motions, spec
from pkm4puu.references import mujoco_model

T = 1.0


def qpos(t):
    pose = motions.autotest_motion(t)[0]
    return np.concatenate([np.asarray(spec.leg_inverse_kinematics(pose)).ravel(), pose])


def main(mjcf_path, state_path):
    pose, pd, pdd = (np.asarray(v, dtype=float) for v in motions.autotest_motion(T))
    h1, h2 = 1e-6, 1e-4
    q = qpos(T)
    qd = (qpos(T + h1) - qpos(T - h1)) / (2 * h1)
    qdd = (qpos(T + h2) - 2 * q + qpos(T - h2)) / (h2 * h2)
    qd[12:], qdd[12:] = pd, pdd
    with open(mjcf_path, "w") as f:
        f.write(mujoco_model.mjcf())
    with open(state_path, "w") as f:
        f.write("\n".join(" ".join(f"{x:.17g}" for x in v) for v in (q, qd, qdd)) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:3])
