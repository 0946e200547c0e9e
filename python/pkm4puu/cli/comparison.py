# SPDX-License-Identifier: BSD-2-Clause
"""The paper's comparison test (section 5.2, docs/model.md "The paper's two tests")
through the plant FMU: 1.5 s from rest at P0, gravity off, F2 = F3 = 0,
F1(t) = 0.02 N sin(2 pi t / 1.5 s) = -F4(t), midpoint-held at a 1 ms step.

This module holds the runner, the quantities the checks look at, their
bounds (BOUNDS) and the result writers; the checks are in
test_fmu_comparison.py and in this program's verdict. `pkm4puu comparison`
is part of the main job (run_autotest.sh): it runs the plant FMU with CVODE and
with RK4, prints the table of the quantities below and the checks against
BOUNDS, exits 1 when one fails, and writes to --out DIR:

  comparison.csv             platform pose, rho1..rho4 and delta rho1 (CVODE)
  comparison_checks.csv      the checks (checks.py)
  comparison_pose.png        platform pose over time (the paper's Figs. 9-10)
  comparison_delta_rho1.png  displacement of actuator 1 (the paper's Fig. 11)

The quantities (each bounded, BOUNDS):
- max ||C(q)||, the loop-closure residual the FMU reports;
- the drift of the machine's vertical centre of mass: with g = 0 the only
  vertical forces are the actuator forces and F1 + F4 = 0, so from rest it
  must stay put;
- CVODE vs RK4: two different integrators must agree;
- max |delta rho1|: the motion must be non-trivial.

The figures need matplotlib (the extra `plots`); without it the CSV files
are written and a line says how to get the figures.
"""
import csv
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..fmu import Fmu, run
from ..interface import F, POSE, START_P0, indexed_names
from ..motions import comparison_forces
from ..plots import pyplot, save_figure
from ..program import case_table, finish, run_cases, start_report
from ..spec import CMP_AMPLITUDE, CMP_DURATION, L as L_ROD, M_PLATFORM, M_ROD, M_SLIDER, STEP
from .checks import check, finish_checks, write_checks

H = STEP
N = round(CMP_DURATION / H)
OUT = POSE + indexed_names("rho", 4) + indexed_names("theta2", 4) + ["constraint_residual"]
START = {"g": 0.0, **START_P0}
# Integrators. RK4 at 1 ms is the paper's. CVODE's rtol bounds only the local
# error of each internal step, relative to |y| (~0.05 m, and phi swings to
# ~0.15 rad here); the FMU restarts CVODE at every 1 ms step, so over 1500
# steps of undamped motion these local errors add up to a global error of the
# order of 1e-8 m at the default rtol = 1e-8: the checks' bound on the
# solvers' agreement (test_fmu_comparison.py). Agreement within it only
# means something when each integrator is well inside it, so CVODE runs at
# rtol = 1e-10 (atol scaled alike, 1e-12).
SOLVERS = {"CVODE": {"solver": 0, "rtol": 1e-10, "atol": 1e-12}, "RK4": {"solver": 1, "rk4_step": 1e-3}}


class Bounds(NamedTuple):
    """The bounds the runs are held to, shown in the table."""
    position: float  # m, CVODE vs RK4 and the vertical centre of mass's drift
    phi: float  # rad, CVODE vs RK4
    constraint: float  # m, max ||C(q)||
    min_delta_rho1: float  # m, the least max |delta rho1| of a non-trivial motion


BOUNDS = Bounds(position=1e-8, phi=1e-7, constraint=1e-12,
                min_delta_rho1=1e-5)  # below this the forces barely moved the machine


def midpoint_held(fmu, k, t):
    fmu.set(F, comparison_forces(t + H / 2))


# --- running ---------------------------------------------------------------------------
def run_solver(plant_fmu, solver):
    """The comparison test with `solver` (a key of SOLVERS): {"t": times,
    name: values at those times for each name in OUT}."""
    with Fmu(plant_fmu, start={**START, **SOLVERS[solver]}) as fmu:
        t, Y = run(fmu, 0.0, H, N, midpoint_held, OUT)
    return {"t": t, **{n: Y[:, i] for i, n in enumerate(OUT)}}


