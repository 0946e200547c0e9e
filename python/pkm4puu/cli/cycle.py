# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu cycle: the time-optimal pick-and-place
cycle (docs/pick_and_place.md). Plans the arch x = -a cos(pi s), y = 0,
z = z0 + h sin(pi s), phi = -(theta/2) cos(pi s) from A (s = 0) to B (s = 1)
carrying the payload and back empty, each leg the fastest rest-to-rest
traversal with every |F_i| <= f_max and |drho_i/dt| <= v_max (TOPP-RA over
the C API's inverse dynamics), and prints the cycle time. The defaults are
the standard cycle. Then it runs the planned cycle closed-loop through the
plant FMU (PKM4PUU.fmu sampled at 10 kHz: the planned forces as
feed-forward, a PD on the sliders' errors, the payload grasped at A and
released at B through the FMU's tunable payload_mass) and prints the
tracking error, the peak forces against f_max and the energy per cycle;
--plan-only leaves that out (it needs the FMUs built).

With --out DIR it writes
  cycle.csv         t, x, y, z, phi, their rates and accelerations, F[1..4]
                    and payload_mass, every --dt over the whole cycle (SI
                    units; the release at B appears twice, with and without
                    the payload)
  cycle.png         the forces against their limit, the slider speeds against
                    theirs, the path velocity against its speed limit, the
                    path in 3D
  closed_loop.csv   the closed-loop run at each sample: t, x, y, z, phi,
                    x_ref, y_ref, z_ref, phi_ref, then F[1..4] applied,
                    F_ff[1..4] (the planned part), payload_mass and the
                    plant's kinetic_energy, potential_energy, actuator_work,
                    dissipated_energy (not with --plan-only)
  closed_loop.png   the reference against the plant's pose, the tracking
                    error, the forces against f_max and the feedback's part
all complete or none: they are written into a temporary folder beside DIR
and moved into it at the end. --table prints instead the Markdown table of
the cycle time against payload and f_max (the documentation's).

Exit status: 0; 2 for bad input (a value that is not finite or negative,
a path that leaves the workspace or crosses a singularity, limits too low
to hold the payload), one line on stderr saying which and where; 1 when
the C API library or the plant FMU cannot be found.

usage: pkm4puu cycle [--payload KG] [--f-max N] [--v-max M/S] [--a M] [--h M] [--z0 M]
                     [--theta-deg DEG] [--grid N] [--dt S] [--plan-only] [--build DIR]
                     [--out DIR | --table]
"""
import argparse
import math
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from .. import extras
from ..locate import LIBRARY
from ..program import ArgumentParser, add_build_arg, command_prog, description, writable_dir

TABLE_PAYLOADS = (0.0, 0.1, 0.25, 0.5)  # kg
TABLE_F_MAX = (5.0, 10.0, 20.0)  # N


def prog():
    """The usage name, as invoked."""
    return command_prog("cycle")


def parser():
    from .. import spec
    from ..planning import DT, GRID
    ap = ArgumentParser(prog=prog(), description=description(__doc__),
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    for flag, kind, default, metavar, unit, what in (
            ("--payload", float, spec.CYCLE_PAYLOAD, "KG", "kg", "mass carried from A to B, at P"),
            ("--f-max", float, spec.CYCLE_F_MAX, "N", "N", "limit of each actuator force |F_i|"),
            ("--v-max", float, spec.CYCLE_V_MAX, "M/S", "m/s", "limit of each slider speed |drho_i/dt|"),
            ("--a", float, spec.CYCLE_A, "M", "m", "half the distance from A to B along x"),
            ("--h", float, spec.CYCLE_H, "M", "m", "height of the arch"),
            ("--z0", float, spec.CYCLE_Z0, "M", "m", "height of A and B"),
            ("--theta-deg", float, math.degrees(spec.CYCLE_THETA), "DEG", "deg", "turn of the platform from A to B"),
            ("--grid", int, GRID, "N", "intervals", "grid intervals per leg"),
            ("--dt", float, DT, "S", "s", "spacing of the samples in cycle.csv")):
        ap.add_argument(flag, type=kind, default=default, metavar=metavar, help=f"{what} (default %(default)g {unit})")
    ap.add_argument("--plan-only", action="store_true",
                    help="plan the cycle only, without the closed-loop run through the plant FMU")
    add_build_arg(ap, holding=f"the C API's library {LIBRARY} and, for the closed loop, PKM4PUU.fmu")
    out = ap.add_mutually_exclusive_group()
    out.add_argument("--out", type=writable_dir, default=None, metavar="DIR",
                     help="write cycle.csv, cycle.png, closed_loop.csv and closed_loop.png into DIR (default: "
                          "write nothing)")
    out.add_argument("--table", action="store_true",
                     help="print the table of the cycle time against payload and f_max (Markdown; its own "
                          "payloads and force limits, the other values as given)")
    return ap


def error(message, status=2):
    print(f"{prog()}: error: {message}", file=sys.stderr, flush=True)
    return status


def write_csv(rows, columns, path):
    import numpy as np
    np.savetxt(path, rows, delimiter=",", header=",".join(columns), comments="", fmt="%.12g")


def plot(cycle, path):
    """The plan: the forces and the slider speeds against their limits, the
    path speed against its slider-speed limit, the path in 3D."""
    import numpy as np
    from ..plots import pyplot, save_figure
    fig = pyplot().figure(figsize=(12, 8.5))
    ax_f, ax_v, ax_s = fig.add_subplot(2, 2, 1), fig.add_subplot(2, 2, 2), fig.add_subplot(2, 2, 3)
    ax_p = fig.add_subplot(2, 2, 4, projection="3d")
    t0 = 0.0
    for k, seg in enumerate(cycle.segments):
        t = 1e3 * (t0 + seg.t)
        for i in range(4):
            label = f"leg {i + 1}" if k == 0 else None
            ax_f.plot(t, seg.F[:, i], f"C{i}", lw=1.2, label=label)
            ax_v.plot(t, seg.drho[:, i], f"C{i}", lw=1.2, label=label)
        ax_s.plot(seg.path.arch_s(seg.s), seg.sd, f"C{4 + k}", lw=1.5, label=f"{seg.name}: ds/dt")
        ax_s.plot(seg.path.arch_s(seg.s), np.sqrt(seg.x_max), f"C{4 + k}", ls=":", lw=1.0,
                  label=f"{seg.name}: slider-speed limit")
        ax_p.plot(1e3 * seg.pose[:, 0], 1e3 * seg.pose[:, 1], 1e3 * seg.pose[:, 2], f"C{4 + k}",
                  label=f"{seg.name} ({seg.payload_mass:g} kg), {seg.duration:.3f} s")
        t0 += seg.duration
        for ax in (ax_f, ax_v):
            ax.axvline(1e3 * t0, color="0.6", lw=0.8)
    seg = cycle.segments[0]
    for ax, lim, unit, what in ((ax_f, seg.force_limit, "N", r"actuator force $F_i$"),
                                (ax_v, seg.speed_limit, "m/s", r"slider speed $\dot\rho_i$")):
        for sign in (1, -1):
            ax.axhline(sign * lim, color="k", ls="--", lw=1.0)
        ax.set_xlabel("t (ms)")
        ax.set_ylabel(f"{what} ({unit})")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    ax_f.set_title(f"forces against ±{seg.force_limit:g} N (release at B: grey line)", fontsize=9)
    ax_v.set_title(f"slider speeds against ±{seg.speed_limit:g} m/s", fontsize=9)
    ax_s.set_xlabel("s of the arch (A at 0, B at 1)")
    ax_s.set_ylabel("ds/dt (1/s)")
    ax_s.set_ylim(0, 1.3 * max(s.sd.max() for s in cycle.segments))
    ax_s.set_title("path speed and the slider-speed limit curve", fontsize=9)
    ax_s.grid(True, alpha=0.3)
    ax_s.legend(fontsize=7)
    a, b = cycle.segments[0].pose[0], cycle.segments[0].pose[-1]
    for p, name in ((a, "A"), (b, "B")):
        ax_p.scatter(*(1e3 * p[:3]), color="k", s=12)
        ax_p.text(*(1e3 * p[:3]), f" {name}", fontsize=9)
    half = 1e3 * max(cycle.arch.a, cycle.arch.h / 2, 1e-3)
    ax_p.set_ylim(-half, half)
    ax_p.set_xlabel("x (mm)")
    ax_p.set_ylabel("y (mm)")
    ax_p.set_zlabel("z (mm)")
    ax_p.set_title("the path of P", fontsize=9)
    ax_p.legend(fontsize=7, loc="upper left")
    fig.suptitle(f"pick-and-place cycle: {cycle.duration:.4f} s ({cycle.arch.describe()})", fontsize=10)
    save_figure(fig, path, dpi=110)


def plot_closed_loop(track, path):
    """The closed-loop run: the reference against the plant's pose, the
    tracking errors against their bounds, the applied forces against
    f_max, the feedback's part."""
    import numpy as np
    from ..planning.tracking import TRACKING_BOUND
    from ..plots import pyplot, save_figure
    plt = pyplot()
    r = track.loop
    t = 1e3 * r.t
    release = 1e3 * track.cycle.segments[0].duration
    f_max = track.cycle.segments[0].force_limit
    fig, ((ax_p, ax_e), (ax_f, ax_b)) = plt.subplots(2, 2, figsize=(12, 8.5), sharex=True)
    for k, (name, scale, unit) in enumerate((("x", 1e3, "mm"), ("z", 1e3, "mm"), ("phi", 180 / np.pi, "deg"))):
        col = "xyz".index(name) if name != "phi" else 3
        ax = ax_p if name != "phi" else ax_p.twinx()
        ax.plot(t, scale * r.pose_d[:, col], f"C{k}", ls="--", lw=2.2, alpha=0.5, label=f"{name}_ref ({unit})")
        ax.plot(t, scale * r.pose[:, col], f"C{k}", lw=0.9, label=f"{name} ({unit})")
        if name == "phi":
            ax.set_ylabel("phi (deg)")
            ax.legend(fontsize=7, loc="lower right")
    ax_p.set_ylabel("x, z (mm)")
    ax_p.legend(fontsize=7, loc="lower left")
    ax_p.set_title("reference (dashed) against the plant FMU's pose", fontsize=9)
    ax_e.semilogy(t, 1e6 * np.maximum(r.pos_err, 1e-12), "C0", lw=1.0, label="|p - p_ref| (um)")
    r_q = TRACKING_BOUND / track.phi_bound  # phi's bound is 0.1 mm at r_Q
    ax_e.semilogy(t, 1e6 * r_q * np.maximum(r.phi_err, 1e-15), "C1", lw=1.0, label="r_Q |phi - phi_ref| (um)")
    ax_e.axhline(1e6 * TRACKING_BOUND, color="k", ls="--", lw=1.0, label="bound 100 um")
    ax_e.set_ylabel("tracking error (um)")
    ax_e.set_title(f"tracking error: max {1e6 * r.pos_err.max():.3g} um", fontsize=9)
    ax_e.legend(fontsize=7, loc="lower right")
    for i in range(4):
        ax_f.plot(t[:-1], r.F[:-1, i], f"C{i}", lw=1.0, label=f"F[{i + 1}]")
        ax_b.plot(t[:-1], 1e3 * r.F_pd[:-1, i], f"C{i}", lw=0.8, label=f"F[{i + 1}] - F_ff[{i + 1}]")
    for sign in (1, -1):
        ax_f.axhline(sign * f_max, color="k", ls="--", lw=1.0)
    ax_f.set_ylabel("applied force (N)")
    ax_f.set_title(f"forces against f_max = {f_max:g} N: peak {np.abs(r.F[:-1]).max():.4f} N", fontsize=9)
    ax_b.set_ylabel("feedback part (mN)")
    ax_b.set_title("the feedback's part of the forces", fontsize=9)
    for ax in (ax_p, ax_e, ax_f, ax_b):
        ax.axvline(release, color="0.6", lw=0.8)
        ax.grid(True, alpha=0.3)
    for ax in (ax_f, ax_b):
        ax.set_xlabel("t (ms)")
        ax.legend(fontsize=7, loc="lower right", ncol=2)
    fig.suptitle(f"the cycle in closed loop through PKM4PUU.fmu ({track.gains.f_c:g} Hz PD on the sliders, the "
                 f"planned forces as feed-forward; payload released at B: grey line)", fontsize=10)
    save_figure(fig, path, dpi=110)


def write_outputs(cycle, out, track=None):
    """cycle.csv and cycle.png (and with a closed-loop run `track`,
    closed_loop.csv and closed_loop.png) into `out`, all or none: written
    into a temporary folder beside it, then moved in (each move atomic)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.cycle-", dir=out.parent))
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp's is private; the folder may become `out`
    try:
        from ..planning import COLUMNS
        write_csv(cycle.samples(), COLUMNS, tmp / "cycle.csv")
        plot(cycle, tmp / "cycle.png")
        names = ["cycle.csv", "cycle.png"]
        if track is not None:
            from ..planning.tracking import COLUMNS as LOOP_COLUMNS
            write_csv(track.samples(), LOOP_COLUMNS, tmp / "closed_loop.csv")
            plot_closed_loop(track, tmp / "closed_loop.png")
            names += ["closed_loop.csv", "closed_loop.png"]
        if not out.exists():
            tmp.rename(out)
            return [out / name for name in names]
        paths = []
        for name in names:
            os.replace(tmp / name, out / name)
            paths.append(out / name)
        return paths
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def table(args):
    """The Markdown table of cycle time against payload and f_max. The
    arch's poses are checked once (neither the payload nor the direction
    changes them); B -> A, always empty, is planned once per f_max."""
    from ..planning import Infeasible, Limits, arch, plan_segment
    from ..planning.segment import check_path, grid_points
    arch = arch(args.a, args.h, args.z0, math.radians(args.theta_deg))
    check_path(arch, grid_points(args.grid), build=args.build, name="the arch")

    def leg(path, mass, limits, name):
        """(its two cells, its time in s; nan when infeasible)."""
        try:
            seg = plan_segment(path, mass, limits, grid=args.grid, dt=args.dt, name=name, build=args.build,
                               check_workspace=False)
        except Infeasible as e:
            return ["—", f"infeasible: {e.short}"], math.nan
        return [f"{seg.duration:.4f}", seg.active_summary()], seg.duration

    lines = [f"Cycle time on the {arch.describe()}, |drho_i/dt| <= {args.v_max:g} m/s; the payload is carried "
             "from A to B, the platform returns empty. Active: the share of each leg's time with a force or the "
             "speed limit at its bound.", "",
             "| payload (kg) | f_max (N) | A → B (s) | active on A → B | B → A (s) | active on B → A | cycle (s) |",
             "|---:|---:|---:|---|---:|---|---:|"]
    for f_max in TABLE_F_MAX:
        limits = Limits(f_max, args.v_max)
        back_cells, back_time = leg(arch.reversed(), 0.0, limits, "B -> A")
        for payload in TABLE_PAYLOADS:
            there_cells, there_time = leg(arch, payload, limits, "A -> B")
            total = there_time + back_time
            cycle = "—" if math.isnan(total) else f"{total:.4f}"
            lines.append(f"| {payload:g} | {f_max:g} | {' | '.join(there_cells + back_cells)} | {cycle} |")
    return "\n".join(lines)


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    extras.require(ap.prog, "toppra", *(("matplotlib",) if args.out is not None else ()))
    from .. import capi
    from ..planning import PlanningError, plan_cycle
    try:
        capi.load(capi.library_path(args.build))
    except OSError as e:
        return error(f"cannot load the C API library: {e}", 1)
    plant_fmu = None
    if not (args.table or args.plan_only):
        from ..fmu import find_fmu
        try:
            plant_fmu = find_fmu("PKM4PUU", 2, args.build)
        except FileNotFoundError as e:
            return error(f"the closed loop needs the plant FMU: {e} (--plan-only plans without it)", 1)
    try:
        if args.table:
            from ..planning import Limits
            Limits(args.f_max, args.v_max)  # the values checked before the sweep
            print(table(args), flush=True)
            return 0
        t0 = time.perf_counter()
        cycle = plan_cycle(args.payload, args.f_max, args.v_max, args.a, args.h, args.z0, math.radians(args.theta_deg),
                           grid=args.grid, dt=args.dt, build=args.build)
        planned = time.perf_counter() - t0
    except PlanningError as e:
        return error(str(e))
    print("\n".join(cycle.summary()), flush=True)
    print(f"{prog()}: planned in {planned:.2f} s ({args.grid} grid intervals per leg, samples every {args.dt:g} s)",
          file=sys.stderr, flush=True)
    track = None
    if plant_fmu is not None:
        from ..planning import track_cycle
        t0 = time.perf_counter()
        try:
            track = track_cycle(cycle, plant_fmu, build=args.build)
        except RuntimeError as e:
            return error(str(e), 1)
        print("\n".join(track.summary()), flush=True)
        print(f"{prog()}: closed loop run in {time.perf_counter() - t0:.2f} s ({len(track.t)} steps of the plant FMU)",
              file=sys.stderr, flush=True)
    if args.out is not None:
        for path in write_outputs(cycle, args.out, track):
            print(f"{prog()}: wrote {path}", file=sys.stderr, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
