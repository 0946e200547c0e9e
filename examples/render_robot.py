# SPDX-License-Identifier: BSD-2-Clause
"""Seeing the robot move: a 3-D drawing of the mechanism (base, the four
prismatic axes, sliders, rods, the h' offsets and the platform) from a CSV of a
run, as an animated GIF and as a still of several frames (like the paper's
Fig. 7).

Every point is computed from the CSV's joint values and pose with
docs/model.md's formulas (pkm4puu.drawing.mechanism_points): the legs from the DH
chain of Table I (slider's U joint O2 at height rho + h on the prismatic axis
through B_i, rod to O3 = O2 + l x3, offset h' along z3 to the leg's end Q_i),
the platform from the pose (p + Rz(phi) r_Qi). The two meet where the loop
closes, which the drawing shows and test_examples_render.py checks.

The CSV has the columns t_s, x, y, z, phi, rho[1..4], theta1[1..4],
theta2[1..4] (pkm4puu.drawing.write_run_csv; closed_loop_control.py writes one
as closed_loop_run.csv). Without --csv, the auto-test is run through the FMUs
first (the inverse FMU's forces, held at each 1 ms step's midpoint, drive the
plant open loop) and written as robot_run.csv.

Writes to --out DIR: robot_run.csv (without --csv), robot_motion.gif,
robot_frames.png.

usage: render_robot.py [--build DIR] [--out DIR] [--csv RUN.csv] [--frames N] [--fps N] [--size PX]
"""
import argparse
import math
import sys
from pathlib import Path

import matplotlib
import numpy as np

from pkm4puu.program import add_common_args, find_fmus, Log
from pkm4puu.drawing import mechanism_points, read_run_csv, RUN_COLUMNS, write_run_csv
from pkm4puu.fmu import Fmu
from pkm4puu.interface import ACC, F, POSE, RK4, START_P0, VEL
from pkm4puu.motions import motion
from pkm4puu.spec import STEP as H, T_MOVE
from pkm4puu.spec import R_B

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402

LEG_COLOURS = ("C0", "C1", "C2", "C3")
XY_LIM = 0.125  # m: the view box, fixed for every frame so that frames compare
Z_TOP = 0.16  # m: top of the drawn prismatic guides and of the view box
VIEW = {"elev": 26.0, "azim": -62.0}


# --- a run to draw ------------------------------------------------------------------------
def autotest_run(plant_fmu, inverse_fmu, T=T_MOVE, t_end=None, h=H):
    """The auto-test through the FMUs with a motion of duration T: the inverse
    FMU's forces at each step's midpoint, held over the step, drive the plant
    (RK4, 1 ms) open loop from rest at P0. Returns (t, Y) with Y's columns
    RUN_COLUMNS, one row per communication point up to t_end (default T)."""
    n = round((T if t_end is None else t_end) / h)
    t = np.arange(n + 1) * h
    Y = np.empty((n + 1, len(RUN_COLUMNS)))
    with Fmu(inverse_fmu, instance_name="inverse") as inv, \
            Fmu(plant_fmu, start={**START_P0, **RK4}, instance_name="plant") as plant:
        vr_in, vr_F = inv.vrs(POSE + VEL + ACC), inv.vrs(F)
        vr_out, vr_plant_F = plant.vrs(RUN_COLUMNS), plant.vrs(F)
        Y[0] = plant.fmu.getReal(vr_out)
        for k in range(n):
            inv.fmu.setReal(vr_in, motion(t[k] + h / 2, T))
            plant.fmu.setReal(vr_plant_F, inv.fmu.getReal(vr_F))
            plant.do_step(t[k], h)
            Y[k + 1] = plant.fmu.getReal(vr_out)
    return t, Y


def rows_from_array(Y, columns=RUN_COLUMNS):
    return [dict(zip(columns, y)) for y in Y]


