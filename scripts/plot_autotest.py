#!/usr/bin/env python3
"""Plots of the auto-test (paper section 5.1) from the CSV files written by
pkm_autotest: actuator forces (in the spirit of the paper's Fig. 5), the
prescribed and simulated platform motion (Fig. 6) and the round-trip error.

usage: plot_autotest.py RESULTS_DIR
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {name: data[name] for name in data.dtype.names}


def plot_forces(d, out):
    fig, axes = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True)
    t = d["t_s"]
    for i in range(1, 5):
        axes[0].plot(t, d[f"F{i}_N"], label=f"$F_{i}$")
        axes[1].plot(t, 1e3 * (d[f"F{i}_N"] - d[f"F{i}_static_N"]), label=f"$F_{i} - F_{{{i},static}}$")
    axes[0].set_ylabel("actuator force (N)")
    axes[0].set_title("Auto-test: actuator forces from inverse dynamics (Eqs. 10-11)")
    axes[1].set_ylabel("dynamic part (mN)")
    axes[1].set_title("minus the forces that hold the same pose at rest", fontsize=9)
    axes[1].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", ncol=4, fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_pose(d, out):
    fig, axes = plt.subplots(2, 2, figsize=(9, 6.5), sharex=True)
    t = d["t_s"]
    specs = [("x", 1e3, "x (mm)"), ("y", 1e3, "y (mm)"), ("z", 1e3, "z (mm)"), ("phi", 180 / np.pi, "phi (deg)")]
    unit = {"x": "m", "y": "m", "z": "m", "phi": "rad"}
    for ax, (name, scale, label) in zip(axes.flat, specs):
        ax.plot(t, scale * d[f"{name}_ref_{unit[name]}"], "k-", lw=3, alpha=0.35, label="prescribed p'(t)")
        ax.plot(t, scale * d[f"{name}_{unit[name]}"], "C3--", lw=1.2, label="forward dynamics p(t)")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="best", fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Auto-test: prescribed motion and forward dynamics driven by the computed forces")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def plot_errors(runs, out):
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
    for ax in axes:
        ax.axhline(1e-10, color="k", ls=":", lw=1, label="test bound 1e-10")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    res = Path(sys.argv[1])
    runs = []
    for name, label in (("rk4", "RK4, h = 1 ms"), ("cvode", "CVODE Adams, rtol 1e-12")):
        path = res / f"autotest_{name}.csv"
        if path.exists():
            runs.append((label, load(path)))
    if not runs:
        print(f"plot_autotest: no autotest_*.csv in {res}", file=sys.stderr)
        return 1
    first = runs[0][1]
    plot_forces(first, res / "autotest_forces.png")
    plot_pose(first, res / "autotest_pose.png")
    plot_errors(runs, res / "autotest_errors.png")
    for f in ("autotest_forces.png", "autotest_pose.png", "autotest_errors.png"):
        print(f"wrote {res / f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
