# SPDX-License-Identifier: BSD-2-Clause
"""The paper's auto-test (Fig. 4, docs/model.md "The paper's two tests") through the FMUs:
the inverse FMU turns the prescribed motion into F1..F4(t); the plant FMU,
driven open loop by those forces at a 1 ms communication step for 2 s, must
reproduce the prescribed pose.

How the master hands a continuous F(t) to the plant over each step decides
the accuracy; three ways are compared:

(a) midpoint: F held over [t, t+h] at F(t + h/2). The impulse over the step
    is exact to O(h^3), so the pose error is O(h^2).
(b) first order: F(t) at the step start plus a slope through
    fmi2SetRealInputDerivatives; the FMU ramps F(t) + dF (tau - t).
    See first_order_slope below for which slope and why.
(c) zero-order hold of F(t): the held force lags the true one by half a step
    on average, so every step's impulse is off by -h^2/2 dF/dt: an O(h) error,
    ~ (h/2) x velocity ~ 1e-5 m here.

This module holds the runner, the writers and the bounds (BOUNDS) that (a)
and (b) are held to, by the checks in test_fmu_autotest.py and by this
program's verdict. `pkm4puu autotest` is part of the main job
(run_autotest.sh): it runs every (input mode, solver) case, prints the table
of max errors and the checks against BOUNDS, exits 1 when one fails, and
writes to --out DIR:

  fmu_autotest.csv          position and phi error of every case over time
  fmu_autotest_checks.csv   the checks (checks.py)
  fmu_autotest_errors.png   the same, plotted
  fmu_autotest_pose.png     prescribed vs FMU-simulated x, y, z, phi
                            (midpoint input, CVODE)
  fmu_autotest_forces.png   F1..F4 from the inverse FMU

The figures need matplotlib (the extra `plots`); without it the CSV files
are written and a line says how to get the figures.
"""
import csv
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .. import plots
from ..fmu import Fmu, inverse_forces, run
from ..interface import ACC, F, POSE, START_P0, VEL
from ..motions import pose_at
from ..plots import pyplot, save_figure
from ..program import case_table, finish, run_cases, start_report
from ..spec import STEP as H, T_MOVE
from .checks import check, finish_checks, write_checks


N = round(T_MOVE / H)
SOLVERS = {"CVODE": {"solver": 0}, "RK4": {"solver": 1, "rk4_step": 1e-3}}
MODES = ("midpoint", "first_order", "zoh")
CASES = [(m, s) for m in MODES for s in SOLVERS]  # (input mode, solver), in the table's order
START = START_P0
# The case shown in fmu_autotest_pose.png.
POSE_PLOT_CASE = ("midpoint", "CVODE")


class Bounds(NamedTuple):
    """Bounds on the max errors of the runs in the input `modes`, with
    every solver."""
    position: float  # m
    phi: float  # rad
    modes: tuple


# (a) and (b) must reproduce the prescribed motion to these with both
# solvers; (c), the ZOH mode, lags by an O(h) error and is only required (by
# test_fmu_autotest.py) to be worse than the midpoint hold.
BOUNDS = Bounds(position=5e-8, phi=5e-8, modes=("midpoint", "first_order"))


class CaseResult:
    """One (mode, solver) run: communication times t (s), the plant's pose
    (x, y, z, phi) at those times, the prescribed pose there, and the errors:
    pos_err = |(x, y, z) - prescribed| (m), phi_err = |phi - prescribed| (rad)."""

    def __init__(self, t, pose, ref):
        self.t = t
        self.pose = pose
        self.ref = ref
        self.pos_err = np.linalg.norm(pose[:, :3] - ref[:, :3], axis=1)
        self.phi_err = np.abs(pose[:, 3] - ref[:, 3])

    def finite(self):
        return bool(np.all(np.isfinite(self.pos_err)) and np.all(np.isfinite(self.phi_err)))


# --- the forces from the inverse FMU -----------------------------------------
def half_step_times():
    """t = j h/2, j = 0 .. 2N: every step's start, midpoint and end."""
    return np.arange(2 * N + 1) * (H / 2)


def half_step_forces(inverse_fmu):
    """F1..F4 (N) from the inverse FMU on the prescribed motion at
    half_step_times(): row 2k is the step k's start, 2k+1 its midpoint."""
    with Fmu(inverse_fmu) as inv:
        return inverse_forces(inv, half_step_times())


def static_forces(inverse_fmu, times):
    """F1..F4 (N) that would hold the prescribed pose p(t) at rest (zero
    velocity and acceleration), from the inverse FMU: the part of the forces
    that is weight, not motion."""
    out = np.empty((len(times), 4))
    with Fmu(inverse_fmu) as inv:
        vr_in, vr_out = inv.vrs(POSE + VEL + ACC), inv.vrs(F)
        for i, t in enumerate(times):
            inv.fmu.setReal(vr_in, [*pose_at(t), *[0.0] * 8])
            out[i] = inv.fmu.getReal(vr_out)
    return out


