# SPDX-License-Identifier: BSD-2-Clause
"""Figures: matplotlib on demand, and the auto-test's two standard figures,
shared by the C++ core's plots (pkm4puu plot-autotest) and the FMU run's
(pkm4puu autotest): actuator forces with their dynamic part (in the spirit
of the paper's Fig. 5) and prescribed versus simulated platform motion
(Fig. 6).

matplotlib is the package's optional extra `plots`: it is imported on the
first figure (pyplot()), not with the package; without it pyplot() raises
extras.MissingExtra saying how to install it."""
import math

import numpy as np

from . import extras


def available():
    """True when matplotlib is installed (the figures can be drawn)."""
    return not extras.missing("matplotlib")


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend, imported now."""
    matplotlib = extras.import_module("matplotlib", "the figures")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(fig, path, dpi=120):
    """Lays out, writes and closes a figure."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)


def plot_forces(t, F, F_static, title, path):
    """F1..F4 (columns of F, N) over t and, below, F minus the forces that
    would hold the same pose at rest (mN)."""
    F, F_static = np.asarray(F), np.asarray(F_static)
    fig, axes = pyplot().subplots(2, 1, figsize=(8, 6.5), sharex=True)
    for i in range(4):
        axes[0].plot(t, F[:, i], label=f"$F_{i + 1}$")
        axes[1].plot(t, 1e3 * (F[:, i] - F_static[:, i]), label=f"$F_{i + 1} - F_{{{i + 1},static}}$")
    axes[0].set_ylabel("actuator force (N)")
    axes[0].set_title(title)
    axes[1].set_ylabel("dynamic part (mN)")
    axes[1].set_title("minus the forces that hold the same pose at rest", fontsize=9)
    axes[1].set_xlabel("time (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", ncol=4, fontsize=8)
    save_figure(fig, path)


def plot_pose(t, ref, sim, sim_label, title, path):
    """Prescribed (ref) and simulated (sim) x, y, z, phi: arrays of shape (n, 4)."""
    ref, sim = np.asarray(ref), np.asarray(sim)
    fig, axes = pyplot().subplots(2, 2, figsize=(9, 6.5), sharex=True)
    specs = [(0, 1e3, "x (mm)"), (1, 1e3, "y (mm)"), (2, 1e3, "z (mm)"), (3, 180 / math.pi, "phi (deg)")]
    for ax, (j, scale, label) in zip(axes.flat, specs):
        ax.plot(t, scale * ref[:, j], "k-", lw=3, alpha=0.35, label="prescribed p'(t)")
        ax.plot(t, scale * sim[:, j], "C3--", lw=1.2, label=sim_label)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="best", fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    fig.suptitle(title, fontsize=10)
    save_figure(fig, path)
