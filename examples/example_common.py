"""What the examples share: the FMU paths, the spec's auto-test motion with a
free duration, the spec's geometry for drawing, logging on stderr, and the
CSV of a run that render_robot.py draws.

The FMUs are driven through python_checks/fmu_helpers.py (`Fmu`, the project's
thin fmpy wrapper), which this module puts on sys.path. Every constant comes
from ../shared/MODEL_SPEC.md (through fmu_helpers where it is there).
"""
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
_CHECKS = REPO / "python_checks"
if str(_CHECKS) not in sys.path:
    sys.path.insert(0, str(_CHECKS))

from fmu_helpers import ACC, F, M_PLATFORM, P0, P1, POSE, T_MOVE, VEL, Fmu, arr, blend  # noqa: E402,F401

PLANT_FMU = "PKM4PUU.fmu"
INVERSE_FMU = "PKM4PUU_Inverse.fmu"
H = 1e-3  # s: the paper's step, and the examples' communication / control period

RHO = arr("rho", 4)
DRHO = arr("drho", 4)
THETA1 = arr("theta1", 4)
THETA2 = arr("theta2", 4)
START_P0 = {"x0": P0[0], "y0": P0[1], "z0": P0[2], "phi0": P0[3]}
# Fixed-step RK4 at 1 ms inside the plant, as in the paper: one RK4 step per
# 1 ms communication step, deterministic and cheap (2.65 us a step).
RK4 = {"solver": 1, "rk4_step": H}


# --- the auto-test motion with a free duration T ----------------------------------
def motion(t, T=T_MOVE):
    """Pose, velocity and acceleration (each x, y, z, phi) of the spec's
    rest-to-rest quintic from P0 to P1 done in T seconds (the spec's T is 2 s),
    as one list of 12 values in the inverse FMU's input order POSE + VEL + ACC."""
    s, ds, dds = blend(t / T)
    d = P1 - P0
    return [*(P0 + d * s), *(d * ds / T), *(d * dds / T**2)]


def pose(t, T=T_MOVE):
    return np.array(motion(t, T)[:4])


# --- geometry of MODEL_SPEC ("Leg placement", "Geometry defaults") ------------------
GEOMETRY = {
    "h": 0.06634, "l": 0.080, "h_prime": 0.075, "r_b": 0.09273, "r_Q": 0.075,
    "beta": [i * math.pi / 2 for i in range(4)],
    "gamma": [math.radians(g) for g in (65.0, -65.0, 65.0, -65.0)],
}


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def mechanism_points(row, geo=GEOMETRY):
    """The points that draw the mechanism at one instant, in the base frame G.

    row: mapping with x, y, z, phi and rho[i], theta1[i], theta2[i] (i = 1..4).
    Returns a dict of arrays (4 x 3, one row per leg): B (base point of the
    prismatic axis), O2 (the slider's U joint at height rho + h on the axis),
    O3 = O2 + l x3 (the rod's far end), Q = O3 + h' z3 (the leg's end point,
    from the DH chain of Table I), and Qp = p + Rz(phi) r_Qi (the platform's
    attachment points from the pose); P (3,) the platform's centre. Q and Qp
    are the same points when the loop closes (Eq. 15)."""
    h, l, hp, rb, rq = (geo[k] for k in ("h", "l", "h_prime", "r_b", "r_Q"))
    p = np.array([row["x"], row["y"], row["z"]])
    Rphi = _rz(row["phi"])
    B, O2, O3, Q, Qp = (np.empty((4, 3)) for _ in range(5))
    for i in range(4):
        beta, gamma = geo["beta"][i], geo["gamma"][i]
        R = _rz(beta)
        rho, t1, t2 = row[f"rho[{i + 1}]"], row[f"theta1[{i + 1}]"], row[f"theta2[{i + 1}]"]
        c1, s1, c2, s2 = math.cos(t1), math.sin(t1), math.cos(t2), math.sin(t2)
        Bi = np.array([rb * math.cos(beta), rb * math.sin(beta), 0.0])
        x3 = np.array([c1 * c2, s1 * c2, s2])  # leg frame 0_i
        z3 = np.array([s1, -c1, 0.0])
        o2 = np.array([0.0, 0.0, rho + h])
        B[i] = Bi
        O2[i] = Bi + R @ o2
        O3[i] = Bi + R @ (o2 + l * x3)
        Q[i] = Bi + R @ (o2 + l * x3 + hp * z3)
        Qp[i] = p + Rphi @ np.array([rq * math.cos(beta + gamma), rq * math.sin(beta + gamma), 0.0])
    return {"B": B, "O2": O2, "O3": O3, "Q": Q, "Qp": Qp, "P": p}


# --- the CSV of a run -------------------------------------------------------------------
RUN_COLUMNS = POSE + RHO + THETA1 + THETA2


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


# --- command line ------------------------------------------------------------------------
class Log:
    """Progress on stderr, prefixed by the program's name and the elapsed time."""

    def __init__(self, prog):
        self.prog = prog
        self.t0 = time.perf_counter()

    def __call__(self, msg):
        print(f"{self.prog} [{time.perf_counter() - self.t0:6.1f} s]: {msg}", file=sys.stderr, flush=True)


def add_common_args(ap):
    ap.add_argument("--build", type=Path, default=REPO / "build",
                    help=f"directory holding {PLANT_FMU} and {INVERSE_FMU} (default: %(default)s)")
    ap.add_argument("--out", type=Path, default=REPO / "results",
                    help="directory for the CSV, PNG and GIF files (default: %(default)s)")


def find_fmus(build, log):
    """(plant, inverse) paths in `build`, or None after saying what is missing."""
    paths = [Path(build) / PLANT_FMU, Path(build) / INVERSE_FMU]
    missing = [str(q) for q in paths if not q.is_file()]
    if missing:
        log(f"error: {', '.join(missing)} not found: build the FMUs first "
            "(./scripts/build.sh builds them into build/) or pass --build DIR")
        return None
    return paths
