# SPDX-License-Identifier: BSD-2-Clause
"""python -m pkm4puu identify LOG.csv: the plant's dynamic parameters from a
drive log (docs/calibration.md). The CSV has a header row naming the
columns t (s), rho[1]..rho[4] (m, the sliders' positions) and F[1]..F[4]
(N, the actuator forces), one row per sample, evenly spaced in time; other
columns are ignored. Prints the base parameters with their standard
deviations and the FMUs' start values (JSON, also to --out FILE).

usage: python -m pkm4puu identify LOG.csv [--cutoff HZ] [--model NAME=VALUE ...] [--no-physical] [--out FILE]
"""
import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

COLUMNS = ["t"] + [f"rho[{i}]" for i in range(1, 5)] + [f"F[{i}]" for i in range(1, 5)]


class LogError(ValueError):
    pass


def read_log(path):
    """(t, rho, F) from the CSV at `path`; LogError says what is wrong."""
    path = Path(path)
    if not path.is_file():
        raise LogError(f"{path}: no such file")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = [h.strip() for h in next(reader)]
        except StopIteration:
            raise LogError(f"{path}: empty file") from None
        missing = [c for c in COLUMNS if c not in header]
        if missing:
            raise LogError(f"{path}: missing column(s) {', '.join(missing)} (the header has {', '.join(header)}); "
                           f"needed: {', '.join(COLUMNS)}")
        idx = [header.index(c) for c in COLUMNS]
        rows = []
        for line, row in enumerate(reader, start=2):
            if not row:
                continue
            try:
                rows.append([float(row[i]) for i in idx])
            except (ValueError, IndexError):
                raise LogError(f"{path}:{line}: not a number in columns {', '.join(COLUMNS)}: {row}") from None
    if not rows:
        raise LogError(f"{path}: no samples after the header")
    a = np.array(rows)
    return a[:, 0], a[:, 1:5], a[:, 5:9]


def parser():
    ap = argparse.ArgumentParser(prog="python -m pkm4puu identify", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log", metavar="LOG.csv", help="columns t, rho[1..4], F[1..4] (header row)")
    ap.add_argument("--cutoff", type=float, default=20.0, help="low-pass cut-off of rho, Hz (default 20)")
    ap.add_argument("--model", metavar="NAME=VALUE", nargs="*", default=[],
                    help="known FMU parameters (geometry, screw_lead, friction_velocity, payload_mass, ...)")
    ap.add_argument("--no-physical", action="store_true", help="no physical-consistency constraints")
    ap.add_argument("--out", metavar="FILE", help="write the start values as JSON to FILE")
    return ap


def parse_model(ap, items):
    """{name: value} from --model NAME=VALUE items (ap.error otherwise)."""
    model = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            model[name] = float(value)
        except ValueError:
            sep = ""
        if not sep:
            ap.error(f"--model {item!r}: expected NAME=VALUE with a number")
    return model


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    model = parse_model(ap, args.model)
    from ..calibration import IdentificationError, identify
    try:
        t, rho, F = read_log(args.log)
        r = identify(t, rho, F, cutoff=args.cutoff, model=model, physical=not args.no_physical)
    except (LogError, IdentificationError, KeyError) as e:
        print(f"python -m pkm4puu identify: error: {e}", file=sys.stderr)
        return 1
    print(r.table())
    print(f"condition number of the base regressor (unit-norm columns): {r.condition:.4g}")
    print(f"samples used: {r.samples}; residual RMS {r.residual_rms:.4g} N")
    for w in r.warnings:
        print(f"warning: {w}", file=sys.stderr)
    for b in r.active_bounds:
        print(f"constraint active: {b}", file=sys.stderr)
    text = json.dumps(r.start_values, indent=2)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
