# SPDX-License-Identifier: BSD-2-Clause
"""Plots of the auto-test (paper section 5.1) from the CSV files written by
pkm_autotest: actuator forces (in the spirit of the paper's Fig. 5), the
prescribed and simulated platform motion (Fig. 6) and the round-trip error.

It needs matplotlib (the extra `plots`).
"""
import sys

import numpy as np

from .. import extras
from ..plots import plot_forces, plot_pose, pyplot, save_figure
from ..program import ArgumentParser, command_prog, writable_dir
from .checks import read_rows


# The quantities of pkm_autotest's checks drawn with their bounds.
POSITION, PHI = "max position error", "max phi error"


def load(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {name: data[name] for name in data.dtype.names}


def unit(name):
    return "rad" if name == "phi" else "m"


def pose_columns(d, suffix):
    return np.stack([d[f"{n}{suffix}_{unit(n)}"] for n in ("x", "y", "z", "phi")], axis=1)


def bounds(results):
    """{quantity: bound} of the position and phi errors, from the checks
    pkm_autotest wrote beside its CSV files (autotest_checks.csv); empty
    when there is no such file."""
    path = results / "autotest_checks.csv"
    rows = read_rows(path) if path.exists() else []
    return {r["quantity"]: float(r["bound"]) for r in rows if r["quantity"] in (POSITION, PHI)}


def plot_errors(runs, out, bound=None):
    """Position and phi error of each run over time; with `bound` ({quantity:
    bound}, see bounds()), a line at each."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for label, d in runs:
        t = d["t_s"]
        pos = np.max(np.abs(np.stack([d["x_m"] - d["x_ref_m"], d["y_m"] - d["y_ref_m"], d["z_m"] - d["z_ref_m"]])), axis=0)
        ang = np.abs(d["phi_rad"] - d["phi_ref_rad"])
        axes[0].semilogy(t, np.maximum(pos, 1e-18), label=label)
        axes[1].semilogy(t, np.maximum(ang, 1e-18), label=label)
    axes[0].set_ylabel("max |position error| (m)")
    axes[1].set_ylabel("|phi error| (rad)")
    axes[1].set_xlabel("time (s)")
    axes[0].set_title("Auto-test round trip: |p(t) - p'(t)|, open loop")
    for ax, quantity in zip(axes, (POSITION, PHI)):
        if quantity in (bound or {}):
            ax.axhline(bound[quantity], color="k", ls=":", lw=1, label=f"test bound {bound[quantity]:g}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    save_figure(fig, out)


def main(argv=None):
    ap = ArgumentParser(prog=command_prog("plot-autotest"),
                        description="Plots of the C++ auto-test (pkm_autotest --out RESULTS_DIR) from its "
                        "autotest_*.csv files: autotest_forces.png, autotest_pose.png and "
                        "autotest_errors.png, written beside them.")
    ap.add_argument("results", type=lambda text: writable_dir(text, must_exist=True), metavar="RESULTS_DIR",
                    help="the directory holding autotest_*.csv, where the figures go")
    res = ap.parse_args(argv).results
    extras.require(ap.prog, "matplotlib")
    runs = []
    for name, label in (("rk4", "RK4, h = 1 ms"), ("cvode", "CVODE Adams, rtol 1e-12")):
        path = res / f"autotest_{name}.csv"
        if path.exists():
            runs.append((label, load(path)))
    if not runs:
        print(f"{ap.prog}: error: no autotest_*.csv in {res}", file=sys.stderr)
        return 1
    first = runs[0][1]
    t = first["t_s"]
    F = np.stack([first[f"F{i}_N"] for i in range(1, 5)], axis=1)
    F_static = np.stack([first[f"F{i}_static_N"] for i in range(1, 5)], axis=1)
    plot_forces(t, F, F_static, "Auto-test: actuator forces from inverse dynamics (Eqs. 10-11)",
                res / "autotest_forces.png")
    plot_pose(t, pose_columns(first, "_ref"), pose_columns(first, ""), "forward dynamics p(t)",
              "Auto-test: prescribed motion and forward dynamics driven by the computed forces",
              res / "autotest_pose.png")
    plot_errors(runs, res / "autotest_errors.png", bounds(res))
    for f in ("autotest_forces.png", "autotest_pose.png", "autotest_errors.png"):
        print(f"wrote {res / f}")
    return 0
