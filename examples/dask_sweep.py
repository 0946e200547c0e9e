# SPDX-License-Identifier: BSD-2-Clause
"""Batch studies that scale past one machine: a payload x duration sweep of
the auto-test on Dask (dask.distributed).

Each run is the auto-test with a payload m_p at the platform's centre and the
spec's quintic P0 -> P1 done in T seconds instead of 2 s (by default 20
payloads from 0 to 0.5 kg, evenly spaced, x 20 durations from 0.25 to 4 s,
geometrically spaced):
  - the inverse FMU, told the payload (m_platform = 0.45474 kg + m_p), gives
    F1..F4 at every 1 ms step's start and midpoint;
  - the plant FMU (same payload; RK4, 1 ms) is driven open loop by them, held
    at each step's midpoint value, from rest at P0.
Per run it reports the peak actuator force max |F_i(t)|, the worst (largest)
condition number of the actuator Jacobian along the run (the plant's
`jacobian_condition` output at every communication point) and the round trip's
max pose error (the check that the run reproduced the prescribed motion).

The sweep runs on a LocalCluster (one single-threaded worker process per
core) or, with --scheduler ADDRESS, on an existing cluster. The client reads
the two FMUs and broadcasts their bytes to the workers once; each worker
process writes and extracts them to its own temporary directory the first time
it needs them (keyed by their SHA-256), and every task instantiates its own
FMU instances there: no shared file system is needed. The workers need this
project's Python packages (fmpy, numpy); the functions of this module and of
the pkm4puu package travel by value (cloudpickle), so the workers do
not need this repository. Progress (runs done, elapsed, estimated time left)
is printed on stderr as the runs finish.

Writes to --out DIR:
  sweep.csv        one row per run: payload, duration, peak |F|, worst
                   condition, max position and phi error, seconds
  sweep_maps.png   the maps

usage: dask_sweep.py [--build DIR] [--out DIR] [--scheduler ADDRESS] [--workers N]
                     [--n-mass N] [--n-duration N] [--mass-max KG] [--t-min S] [--t-max S]
"""
import argparse
import csv
import hashlib
import math
import os
import shutil
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

import pkm4puu
from pkm4puu.program import add_common_args, start, write_outputs
from pkm4puu.plots import save_figure
from pkm4puu.fmu import Fmu
from pkm4puu.interface import ACC, F, POSE, RK4, START_P0, VEL
from pkm4puu.motions import motion
from pkm4puu.spec import M_PLATFORM, STEP as H

N_MASS, N_DURATION = 20, 20
MASS_MAX = 0.5  # kg: payloads 0 .. 0.5 kg (the platform itself is 0.455 kg)
# s: the spec's 2-s motion done 8x faster to 2x slower, geometrically spaced
# (the dynamic forces go as 1/T^2); below ~0.3 s they raise the peak force.
T_MIN, T_MAX = 0.25, 4.0


@dataclass
class RunResult:
    """One run of the sweep (see the module's doc). `seconds` is the run's
    wall time on its worker: the only field that differs between two runs of
    the same case."""
    payload: float  # kg
    duration: float  # s
    peak_force: float  # N, max over actuators and the half-step samples of |F_i|
    peak_dynamic_force: float  # N, the same of |F_i - F_i,static|: what the motion adds to the weight
    worst_condition: float  # max of the plant's jacobian_condition over the run
    max_pos_err: float  # m, max |(x, y, z) - prescribed|
    max_phi_err: float  # rad
    seconds: float

    def key(self):
        """Everything but the timing: what must be identical wherever it ran."""
        d = asdict(self)
        d.pop("seconds")
        return d


# --- the FMU on the worker ---------------------------------------------------------------------
class FmuBlob:
    """An FMU's bytes with its name and SHA-256, as sent to the workers."""

    def __init__(self, path):
        path = Path(path)
        self.name = path.name
        self.data = path.read_bytes()
        self.sha256 = hashlib.sha256(self.data).hexdigest()