def run_all(plant_fmu, log=None, errors=None):
    """{solver: run_solver(...)} for every solver. log(message), when given, is
    told when each run starts and ends. When `errors` is a dict, a run that
    raises is recorded there (solver -> exception) and left out; otherwise
    the exception propagates."""
    return run_cases(SOLVERS, lambda name: run_solver(plant_fmu, name), str, log, errors,
                     f"running {N} steps of {H * 1e3:g} ms")


# --- what the checks look at ---------------------------------------------------------------
def nonfinite_outputs(r):
    """Names of the outputs that are not finite at every point."""
    return [n for n in OUT if not np.all(np.isfinite(r[n]))]


def max_constraint_residual(r):
    """max ||C(q)|| (m) over the run."""
    return r["constraint_residual"].max()


def delta_rho1(r):
    """rho1(t) - rho1(0) (m)."""
    return r["rho[1]"] - r["rho[1]"][0]


def max_delta_rho1(r):
    return np.abs(delta_rho1(r)).max()


def vertical_com_drift(r):
    """Largest change (m) of the machine's vertical centre of mass,
    (m_p z + sum(m_s rho_i + m_r z_rod_i)) / m_total with
    z_rod_i = rho_i + h + (l/2) sin(theta2_i) (the constant h dropped)."""
    rods = sum(r[f"rho[{i}]"] + 0.5 * L_ROD * np.sin(r[f"theta2[{i}]"]) for i in range(1, 5))
    sliders = sum(r[f"rho[{i}]"] for i in range(1, 5))
    z_weighted = M_PLATFORM * r["z"] + M_SLIDER * sliders + M_ROD * rods  # + a constant
    return np.abs(z_weighted - z_weighted[0]).max() / (M_PLATFORM + 4 * (M_SLIDER + M_ROD))


def solver_difference(a, b):
    """(largest |a - b| over x, y, z, rho1..rho4 (m), largest |a - b| of phi (rad))."""
    d_pos = max(np.abs(a[n] - b[n]).max() for n in ["x", "y", "z"] + indexed_names("rho", 4))
    d_phi = np.abs(a["phi"] - b["phi"]).max()
    return d_pos, d_phi


def checks(runs, bounds=BOUNDS):
    """The Checks of every run's constraint residual and centre-of-mass
    drift, of CVODE's motion being non-trivial and of CVODE vs RK4, against
    `bounds`."""
    out = []
    for name, r in runs.items():
        out += [check(f"comparison {name}", "max ||C(q)||", max_constraint_residual(r), bounds.constraint, "m"),
                check(f"comparison {name}", "vertical COM drift", vertical_com_drift(r), bounds.position, "m")]
    if "CVODE" in runs:
        out.append(check("comparison CVODE", "max |delta rho1|", max_delta_rho1(runs["CVODE"]),
                         bounds.min_delta_rho1, "m", relation=">"))
    if "CVODE" in runs and "RK4" in runs:
        d_pos, d_phi = solver_difference(runs["CVODE"], runs["RK4"])
        out += [check("comparison CVODE vs RK4", "max |delta position|", d_pos, bounds.position, "m"),
                check("comparison CVODE vs RK4", "max |delta phi|", d_phi, bounds.phi, "rad")]
    return out


