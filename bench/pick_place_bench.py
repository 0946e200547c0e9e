# SPDX-License-Identifier: BSD-2-Clause
"""Speed of the pick-and-place planner (a benchmark, not a test):
pkm4puu.plan_cycle on the standard cycle against the target of one second,
beside its parts measured in the same run; --grids: the cycle time's
convergence with the grid (first order: Richardson's extrapolate of the two
finest).
"""
import argparse
import statistics
import sys
import time
import timeit

import numpy as np

TARGET = 1.0  # s to plan the standard cycle


def median_time(fn, repeat):
    """The median wall time of `repeat` calls of fn()."""
    return statistics.median(timeit.repeat(fn, repeat=repeat, number=1))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="pick_place_bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", help="the build directory (default $PKM_BUILD_DIR, else ./build)")
    ap.add_argument("--repeat", type=int, default=5, help="timed calls of each part (default 5)")
    ap.add_argument("--grids", type=int, nargs="*", default=[], metavar="N",
                    help="grid sizes for the convergence table (e.g. 500 1000 2000 4000 8000 16000)")
    args = ap.parse_args(argv)
    if args.repeat < 1 or any(n < 2 for n in args.grids):
        ap.error("--repeat must be >= 1 and each grid >= 2")

    t0 = time.perf_counter()
    import pkm4puu
    from pkm4puu import spec
    from pkm4puu.planning import DT, GRID, arch, segment, topp
    from pkm4puu.planning.capi_adapter import InverseDynamics
    cycle = pkm4puu.plan_cycle(build=args.build)
    first = time.perf_counter() - t0

    plan = median_time(lambda: pkm4puu.plan_cycle(build=args.build), args.repeat)
    path, s = arch(), np.linspace(0.0, 1.0, GRID + 1)
    legs = ((path, spec.CYCLE_PAYLOAD), (path.reversed(), 0.0))

    def coefficients():
        out = []
        for p, m in legs:
            with InverseDynamics(m, build=args.build) as dyn:
                out.append(topp.path_coefficients(dyn, p, s))
        return out

    t_coeff = median_time(coefficients, args.repeat)
    coeffs = coefficients()

    def solve():
        for a, b, c, drho_ds in coeffs:
            topp.solve(s, a, b, c, spec.CYCLE_F_MAX, spec.CYCLE_V_MAX ** 2 / (drho_ds ** 2).max(axis=1))

    t_solve = median_time(solve, args.repeat)
    t_sample = median_time(lambda: [segment.sample(seg, DT, build=args.build) for seg in cycle.segments], args.repeat)

    print(f"pick-and-place planning: the standard cycle ({cycle.arch.describe()}, payload {spec.CYCLE_PAYLOAD:g} kg), "
          f"grid {GRID} intervals per leg, samples every {DT:g} s; median of {args.repeat} calls")
    print(f"   {'part':<58} {'time':>10} {'/ planning':>10}")
    for name, t in (("the C API's inverse dynamics on the grids (coefficients)", t_coeff),
                    ("toppra's solve of both legs", t_solve),
                    ("the samples' forces and slider rates (C API)", t_sample),
                    ("plan_cycle, all of it (baseline)", plan),
                    ("plan_cycle, first call (imports, library)", first)):
        print(f"   {name:<58} {t * 1e3:7.1f} ms {t / plan:9.2f}x")
    print(f"cycle time {cycle.duration:.4f} s; planning {plan:.3f} s = {plan / cycle.duration:.2f} x the cycle time; "
          f"target <= {TARGET:g} s: {'ok' if plan <= TARGET else 'OVER'}")

    if args.grids:
        grids = sorted(args.grids)
        times = [pkm4puu.plan_cycle(grid=n, dt=1e-2, build=args.build).duration for n in grids]
        limit = 2 * times[-1] - times[-2] if len(grids) > 1 else times[-1]
        print(f"\ngrid convergence of the cycle time (Richardson extrapolate of the two finest: {limit:.7f} s)")
        print(f"   {'grid':>6} {'cycle time (s)':>15} {'- finest (s)':>13} {'- extrapolate':>14} {'relative':>9}")
        for n, t in zip(grids, times):
            print(f"   {n:>6} {t:15.7f} {t - times[-1]:13.2e} {t - limit:14.2e} {(t - limit) / limit:9.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
