# SPDX-License-Identifier: BSD-2-Clause
"""python -m pkm4puu excitation: an exciting trajectory for the
identification (docs/calibration.md): a Fourier series per axis optimised
for the condition number of the stacked base regressor within the
workspace, the end stops and the drives' limits. Prints its condition
number; with --out FILE writes one period sampled at --rate Hz as CSV
(t, x, y, z, phi, their rates and accelerations, rho[1..4], drho[1..4]) to
command the machine with.

usage: python -m pkm4puu excitation [--period S] [--harmonics N] [--seed N] [--xy M] [--z LO HI] [--phi RAD]
                                     [--stop-margin M] [--speed M_PER_S] [--force N] [--model NAME=VALUE ...]
                                     [--rate HZ] [--out FILE.csv]
"""
import argparse
import csv
import sys
from pathlib import Path

import numpy as np

from .identify import parse_model


def parser():
    from ..calibration import Limits
    d = Limits()
    ap = argparse.ArgumentParser(prog="python -m pkm4puu excitation", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--period", type=float, default=2.5, help="period of the series, s (default 2.5)")
    ap.add_argument("--harmonics", type=int, default=5, help="harmonics per axis (default 5)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the random start (default 0)")
    ap.add_argument("--xy", type=float, default=d.xy, help=f"|x|, |y| of P, m (default {d.xy})")
    ap.add_argument("--z", type=float, nargs=2, default=list(d.z), metavar=("LO", "HI"),
                    help=f"range of z of P, m (default {d.z[0]} {d.z[1]})")
    ap.add_argument("--phi", type=float, default=d.phi, help=f"|phi|, rad (default {d.phi})")
    ap.add_argument("--stop-margin", type=float, default=d.stop_margin, help=f"from each end stop, m (default {d.stop_margin})")
    ap.add_argument("--speed", type=float, default=d.speed, help=f"|drho| of each drive, m/s (default {d.speed})")
    ap.add_argument("--force", type=float, default=d.force, help=f"|F| of each drive, N (default {d.force})")
    ap.add_argument("--model", metavar="NAME=VALUE", nargs="*", default=[],
                    help="nominal FMU parameters (geometry, payload, ...) over the spec's")
    ap.add_argument("--rate", type=float, default=1000.0, help="sampling rate of --out, Hz (default 1000)")
    ap.add_argument("--out", metavar="FILE.csv", help="write one period of the trajectory")
    return ap


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    model = parse_model(ap, args.model)
    if args.period <= 0 or args.harmonics < 1 or args.rate <= 0:
        ap.error("--period and --rate must be > 0, --harmonics >= 1")
    from .. import capi
    from ..calibration import Limits, optimise_excitation
    from ..calibration.parameters import make_plant
    limits = Limits(xy=args.xy, z=tuple(args.z), phi=args.phi, stop_margin=args.stop_margin, speed=args.speed,
                    force=args.force)
    lib = capi.load()
    try:
        traj = optimise_excitation(lib, period=args.period, harmonics=args.harmonics, limits=limits, model=model,
                                   seed=args.seed)
    except (RuntimeError, KeyError, capi.PkmError) as e:
        print(f"python -m pkm4puu excitation: error: {e}", file=sys.stderr)
        return 1
    print(f"condition number of the stacked base regressor (unit-norm columns): {traj.condition:.4g} "
          f"(random start {traj.start_condition:.4g})")
    if args.out:
        t = np.arange(int(round(args.period * args.rate))) / args.rate
        pose, vel, acc = traj.evaluate(t)
        with make_plant(lib, model) as p:
            _, _, rho, drho = p.regressor_poses(pose, vel, acc)
        cols = ["t", "x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"] + \
            [f"rho[{i}]" for i in range(1, 5)] + [f"drho[{i}]" for i in range(1, 5)]
        with open(Path(args.out), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(cols)
            for row in np.column_stack([t, pose, vel, acc, rho, drho]):
                w.writerow([f"{v:.12g}" for v in row])
        print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