def format_table(runs, errors=None, bounds=None):
    """The table of max errors per solver and of CVODE vs RK4; with `bounds`
    (Bounds), the bound on each."""
    head = [f"FMU comparison test (paper section 5.2): plant FMU, g = 0, F1 = -F4 = {CMP_AMPLITUDE:g} N "
            f"sin(2 pi t / {CMP_DURATION:g} s), F2 = F3 = 0, {H * 1e3:g} ms communication step, {CMP_DURATION:g} s",
            f"{'solver':<6} {'max ||C(q)|| (m)':>17} {'vertical COM drift (m)':>23} {'max |delta rho1| (m)':>21}"]
    lines = case_table(head, SOLVERS, runs, errors, lambda name: f"{name:<6}",
                       lambda name, r: f"{max_constraint_residual(r):17.3e} {vertical_com_drift(r):23.3e} "
                                       f"{max_delta_rho1(r):21.4e}")
    if bounds is not None:
        lines.append(f"{'bound':<6} {'<= ' + format(bounds.constraint, 'g'):>17} "
                     f"{'<= ' + format(bounds.position, 'g'):>23} {'> ' + format(bounds.min_delta_rho1, 'g'):>21}")
    if "CVODE" in runs and "RK4" in runs:
        d_pos, d_phi = solver_difference(runs["CVODE"], runs["RK4"])
        pos_bound, phi_bound = ((f" (bound {bounds.position:g} m)", f" (bound {bounds.phi:g} rad)")
                                if bounds is not None else ("", ""))
        lines.append(f"CVODE vs RK4: max |delta position| {d_pos:.3e} m{pos_bound}, "
                     f"max |delta phi| {d_phi:.3e} rad{phi_bound}")
    return "\n".join(lines)


# --- results ------------------------------------------------------------------------------------
def write_results(runs, out_dir, figures=True):
    """Writes comparison.csv and, with `figures`, comparison_pose.png and
    comparison_delta_rho1.png (from the CVODE run) into out_dir (created if
    missing; files are overwritten). Returns their paths in that order."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    r = runs["CVODE"]
    t = r["t"]
    d_rho1 = delta_rho1(r)
    cols = ["x", "y", "z", "phi"] + indexed_names("rho", 4)
    csv_path = out_dir / "comparison.csv"
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "x", "y", "z", "phi", "rho1", "rho2", "rho3", "rho4", "delta_rho1"])
        for i in range(len(t)):
            w.writerow([f"{t[i]:.6f}"] + [f"{r[c][i]:.12e}" for c in cols] + [f"{d_rho1[i]:.12e}"])
    if not figures:
        return [csv_path]

    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(9, 6), sharex=True)
    for ax, name, scale, unit in zip(axes.flat, POSE, (1e3, 1e3, 1e3, 180 / math.pi), ("mm", "mm", "mm", "deg")):
        ax.plot(t, scale * r[name])
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Comparison test through the plant FMU: platform pose (CVODE, 1 ms step)\n"
                 "g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), F2 = F3 = 0", fontsize=11)
    pose_png = out_dir / "comparison_pose.png"
    save_figure(fig, pose_png)

    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, 1e3 * d_rho1)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("delta rho1 (mm)")
    ax.set_title("Comparison test through the plant FMU: displacement of actuator 1 (CVODE)")
    ax.grid(True, alpha=0.3)
    rho_png = out_dir / "comparison_delta_rho1.png"
    save_figure(fig, rho_png)
    return [csv_path, pose_png, rho_png]


# --- command line ---------------------------------------------------------------------------
def main(argv=None):
    args, log, fmus, figures = start_report(
        "comparison", "The paper's comparison test (section 5.2) through the plant FMU, with CVODE and with RK4.",
        "comparison.csv, comparison_checks.csv and, with matplotlib, comparison_pose.png and "
        "comparison_delta_rho1.png", argv, models=("PKM4PUU",))
    if fmus is None:
        return 1
    plant = fmus[0]
    errors = {}
    runs = run_all(plant, log=log, errors=errors)
    bad = [f"{name}: non-finite outputs {nonfinite_outputs(r)}" for name, r in runs.items() if nonfinite_outputs(r)]
    results = checks(runs)
    status = finish(log, format_table(runs, errors, BOUNDS), errors, bad, len(SOLVERS), "runs",
                    lambda: [*write_results(runs, args.out, figures),
                             write_checks(args.out / "comparison_checks.csv", results)])
    return finish_checks(status, results, log)