def local_fmu(blob, scratch=None):
    """(path of the .fmu, directory it is extracted to) under `scratch`: the
    Dask worker's local directory (which the worker removes when it closes)
    when None and called in a worker. Written and extracted once per
    directory, by whichever task gets there first: each extraction goes to
    a private directory that is then renamed into place, so concurrent tasks
    (a worker with several threads) never see a half-extracted FMU. Nothing
    here is module state, so it also works when this module is shipped to the
    workers by value."""
    if scratch is None:
        from distributed import get_worker
        scratch = get_worker().local_directory  # ValueError outside a worker
    final = Path(scratch) / f"pkm_fmu_{blob.sha256[:16]}"
    if not (final / ".ready").exists():
        from fmpy import extract
        tmp = Path(tempfile.mkdtemp(dir=scratch, prefix=".extracting_"))
        (tmp / blob.name).write_bytes(blob.data)
        if hashlib.sha256((tmp / blob.name).read_bytes()).hexdigest() != blob.sha256:
            raise RuntimeError(f"{blob.name}: corrupted on its way to the worker")
        extract(str(tmp / blob.name), unzipdir=str(tmp / "x"))
        (tmp / ".ready").touch()
        try:
            os.rename(tmp, final)
        except OSError:  # another task put it there first
            shutil.rmtree(tmp, ignore_errors=True)
    return final / blob.name, final / "x"


def autotest_case(plant_blob, inverse_blob, payload, duration, h=H, scratch=None):
    """One run of the sweep: the auto-test with `payload` (kg) and motion
    duration `duration` (s, a whole number of steps h). Runs wherever it is
    called: in this process (serial, with a `scratch` directory for the
    extracted FMUs) or on a Dask worker."""
    t_start = time.perf_counter()
    n = round(duration / h)
    if abs(n * h - duration) > 1e-9 or n < 1:
        raise ValueError(f"duration {duration} s is not a whole number of {h} s steps")
    plant_path, plant_dir = local_fmu(plant_blob, scratch)
    inverse_path, inverse_dir = local_fmu(inverse_blob, scratch)
    mass = {"m_platform": M_PLATFORM + payload}
    with Fmu(inverse_path, start=mass, unzipdir=inverse_dir, instance_name="inverse") as inv:
        vr_in, vr_F = inv.vrs(POSE + VEL + ACC), inv.vrs(F)
        Fh, Fs = np.empty((2 * n + 1, 4)), np.empty((2 * n + 1, 4))
        for j in range(2 * n + 1):  # every step's start and midpoint, and the end
            m = motion(j * h / 2, duration)
            inv.fmu.setReal(vr_in, m)
            Fh[j] = inv.fmu.getReal(vr_F)
            inv.fmu.setReal(vr_in, m[:4] + [0.0] * 8)  # the same pose at rest: the static forces
            Fs[j] = inv.fmu.getReal(vr_F)
    pos_err = phi_err = 0.0
    with Fmu(plant_path, start={**START_P0, **RK4, **mass}, unzipdir=plant_dir, instance_name="plant") as plant:
        vr_F, vr_out = plant.vrs(F), plant.vrs(["jacobian_condition"] + POSE)
        cond = plant.fmu.getReal(vr_out)[0]
        for k in range(n):
            plant.fmu.setReal(vr_F, list(Fh[2 * k + 1]))
            plant.do_step(k * h, h)
            y = plant.fmu.getReal(vr_out)
            ref = motion((k + 1) * h, duration)
            cond = max(cond, y[0])
            pos_err = max(pos_err, math.dist(y[1:4], ref[:3]))
            phi_err = max(phi_err, abs(y[4] - ref[3]))
    if not all(math.isfinite(v) for v in (cond, pos_err, phi_err)):
        raise RuntimeError(f"payload {payload} kg, duration {duration} s: non-finite result")
    return RunResult(float(payload), float(duration), float(np.abs(Fh).max()), float(np.abs(Fh - Fs).max()),
                     float(cond), float(pos_err), float(phi_err), time.perf_counter() - t_start)