# --- the three input modes -----------------------------------------------------
def first_order_slope(F0, Fm, F1):
    """Slope for mode (b) from F at the step's start, midpoint and end.

    With the value pinned to F(t) at the step start, the slope decides how
    well the ramp's impulse over [t, t+h] matches the true one:
      - (F1 - F0)/h, the secant (linear interpolation through the samples):
        impulse off by -h^3/12 F'' per step, twice the midpoint hold's error;
      - F'(t) itself (a central difference at t): off by +h^3/6 F'';
      - the slope that makes the ramp's mean equal Simpson's mean of F over
        the step, (F0 + 4 Fm + F1)/6, i.e. b = (4 Fm + F1 - 5 F0) / (3 h):
        impulse exact to O(h^5) and the first moment to O(h^4), so the
        input's contribution to the error drops well below the midpoint
        hold's. It is built from a central difference about the midpoint
        (Fm) and needs no sample beyond the step, so it is used here.
    With RK4 the input then adds next to nothing to the integrator's own
    error; with CVODE at its default rtol = 1e-8, CVODE's own error dominates.
    The secant, by the estimate above, doubles the midpoint hold's error and
    would leave CVODE at its defaults with little margin to the checks'
    position bound (test_fmu_autotest.py).
    """
    return (4.0 * Fm + F1 - 5.0 * F0) / (3.0 * H)


FIRST_ORDER_SLOPE = first_order_slope


def midpoint_input(Fh):
    """(a) F held over step k at F(t_k + h/2)."""
    def midpoint(fmu, k, t):
        fmu.set(F, Fh[2 * k + 1])
    return midpoint


def first_order_input(Fh):
    """(b) F(t_k) plus the slope of first_order_slope, through
    fmi2SetRealInputDerivatives."""
    def first_order(fmu, k, t):
        fmu.set(F, Fh[2 * k])
        fmu.set_derivatives(F, FIRST_ORDER_SLOPE(Fh[2 * k], Fh[2 * k + 1], Fh[2 * k + 2]))
    return first_order


def zoh_input(Fh):
    """(c) F held over step k at F(t_k)."""
    def zoh(fmu, k, t):
        fmu.set(F, Fh[2 * k])
    return zoh


INPUT_MODES = {"midpoint": midpoint_input, "first_order": first_order_input, "zoh": zoh_input}


def inputs(mode, Fh):
    """The master's input callback for run() in `mode`, from the half-step table Fh."""
    return INPUT_MODES[mode](Fh)


# --- running the cases ---------------------------------------------------------------
def run_case(plant_fmu, mode, solver, Fh):
    """Plant FMU from rest at P0, driven open loop by the half-step table Fh
    in input `mode` for N steps of H with `solver` (a key of SOLVERS)."""
    with Fmu(plant_fmu, start={**START, **SOLVERS[solver]}) as fmu:
        if mode == "first_order" and not fmu.md.coSimulation.canInterpolateInputs:
            raise RuntimeError(f"{Path(plant_fmu).name} does not declare canInterpolateInputs: "
                               "first-order input interpolation is not available")
        t, Y = run(fmu, 0.0, H, N, inputs(mode, Fh), POSE)
    return CaseResult(t, Y, np.array([pose_at(ti) for ti in t]))


def run_all(plant_fmu, Fh, log=None, errors=None):
    """Every (mode, solver) case: {(mode, solver): CaseResult}.

    log(message), when given, is told when each case starts and ends. When
    `errors` is a dict, a case that raises is recorded there as
    (mode, solver) -> exception and left out; otherwise the exception
    propagates."""
    return run_cases(CASES, lambda case: run_case(plant_fmu, *case, Fh), lambda case: "case {}/{}".format(*case),
                     log, errors, f"running {N} steps of {H * 1e3:g} ms",
                     lambda r: f", max position error {r.pos_err.max():.3e} m, max phi error {r.phi_err.max():.3e} rad")


def format_table(runs, errors=None, bounds=None):
    """The table of max errors, one row per case; with `bounds` (Bounds), the
    bound each case is held to."""
    def row(case, r):
        errors = f"{r.pos_err.max():13.3e} {r.phi_err.max():11.3e}"
        if bounds is None:
            return errors
        bound = (f"<= {bounds.position:g} m, <= {bounds.phi:g} rad" if case[0] in bounds.modes
                 else "above the midpoint hold's (O(h) lag)")
        return f"{errors}  {bound}"

    head = [f"FMU auto-test (paper section 5.1): inverse FMU -> F1..F4 -> plant FMU, open loop, "
            f"{H * 1e3:g} ms communication step, {T_MOVE:g} s: max errors",
            f"{'input mode':<12} {'solver':<6} {'position (m)':>13} {'phi (rad)':>11}"
            + ("  test bound" if bounds is not None else "")]
    return "\n".join(case_table(head, CASES, runs, errors, lambda case: "{:<12} {:<6}".format(*case), row))


