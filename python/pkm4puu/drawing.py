# SPDX-License-Identifier: BSD-2-Clause
"""The mechanism drawn: its points at one instant from the FMU's outputs, and
the CSV of a run that examples/render_robot.py draws."""
import csv
import math
from pathlib import Path

import numpy as np

from .interface import RUN_COLUMNS
from .spec import BETA, H, H_PRIME, L, base_point, platform_point, rz


# --- the mechanism's points ---------------------------------------------------------
def mechanism_points(row):
    """The points that draw the mechanism at one instant, in the base frame G.

    row: mapping with x, y, z, phi and rho[i], theta1[i], theta2[i] (i = 1..4).
    Returns a dict of arrays (4 x 3, one row per leg): B (base point of the
    prismatic axis), O2 (the slider's U joint at height rho + h on the axis),
    O3 = O2 + l x3 (the rod's far end), Q = O3 + h' z3 (the leg's end point,
    from the DH chain of Table I), and Qp = p + Rz(phi) r_Qi (the platform's
    attachment points from the pose); P (3,) the platform's centre. Q and Qp
    are the same points when the loop closes (Eq. 15)."""
    p = np.array([row["x"], row["y"], row["z"]])
    Rphi = rz(row["phi"])
    B, O2, O3, Q, Qp = (np.empty((4, 3)) for _ in range(5))
    for i in range(4):
        R = rz(BETA[i])
        rho, t1, t2 = row[f"rho[{i + 1}]"], row[f"theta1[{i + 1}]"], row[f"theta2[{i + 1}]"]
        c1, s1, c2, s2 = math.cos(t1), math.sin(t1), math.cos(t2), math.sin(t2)
        Bi = base_point(i)
        x3 = np.array([c1 * c2, s1 * c2, s2])  # leg frame 0_i
        z3 = np.array([s1, -c1, 0.0])
        o2 = np.array([0.0, 0.0, rho + H])
        B[i] = Bi
        O2[i] = Bi + R @ o2
        O3[i] = Bi + R @ (o2 + L * x3)
        Q[i] = Bi + R @ (o2 + L * x3 + H_PRIME * z3)
        Qp[i] = p + Rphi @ platform_point(i)
    return {"B": B, "O2": O2, "O3": O3, "Q": Q, "Qp": Qp, "P": p}


# --- the CSV of a run -------------------------------------------------------------------

def write_run_csv(path, t, Y, columns=RUN_COLUMNS):
    """t (n,) and Y (n, len(columns)) as a CSV with a header t_s, columns..."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s", *columns])
        for ti, yi in zip(t, Y):
            w.writerow([f"{ti:.6f}", *(f"{v:.12e}" for v in yi)])
    return path


def read_run_csv(path):
    """A run CSV as (t array, list of row dicts keyed by the column names)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no rows")
    missing = [c for c in ["t_s", *RUN_COLUMNS] if c not in rows[0]]
    if missing:
        raise ValueError(f"{path}: missing columns {missing}")
    t = np.array([float(r["t_s"]) for r in rows])
    return t, [{k: float(v) for k, v in r.items()} for r in rows]
