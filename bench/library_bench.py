# SPDX-License-Identifier: BSD-2-Clause
"""The Python library's two long calls against their targets of one second
(a benchmark, not a test), each beside its parts measured in the same run.

identify: pkm4puu.identify on --seconds of a 1 kHz drive log (calibration.drive_log: the plant FMU along a random
Fourier trajectory, 1 % force noise, 1 um encoder steps), target 1 s per 10 s, beside the C API's regressor over the
same samples; its peak memory against the stacked regressor's (identify stacks it in blocks: below it from a few
blocks on, --seconds 100).
plan: pkm4puu.plan_cycle on the standard cycle, target 1 s; --grids: the cycle time's convergence with the grid.
"""
import argparse
import statistics
import sys
import time
import timeit
import tracemalloc

import numpy as np

TARGET = 1.0  # s: identify on 10 s of log; plan_cycle on the standard cycle
MODEL = {"friction_velocity": 0.005, "rotor_inertia": 1.5e-7, "friction_viscous": 5.0, "friction_coulomb": 0.6}


def median_time(fn, repeat):
    """The median wall time of `repeat` calls of fn()."""
    return statistics.median(timeit.repeat(fn, repeat=repeat, number=1))


def first_call(fn):
    """fn()'s result and the wall time of this, its first call (imports, the library)."""
    t0 = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - t0


def row(name, value, unit, ratio, note=""):
    print(f"   {name:<58} {value:8.1f} {unit} {ratio:9.2f}x  {note}".rstrip())


def verdict(value, target):
    return f"target <= {target:g} s: {'ok' if value <= target else 'OVER'}"


def identify_bench(args):
    from pkm4puu import capi
    from pkm4puu.calibration import filtered_derivatives, identify, random_trajectory
    from pkm4puu.calibration.drive_log import simulate_drive_log
    from pkm4puu.calibration.parameters import make_plant
    from pkm4puu.locate import library_path
    lib = capi.load(library_path(args.build))
    log = simulate_drive_log(random_trajectory(lib, model=MODEL, period=2.5, harmonics=5, seed=0), args.seconds, MODEL,
                             build=args.build)
    t, run = log.t, lambda: identify(log.t, log.rho, log.F, model=MODEL, lib=lib)
    r, first = first_call(run)
    med = median_time(run, args.repeat)
    joints = filtered_derivatives(t, log.rho, 20.0)
    with make_plant(lib, MODEL) as p:
        reg = median_time(lambda: p.regressor_joints(*joints), args.repeat)
    tracemalloc.start()
    run()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    stacked = len(t) * 4 * len(capi.regressor_params(lib)) * 8
    print(f"identify: {len(t)} samples ({args.seconds:g} s at 1 kHz), {len(r.names)} base parameters, "
          f"condition {r.condition:.3g}; median of {args.repeat} calls")
    print(f"   {'evaluation':<58} {'time, size':>11} {'ratio':>10}")
    row("pkm_regressor_joints over the samples (baseline)", reg * 1e3, "ms", 1.0)
    row("identify, median of later calls", med * 1e3, "ms", med / reg, verdict(med, TARGET * args.seconds / 10))
    row("identify, first call (imports, library)", first * 1e3, "ms", first / reg)
    row("memory: the stacked regressor (baseline)", stacked / 1e6, "MB", 1.0)
    row("memory: identify, peak allocation", peak / 1e6, "MB", peak / stacked)


def plan_bench(args):
    def plan_first():
        import pkm4puu
        return pkm4puu, pkm4puu.plan_cycle(build=args.build)
    (pkm4puu, cycle), first = first_call(plan_first)
    from pkm4puu import spec
    from pkm4puu.planning import DT, GRID, arch, segment, topp
    from pkm4puu.planning.capi_adapter import InverseDynamics
    plan = median_time(lambda: pkm4puu.plan_cycle(build=args.build), args.repeat)
    path, s = arch(), np.linspace(0.0, 1.0, GRID + 1)

    def coefficients():
        out = []
        for p, m in ((path, spec.CYCLE_PAYLOAD), (path.reversed(), 0.0)):
            with InverseDynamics(m, build=args.build) as dyn:
                out.append(topp.path_coefficients(dyn, p, s))
        return out

    def solve():
        for a, b, c, drho_ds in coeffs:
            topp.solve(s, a, b, c, spec.CYCLE_F_MAX, spec.CYCLE_V_MAX ** 2 / (drho_ds ** 2).max(axis=1))

    coeffs = coefficients()
    parts = (("the C API's inverse dynamics on the grids (coefficients)", median_time(coefficients, args.repeat)),
             ("toppra's solve of both legs", median_time(solve, args.repeat)),
             ("the samples' forces and slider rates (C API)",
              median_time(lambda: [segment.sample(g, DT, build=args.build) for g in cycle.segments], args.repeat)),
             ("plan_cycle, all of it (baseline)", plan), ("plan_cycle, first call (imports, library)", first))
    print(f"pick-and-place planning: the standard cycle ({cycle.arch.describe()}, payload {spec.CYCLE_PAYLOAD:g} kg), "
          f"grid {GRID} intervals per leg, samples every {DT:g} s; median of {args.repeat} calls")
    print(f"   {'part':<58} {'time':>11} {'/ planning':>10}")
    for name, t in parts:
        row(name, t * 1e3, "ms", t / plan)
    print(f"cycle time {cycle.duration:.4f} s; planning {plan:.3f} s = {plan / cycle.duration:.2f} x the cycle time; "
          f"{verdict(plan, TARGET)}")
    if args.grids:
        grids = sorted(args.grids)
        times = [pkm4puu.plan_cycle(grid=n, dt=1e-2, build=args.build).duration for n in grids]
        limit = 2 * times[-1] - times[-2] if len(grids) > 1 else times[-1]
        print(f"\ngrid convergence of the cycle time (Richardson extrapolate of the two finest: {limit:.7f} s)")
        print(f"   {'grid':>6} {'cycle time (s)':>15} {'- finest (s)':>13} {'- extrapolate':>14} {'relative':>9}")
        for n, t in zip(grids, times):
            print(f"   {n:>6} {t:15.7f} {t - times[-1]:13.2e} {t - limit:14.2e} {(t - limit) / limit:9.2e}")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="library_bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("bench", choices=("identify", "plan"), help="identify (calibration) or plan (pick-and-place)")
    ap.add_argument("--build", help="the build directory (default $PKM_BUILD_DIR, else ./build)")
    ap.add_argument("--repeat", type=int, default=5, help="timed calls after the first (default 5)")
    ap.add_argument("--seconds", type=float, default=10.0, help="identify: length of the log, s (default 10)")
    ap.add_argument("--grids", type=int, nargs="*", default=[], metavar="N",
                    help="plan: grid sizes for the convergence table (e.g. 500 1000 2000 4000 8000 16000)")
    args = ap.parse_args(argv)
    if args.repeat < 1 or any(n < 2 for n in args.grids) or not args.seconds > 0:
        ap.error("--repeat must be >= 1, --seconds > 0 and each grid >= 2")
    (identify_bench if args.bench == "identify" else plan_bench)(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