def checks(runs, bounds=BOUNDS):
    """The Checks of the bounded cases' max errors against `bounds`."""
    out = []
    for mode, solver in CASES:
        if mode in bounds.modes and (mode, solver) in runs:
            r, case = runs[(mode, solver)], f"FMU auto-test {mode}/{solver}"
            out += [check(case, "max position error", r.pos_err.max(), bounds.position, "m"),
                    check(case, "max phi error", r.phi_err.max(), bounds.phi, "rad")]
    return out


# --- results ------------------------------------------------------------------------------
def write_csv(runs, path):
    """Position and phi error of every case over time, one column each."""
    t = runs[(MODES[0], "CVODE")].t
    keys = list(runs)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s"] + [f"{m}_{s}_{q}" for m, s in keys for q in ("pos_err_m", "phi_err_rad")])
        for i, ti in enumerate(t):
            w.writerow([f"{ti:.6f}"] + [f"{v[i]:.6e}" for k in keys for v in (runs[k].pos_err, runs[k].phi_err)])


def plot_errors(runs, path, bounds=None):
    """Position and phi error of every case over time; with `bounds`
    (Bounds), a line at each."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    for (m, s), r in runs.items():
        style = "-" if s == "CVODE" else "--"
        axes[0].semilogy(r.t, np.maximum(r.pos_err, 1e-18), style, label=f"{m}, {s}")
        axes[1].semilogy(r.t, np.maximum(r.phi_err, 1e-18), style, label=f"{m}, {s}")
    axes[0].set_ylabel("|p - p_prescribed| (m)")
    axes[1].set_ylabel("|phi - phi_prescribed| (rad)")
    axes[1].set_xlabel("time (s)")
    axes[0].set_title("Auto-test through the FMUs, open loop, 1 ms communication step")
    for ax, tol, unit in ((axes[0], bounds and bounds.position, "m"), (axes[1], bounds and bounds.phi, "rad")):
        if bounds is not None:
            ax.axhline(tol, color="k", lw=0.8, ls=":", label=f"test bound {tol:g} {unit}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=3)
    save_figure(fig, path)


def plot_pose(runs, path, case=POSE_PLOT_CASE):
    """Prescribed vs FMU-simulated x, y, z, phi for one case."""
    r = runs[case]
    m, s = case
    plots.plot_pose(
        r.t, r.ref, r.pose, "plant FMU p(t)",
        "Auto-test through the FMUs: prescribed motion and the plant FMU driven open loop\n"
        f"by the inverse FMU's forces ({m} input, {s}, {H * 1e3:g} ms step; max error "
        f"{r.pos_err.max():.1e} m, {r.phi_err.max():.1e} rad)", path)


def plot_forces(Fh, F_static, path):
    """F1..F4 from the inverse FMU at the half-step times, and their dynamic part."""
    plots.plot_forces(half_step_times(), Fh, F_static,
                               "Auto-test: actuator forces from the inverse FMU (PKM4PUU_Inverse)", path)


def write_results(runs, Fh, inverse_fmu, out_dir, bounds=None, figures=True):
    """Writes fmu_autotest.csv and, with `figures`, fmu_autotest_errors.png
    (with `bounds`, see plot_errors), fmu_autotest_pose.png and
    fmu_autotest_forces.png into out_dir (created if missing; files are
    overwritten). Returns their paths in that order."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [out_dir / n for n in ("fmu_autotest.csv", "fmu_autotest_errors.png",
                                   "fmu_autotest_pose.png", "fmu_autotest_forces.png")]
    write_csv(runs, paths[0])
    if not figures:
        return paths[:1]
    plot_errors(runs, paths[1], bounds)
    plot_pose(runs, paths[2])
    plot_forces(Fh, static_forces(inverse_fmu, half_step_times()), paths[3])
    return paths


# --- command line ---------------------------------------------------------------------------
def main(argv=None):
    args, log, fmus, figures = start_report(
        "autotest", "The paper's auto-test (section 5.1) through the FMUs: inverse FMU -> F1..F4 -> plant FMU, open "
        "loop, 1 ms communication step, 2 s.", "fmu_autotest.csv, fmu_autotest_checks.csv and, with matplotlib, "
        "fmu_autotest_errors.png, fmu_autotest_pose.png and fmu_autotest_forces.png", argv)
    if fmus is None:
        return 1
    plant, inverse = fmus
    log(f"inverse FMU {inverse}: F1..F4 at {2 * N + 1} half-step times")
    Fh = half_step_forces(inverse)
    errors = {}
    runs = run_all(plant, Fh, log=log, errors=errors)
    bad = [f"case {m}/{s}: non-finite pose" for m, s in sorted(k for k, r in runs.items() if not r.finite())]
    results = checks(runs)
    status = finish(log, format_table(runs, errors, BOUNDS), errors, bad, len(CASES), "cases",
                    lambda: [*write_results(runs, Fh, inverse, args.out, BOUNDS, figures),
                             write_checks(args.out / "fmu_autotest_checks.csv", results)])
    return finish_checks(status, results, log)