# --- drawing -----------------------------------------------------------------------------------
def _setup_axes(ax, title=None):
    ax.set_xlim(-XY_LIM, XY_LIM)
    ax.set_ylim(-XY_LIM, XY_LIM)
    ax.set_zlim(0.0, Z_TOP)
    ax.set_box_aspect((2 * XY_LIM, 2 * XY_LIM, Z_TOP), zoom=1.05)
    ax.view_init(**VIEW)
    ax.set_proj_type("ortho")  # no perspective: equal lengths look equal at any depth
    mm = matplotlib.ticker.FuncFormatter(lambda v, _: f"{1e3 * v:.0f}")
    for axis, name in ((ax.xaxis, "x"), (ax.yaxis, "y"), (ax.zaxis, "z")):
        axis.set_major_locator(matplotlib.ticker.MultipleLocator(0.05))
        axis.set_major_formatter(mm)
        axis.set_label_text(f"{name} (mm)", fontsize=7)
        axis.labelpad = -8
    ax.tick_params(labelsize=6, pad=-3)
    if title:
        ax.set_title(title, fontsize=8, pad=0)


def _platform_outline(pts):
    return np.vstack([pts["Qp"], pts["Qp"][:1]])


def draw(ax, row, ghost=None, trace=None, title=None):
    """Draws the mechanism at `row` (a dict with RUN_COLUMNS) on a 3-D axes.
    ghost: another row whose platform is drawn faintly (e.g. the start pose);
    trace: (n, 3) path of P drawn dotted."""
    pts = mechanism_points(row)
    _setup_axes(ax, title)
    # base: the circle through the prismatic axes, and the axes themselves
    a = np.linspace(0.0, 2 * math.pi, 73)
    rb = R_B
    ax.plot(rb * np.cos(a), rb * np.sin(a), 0.0 * a, color="0.35", lw=1.2)
    ax.add_collection3d(_poly([np.c_[rb * np.cos(a), rb * np.sin(a), 0.0 * a]], "0.85", 0.5))
    for i in range(4):
        B = pts["B"][i]
        ax.plot([B[0], B[0]], [B[1], B[1]], [0.0, Z_TOP], color="0.45", lw=1.0, ls="-")
    if ghost is not None:
        g = _platform_outline(mechanism_points(ghost))
        ax.plot(g[:, 0], g[:, 1], g[:, 2], color="0.6", lw=0.9, ls="--")
    if trace is not None:
        ax.plot(trace[:, 0], trace[:, 1], trace[:, 2], color="k", lw=0.8, ls=":")
    # legs: slider at O2, rod O2 -> O3, offset h' O3 -> Q
    for i in range(4):
        c = LEG_COLOURS[i]
        O2, O3, Q = pts["O2"][i], pts["O3"][i], pts["Q"][i]
        ax.plot([O2[0]] * 2, [O2[1]] * 2, [O2[2] - 0.008, O2[2] + 0.008], color=c, lw=5.0,
                solid_capstyle="butt")
        ax.plot([O2[0], O3[0]], [O2[1], O3[1]], [O2[2], O3[2]], color=c, lw=2.4)
        ax.plot([O3[0], Q[0]], [O3[1], Q[1]], [O3[2], Q[2]], color=c, lw=1.2)
        ax.scatter(*O3, color=c, s=6, depthshade=False)
    # platform: polygon through the attachment points, its centre and a heading mark
    outline = _platform_outline(pts)
    ax.add_collection3d(_poly([pts["Qp"]], "C7", 0.35))
    ax.plot(outline[:, 0], outline[:, 1], outline[:, 2], color="k", lw=1.5)
    P = pts["P"]
    head = P + 0.05 * np.array([math.cos(row["phi"]), math.sin(row["phi"]), 0.0])
    ax.plot([P[0], head[0]], [P[1], head[1]], [P[2], head[2]], color="C3", lw=1.6)
    ax.scatter(*P, color="k", s=10, depthshade=False)
    return pts


def _poly(verts, colour, alpha):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    return Poly3DCollection(verts, facecolors=colour, alpha=alpha, edgecolors="none")


def _frame_title(t, row):
    return (f"t = {t:.2f} s   z = {1e3 * row['z']:.1f} mm   "
            f"phi = {math.degrees(row['phi']):.2f} deg")


def frame_image(row, size_px=240, t=None, ghost=None):
    """One frame rendered off-screen, as an (H, W, 4) uint8 RGBA array."""
    dpi = 100
    fig = plt.figure(figsize=(size_px / dpi, size_px / dpi), dpi=dpi)
    try:
        ax = fig.add_subplot(projection="3d")
        draw(ax, row, ghost=ghost, title=None if t is None else _frame_title(t, row))
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba()).copy()
    finally:
        plt.close(fig)


def pick(t, n):
    """Indices of n rows at evenly spaced times from t[0] to t[-1]."""
    targets = np.linspace(t[0], t[-1], n)
    return [int(np.argmin(np.abs(t - x))) for x in targets]