# --- the grid ------------------------------------------------------------------------------------
def grid(n_mass=N_MASS, n_duration=N_DURATION, mass_max=MASS_MAX, t_min=T_MIN, t_max=T_MAX, h=H):
    """(payloads, durations): payloads evenly spaced, durations geometrically
    spaced and rounded to whole steps h."""
    masses = np.linspace(0.0, mass_max, n_mass) if n_mass > 1 else np.array([0.0])
    durations = np.geomspace(t_min, t_max, n_duration) if n_duration > 1 else np.array([t_min])
    durations = np.round(durations / h) * h
    return [float(m) for m in masses], [float(T) for T in durations]


def cases(masses, durations):
    """Longest runs first, so that the last tasks to finish are short ones."""
    return sorted(((m, T) for m in masses for T in durations), key=lambda c: (-c[1], c[0]))


# --- running it ----------------------------------------------------------------------------------
class Progress:
    """'k/n runs' with elapsed and estimated remaining time, on stderr via log,
    at most every `every` seconds (and at the last run)."""

    def __init__(self, n, log, every=2.0):
        self.n, self.log, self.every = n, log, every
        self.done = 0
        self.t0 = time.perf_counter()
        self.last = -math.inf

    def __call__(self):
        self.done += 1
        now = time.perf_counter()
        if self.log and (now - self.last >= self.every or self.done == self.n):
            self.last = now
            el = now - self.t0
            left = el / self.done * (self.n - self.done)
            bar = "#" * (30 * self.done // self.n)
            self.log(f"[{bar:<30}] {self.done}/{self.n} runs, {el:.1f} s elapsed, ~{left:.0f} s left")


def run_serial(plant_fmu, inverse_fmu, masses, durations, log=None):
    """Every case in this process, one after the other."""
    plant, inverse = FmuBlob(plant_fmu), FmuBlob(inverse_fmu)
    todo = cases(masses, durations)
    progress = Progress(len(todo), log)
    out = []
    with tempfile.TemporaryDirectory(prefix="pkm_sweep_") as scratch:
        for m, T in todo:
            out.append(autotest_case(plant, inverse, m, T, scratch=scratch))
            progress()
    return sort_results(out)


def ship_by_value():
    """Functions of this module and of the pkm4puu package are pickled by
    value, so the workers need not import them (a remote cluster does not
    have this repository). When run as a script this module is __main__,
    which cloudpickle ships by value anyway."""
    import cloudpickle
    for mod in (pkm4puu, sys.modules[__name__]):
        if mod.__name__ != "__main__":
            cloudpickle.register_pickle_by_value(mod)


def upload_this_module(client):
    """Imported as a module (by a test, say), this file's objects that Dask
    pickles by reference (the FmuBlob instances, the results) name the module
    `dask_sweep`: the workers get this file so that the name resolves there.
    As a script it is __main__, which Dask ships by value anyway."""
    if __name__ != "__main__":
        client.upload_file(__file__)


def run_dask(client, plant_fmu, inverse_fmu, masses, durations, log=None):
    """Every case as one Dask task on `client`'s cluster; results sorted by
    (payload, duration)."""
    from dask.distributed import as_completed
    ship_by_value()
    upload_this_module(client)
    plant, inverse = FmuBlob(plant_fmu), FmuBlob(inverse_fmu)
    # The FMUs (~0.4 MB) go to every worker once; tasks refer to them.
    plant_f, inverse_f = client.scatter([plant, inverse], broadcast=True)
    todo = cases(masses, durations)
    futures = [client.submit(autotest_case, plant_f, inverse_f, m, T, pure=False) for m, T in todo]
    progress = Progress(len(futures), log)
    out = []
    try:
        for fut in as_completed(futures):
            out.append(fut.result())  # re-raises a task's exception here
            progress()
    finally:
        client.cancel(futures)
    return sort_results(out)


def sort_results(results):
    return sorted(results, key=lambda r: (r.payload, r.duration))


def local_cluster(n_workers=None):
    """A LocalCluster on this machine's loopback: single-threaded worker
    processes (one per core unless n_workers), no dashboard."""
    from dask.distributed import LocalCluster
    return LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                        host="127.0.0.1", dashboard_address=None)


