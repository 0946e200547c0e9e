# SPDX-License-Identifier: BSD-2-Clause
"""Speed of the identification (a benchmark, not a test): pkm4puu.identify on
--seconds of a 1 kHz drive log (a random Fourier trajectory, the exact
forces, 1 % force noise, 1 um encoder steps) against the target of one second
for 10 s, beside the C API's regressor over the same samples; its peak memory
against the stacked regressor's size (identify stacks it in blocks, so the
peak falls below it from a few blocks on: --seconds 100).
"""
import argparse
import sys
import time
import timeit
import tracemalloc

import numpy as np

from pkm4puu import capi
from pkm4puu.calibration.parameters import make_plant
from pkm4puu.locate import library_path

TARGET = 1.0  # s for 10 s of 1 kHz data
MODEL = {"friction_velocity": 0.005, "rotor_inertia": 1.5e-7, "friction_viscous": 5.0, "friction_coulomb": 0.6}


def drive_log(lib, seconds, h=1e-3, seed=0):
    from pkm4puu.calibration import random_trajectory
    traj = random_trajectory(lib, model=MODEL, period=2.5, harmonics=5, seed=seed)
    t = np.arange(int(round(seconds / h)) + 1) * h
    with make_plant(lib, MODEL) as p:
        Y, F0, rho, _ = p.regressor_poses(*traj.evaluate(t))
        F = np.einsum("nij,j->ni", Y, p.regressor_params()) + F0
    rng = np.random.default_rng(seed)
    F += rng.standard_normal(F.shape) * 0.01 * np.sqrt(np.mean(F ** 2, axis=0))
    return t, np.round(rho / 1e-6) * 1e-6, F


def main(argv=None):
    ap = argparse.ArgumentParser(prog="calibration_bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", help="the build directory (default $PKM_BUILD_DIR, else ./build)")
    ap.add_argument("--seconds", type=float, default=10.0, help="length of the log, s (default 10)")
    ap.add_argument("--repeat", type=int, default=5, help="timed calls after the first (default 5)")
    args = ap.parse_args(argv)
    lib = capi.load(library_path(args.build))
    t, rho, F = drive_log(lib, args.seconds)

    t0 = time.perf_counter()
    from pkm4puu.calibration import filtered_derivatives, identify
    r = identify(t, rho, F, model=MODEL, lib=lib)
    first = time.perf_counter() - t0
    warm = timeit.repeat(lambda: identify(t, rho, F, model=MODEL, lib=lib), repeat=args.repeat, number=1)
    r_, rd, rdd = filtered_derivatives(t, rho, 20.0)
    with make_plant(lib, MODEL) as p:
        reg = timeit.repeat(lambda: p.regressor_joints(r_, rd, rdd), repeat=max(args.repeat, 1), number=1)
    tracemalloc.start()
    identify(t, rho, F, model=MODEL, lib=lib)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    stacked = len(t) * 4 * len(capi.regressor_params(lib)) * 8
    med, reg_med = float(np.median(warm)) if warm else first, float(np.median(reg))
    target = TARGET * args.seconds / 10.0
    print(f"identify: {len(t)} samples ({args.seconds:g} s at 1 kHz), {len(r.names)} base parameters, "
          f"condition {r.condition:.3g}")
    print(f"   {'evaluation':<48} {'time':>10} {'ratio':>8} {'target':>18}")
    print(f"   {'pkm_regressor_joints over the samples (baseline)':<48} {reg_med * 1e3:8.1f} ms {1.0:7.2f}x")
    print(f"   {'identify, median of later calls':<48} {med * 1e3:8.1f} ms {med / reg_med:7.2f}x "
          f"{f'<= {target:g} s  ' + ('ok' if med <= target else 'OVER'):>18}")
    print(f"   {'identify, first call (imports, library)':<48} {first * 1e3:8.1f} ms {first / reg_med:7.2f}x")
    print(f"   {'memory: the stacked regressor (baseline)':<48} {stacked / 1e6:8.1f} MB {1.0:7.2f}x")
    print(f"   {'memory: identify, peak allocation':<48} {peak / 1e6:8.1f} MB {peak / stacked:7.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