def write_gif(t, rows, path, n_frames=51, fps=25, size_px=400, hold=12, log=None):
    """Animated GIF of n_frames evenly spaced in time (the last one held for
    `hold` more frames, so a viewer sees where the motion ends)."""
    idx = pick(t, n_frames)
    idx = idx + [idx[-1]] * hold
    trace = np.array([[r["x"], r["y"], r["z"]] for r in rows])
    dpi = 100
    fig = plt.figure(figsize=(size_px / dpi, size_px / dpi), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.02, top=0.95)

    def update(j):
        k = idx[j]
        ax.cla()
        draw(ax, rows[k], ghost=rows[0], trace=trace[: k + 1], title=_frame_title(t[k], rows[k]))
        if log and j % 20 == 0:
            log(f"  GIF frame {j + 1}/{len(idx)}")
        return []

    anim = FuncAnimation(fig, update, frames=len(idx), blit=False)
    try:
        anim.save(path, writer=PillowWriter(fps=fps))
    finally:
        plt.close(fig)
    return path


def write_still(t, rows, path, n_frames=4):
    """Several frames side by side (like the paper's Fig. 7), with the start
    pose's platform dashed in every frame and P's path so far dotted."""
    idx = pick(t, n_frames)
    trace = np.array([[r["x"], r["y"], r["z"]] for r in rows])
    fig = plt.figure(figsize=(3.6 * n_frames, 3.8))
    for j, k in enumerate(idx):
        ax = fig.add_subplot(1, n_frames, j + 1, projection="3d")
        draw(ax, rows[k], ghost=rows[0] if k else None, trace=trace[: k + 1],
             title=_frame_title(t[k], rows[k]).replace("   z", "\nz"))
    fig.suptitle("4-PUU robot along the auto-test: P0 = (0, 0, 50 mm, 0) to P1 = (5, -5, 70 mm, 4 deg) in "
                 f"{t[-1] - t[0]:g} s (dashed: the platform at the start; red: platform heading phi)",
                 fontsize=9, y=0.985)
    fig.subplots_adjust(left=0.0, right=0.965, bottom=0.01, top=0.83, wspace=0.1)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def closure_error(rows):
    """max |Q_i (from the legs' joints) - (p + Rz(phi) r_Qi) (from the pose)| over rows (m)."""
    return max(float(np.abs(pts["Q"] - pts["Qp"]).max())
               for pts in (mechanism_points(r) for r in rows))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="render_robot", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "robot_run.csv (without --csv), robot_motion.gif and robot_frames.png")
    ap.add_argument("--csv", type=Path, help="a run CSV to draw (default: run the auto-test through the FMUs)")
    ap.add_argument("--frames", type=int, default=51, help="GIF frames over the run (default %(default)s)")
    ap.add_argument("--fps", type=int, default=25, help="GIF frames per second (default %(default)s)")
    ap.add_argument("--size", type=int, default=400, help="GIF width and height in pixels (default %(default)s)")
    args = ap.parse_args(argv)
    log = Log("render_robot")
    args.out.mkdir(parents=True, exist_ok=True)
    try:
        if args.csv is None:
            fmus = find_fmus(args.build, log)
            if fmus is None:
                return 1
            log("running the auto-test through the FMUs (2 s at 1 ms)")
            t, Y = autotest_run(*fmus)
            csv_path = write_run_csv(args.out / "robot_run.csv", t, Y)
            log(f"wrote {csv_path}")
            rows = rows_from_array(Y)
        else:
            t, rows = read_run_csv(args.csv)
            log(f"read {len(rows)} rows from {args.csv}")
        gap = closure_error(rows)
        log(f"loop closure of the drawing (legs from joints vs platform from pose): max gap {gap:.2e} m")
        if gap > 1e-6:
            log(f"error: the legs and the platform do not meet (gap {gap:.3e} m): "
                "is the CSV from this geometry (docs/model.md defaults)?")
            return 1
        log(f"rendering {args.frames} GIF frames")
        gif = write_gif(t, rows, args.out / "robot_motion.gif", n_frames=args.frames, fps=args.fps,
                        size_px=args.size, log=log)
        log(f"wrote {gif}")
        still = write_still(t, rows, args.out / "robot_frames.png")
        log(f"wrote {still}")
    except Exception as exc:
        log(f"error: {exc}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