# --- results -------------------------------------------------------------------------------------
FIELDS = ["payload", "duration", "peak_force", "peak_dynamic_force", "worst_condition", "max_pos_err",
          "max_phi_err", "seconds"]
HEADER = ["payload_kg", "duration_s", "peak_force_N", "peak_dynamic_force_N", "worst_condition", "max_pos_err_m",
          "max_phi_err_rad", "seconds"]
MAPS = ("peak_force", "peak_dynamic_force", "worst_condition", "max_pos_err")


def write_csv(results, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HEADER)
        for r in results:
            w.writerow([repr(getattr(r, k)) for k in FIELDS])


def maps(results, masses, durations):
    """{field: (len(durations), len(masses)) array} for the map fields."""
    im = {m: i for i, m in enumerate(masses)}
    it = {T: i for i, T in enumerate(durations)}
    out = {k: np.full((len(durations), len(masses)), np.nan)
           for k in MAPS}
    for r in results:
        for k in out:
            out[k][it[r.duration], im[r.payload]] = getattr(r, k)
    return out


def plot(results, masses, durations, path):
    """Four maps over (payload, duration)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    M = maps(results, masses, durations)
    x, y = 1e3 * np.array(masses), np.array(durations)
    xe, ye = _edges(x), np.exp(_edges(np.log(y)))
    cond = M["worst_condition"]
    dyn = 1e3 * M["peak_dynamic_force"]
    # (map, colour map, number format, title, log colour scale, contour lines)
    specs = [
        (M["peak_force"], "viridis", "%.2f", "peak actuator force max |F_i(t)| (N)", False, True),
        (dyn, "plasma", "%g", "peak dynamic force max |F_i - F_i,static| (mN), log scale:\n"
         "what the motion adds to the weight (~ 1/T^2)", True, True),
        (cond, "magma", "%.6f", f"worst Jacobian condition number along the run\n(range {np.nanmin(cond):.6f} .. "
         f"{np.nanmax(cond):.6f}: set by the path, not the load)", False, False),
        (np.log10(M["max_pos_err"]), "cividis", "%.1f", "log10 max position error of the open-loop round trip "
         "(m):\nthe check that each run reproduced the motion", False, True),
    ]
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5))
    for ax, (Z, cmap, fmt, label, log, lines) in zip(axes.flat, specs):
        norm = matplotlib.colors.LogNorm(np.nanmin(Z), np.nanmax(Z)) if log and np.nanmin(Z) > 0 else None
        pc = ax.pcolormesh(xe, ye, Z, cmap=cmap, shading="flat", norm=norm)
        cb = fig.colorbar(pc, ax=ax, format=matplotlib.ticker.FormatStrFormatter(fmt))
        cb.ax.tick_params(labelsize=8)
        if lines and len(x) > 1 and len(y) > 1 and np.nanmax(Z) > np.nanmin(Z):
            levels = [v for v in (2, 5, 10, 20, 50, 100, 200, 500, 1000) if np.nanmin(Z) < v < np.nanmax(Z)] \
                if norm is not None else 6
            cs = ax.contour(x, y, Z, levels=levels, colors="w", linewidths=0.7, alpha=0.8, linestyles="solid")
            ax.clabel(cs, fmt=fmt, fontsize=7)
        ax.set_xlabel("payload (g)")
        ax.set_ylabel("motion duration T (s)")
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(matplotlib.ticker.FixedLocator([0.25, 0.5, 1, 2, 4]))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(label, fontsize=9)
    fig.suptitle(f"Auto-test sweep on Dask: {len(masses)} payloads x {len(durations)} durations = {len(results)} "
                 "runs\n(inverse FMU, told the payload -> forces -> plant FMU with the payload, open loop, RK4 "
                 "1 ms)", fontsize=10)
    save_figure(fig, path, dpi=100)


def _edges(c):
    if len(c) == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5])
    mid = (c[1:] + c[:-1]) / 2
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])


def summary(results, wall, where):
    pf = [r.peak_force for r in results]
    pd = [r.peak_dynamic_force for r in results]
    cond = [r.worst_condition for r in results]
    pe = [r.max_pos_err for r in results]
    busy = sum(r.seconds for r in results)
    worst = max(results, key=lambda r: r.peak_force)
    return "\n".join([
        f"{len(results)} runs on {where} in {wall:.1f} s wall, cluster start-up not counted "
        f"({busy:.1f} s of run time summed over the runs: {busy / wall:.2f} runs at a time on average)",
        f"peak |F|: {min(pf):.4f} .. {max(pf):.4f} N (largest at payload {worst.payload:g} kg, T = "
        f"{worst.duration:g} s)",
        f"peak dynamic part |F - F_static|: {1e3 * min(pd):.2f} .. {1e3 * max(pd):.2f} mN",
        f"worst Jacobian condition: {min(cond):.6f} .. {max(cond):.6f}",
        f"max round-trip position error: {min(pe):.2e} .. {max(pe):.2e} m",
    ])


def main(argv=None):
    ap = argparse.ArgumentParser(prog="dask_sweep", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "sweep.csv and sweep_maps.png")
    ap.add_argument("--scheduler", metavar="ADDRESS",
                    help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786 (default: start a "
                         "LocalCluster on this machine)")
    ap.add_argument("--workers", type=int, default=None,
                    help="LocalCluster worker processes (default: one per core)")
    ap.add_argument("--serial", action="store_true", help="no Dask: run every case in this process")
    ap.add_argument("--n-mass", type=int, default=N_MASS, help="payload values (default %(default)s)")
    ap.add_argument("--n-duration", type=int, default=N_DURATION, help="duration values (default %(default)s)")
    ap.add_argument("--mass-max", type=float, default=MASS_MAX, help="largest payload (kg, default %(default)s)")
    ap.add_argument("--t-min", type=float, default=T_MIN, help="shortest duration (s, default %(default)s)")
    ap.add_argument("--t-max", type=float, default=T_MAX, help="longest duration (s, default %(default)s)")
    args, log, fmus = start(ap, argv)
    if fmus is None:
        return 1
    if args.n_mass < 1 or args.n_duration < 1 or args.mass_max < 0 or not 0 < args.t_min <= args.t_max:
        log("error: need --n-mass, --n-duration >= 1, --mass-max >= 0 and 0 < --t-min <= --t-max")
        return 2
    masses, durations = grid(args.n_mass, args.n_duration, args.mass_max, args.t_min, args.t_max)
    n = len(masses) * len(durations)
    try:
        if args.serial:
            where = "this process (serial)"
            log(f"{n} runs, serially")
            t0 = time.perf_counter()
            results = run_serial(*fmus, masses, durations, log=log)
            wall = time.perf_counter() - t0
        else:
            from dask.distributed import Client
            if args.scheduler:
                client, cluster = Client(args.scheduler), None
            else:
                cluster = local_cluster(args.workers)
                client = Client(cluster)
            try:
                nw = len(client.scheduler_info()["workers"])
                where = f"Dask, {nw} workers ({args.scheduler or 'LocalCluster'})"
                log(f"{n} runs on {where}")
                t0 = time.perf_counter()
                results = run_dask(client, *fmus, masses, durations, log=log)
                wall = time.perf_counter() - t0
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
    except Exception as exc:
        log(f"error: {type(exc).__name__}: {exc}")
        return 1
    print(summary(results, wall, where), flush=True)
    write_outputs(args.out, log, {"sweep.csv": lambda p: write_csv(results, p),
                                  "sweep_maps.png": lambda p: plot(results, masses, durations, p)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
