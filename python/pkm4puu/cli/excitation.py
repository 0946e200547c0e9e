# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu excitation: an exciting trajectory for the identification
(docs/calibration.md): a Fourier series per axis optimised for the
condition number of the stacked base regressor within the workspace, the
end stops and the drives' limits. Prints its condition number; with --out
FILE writes one period sampled at --rate Hz as CSV (t, x, y, z, phi, their
rates and accelerations, rho[1..4], drho[1..4]) to command the machine
with. Needs scipy (the extra `calibration`).
"""
import argparse
import csv
import sys

import numpy as np

from .. import extras
from ..program import (ArgumentParser, command_prog, counting, description, non_negative, number, positive,
                       writable_file)
from .identify import add_model_arg, model_parameters


def parser():
    from ..calibration import Limits
    d = Limits()
    ap = ArgumentParser(prog=command_prog("excitation"),
                        description=description(__doc__),
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--period", type=positive, default=2.5, help="period of the series, s (default 2.5)")
    ap.add_argument("--harmonics", type=counting(1), default=5, help="harmonics per axis (default 5)")
    ap.add_argument("--seed", type=counting(0), default=0, help="seed of the random start (default 0)")
    ap.add_argument("--xy", type=positive, default=d.xy, help=f"|x|, |y| of P, m (default {d.xy})")
    ap.add_argument("--z", type=number, nargs=2, default=list(d.z), metavar=("LO", "HI"),
                    help=f"range of z of P, m (default {d.z[0]} {d.z[1]})")
    ap.add_argument("--phi", type=positive, default=d.phi, help=f"|phi|, rad (default {d.phi})")
    ap.add_argument("--stop-margin", type=non_negative, default=d.stop_margin,
                    help=f"from each end stop, m (default {d.stop_margin})")
    ap.add_argument("--speed", type=positive, default=d.speed, help=f"|drho| of each drive, m/s (default {d.speed})")
    ap.add_argument("--force", type=positive, default=d.force, help=f"|F| of each drive, N (default {d.force})")
    add_model_arg(ap, "nominal FMU parameters (geometry, payload, ...) over the spec's")
    ap.add_argument("--rate", type=positive, default=1000.0, help="sampling rate of --out, Hz (default 1000)")
    ap.add_argument("--out", metavar="FILE.csv", type=writable_file, help="write one period of the trajectory")
    return ap


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    if not args.z[0] < args.z[1]:
        ap.error(f"--z {args.z[0]:g} {args.z[1]:g}: LO must be below HI")
    extras.require(ap.prog, "scipy")
    from .. import capi
    from ..calibration import Limits, optimise_excitation
    from ..calibration.parameters import make_plant
    limits = Limits(xy=args.xy, z=tuple(args.z), phi=args.phi, stop_margin=args.stop_margin, speed=args.speed,
                    force=args.force)
    lib = capi.load()
    model = model_parameters(ap, args.model, lib)
    try:
        traj = optimise_excitation(lib, period=args.period, harmonics=args.harmonics, limits=limits, model=model,
                                   seed=args.seed)
    except (RuntimeError, KeyError, capi.PkmError) as e:
        print(f"{ap.prog}: error: {e}", file=sys.stderr)
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
        args.out.parent.mkdir(parents=True, exist_ok=True)
        with open(args.out, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(cols)
            for row in np.column_stack([t, pose, vel, acc, rho, drho]):
                w.writerow([f"{v:.12g}" for v in row])
        print(f"wrote {args.out}")
    return 0
