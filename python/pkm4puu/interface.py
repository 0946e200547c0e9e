# SPDX-License-Identifier: BSD-2-Clause
"""Names of the FMUs' variables (docs/model.md "The FMUs' names") and the
start values the tests and examples use most."""
from .spec import P0, STEP


def indexed_names(name, n):
    """The names of an FMI array's elements, 1-based: indexed_names('F', 4)
    -> ['F[1]', ..., 'F[4]']."""
    return [f"{name}[{i}]" for i in range(1, n + 1)]


POSE = ["x", "y", "z", "phi"]
VEL = ["dx", "dy", "dz", "dphi"]
ACC = ["ddx", "ddy", "ddz", "ddphi"]
F = indexed_names("F", 4)
WRENCH = indexed_names("Fe", 3) + ["Me_z"]
RHO = indexed_names("rho", 4)
DRHO = indexed_names("drho", 4)
THETA1 = indexed_names("theta1", 4)
THETA2 = indexed_names("theta2", 4)
# The columns of a run's CSV (pkm4puu.drawing.write_run_csv).
RUN_COLUMNS = POSE + RHO + THETA1 + THETA2


def start_pose(pose):
    """The plant's initial-pose parameters x0, y0, z0, phi0 for `pose`."""
    return dict(zip(("x0", "y0", "z0", "phi0"), (float(v) for v in pose)))


START_P0 = start_pose(P0)
# Fixed-step RK4 inside the plant at the paper's step: one RK4 step per 1 ms
# communication step, deterministic and cheap.
RK4 = {"solver": 1, "rk4_step": STEP}
