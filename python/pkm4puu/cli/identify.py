# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu identify LOG.csv: the plant's dynamic parameters from a drive log
(docs/calibration.md). The CSV has a header row naming the columns t (s),
rho[1]..rho[4] (m, the sliders' positions) and F[1]..F[4] (N, the actuator
forces), one row per sample, evenly spaced in time; other columns are
ignored. Prints the base parameters with their standard deviations and the
FMUs' start values (JSON, also to --out FILE). Needs scipy (the extra
`calibration`).

Wrong arguments (a log that is no file, a cut-off or trim that is no
number of the kind, an unknown model parameter, an --out that cannot be
written) end with status 2 before anything is read; data the
identification cannot use (a missing column or field, a non-number, NaN,
time going back, positions out of reach, non-exciting motion) with status 1;
each with one line naming the value.
"""
import argparse
import csv
import json
import sys
from array import array
from pathlib import Path

import numpy as np

from .. import extras
from ..program import (ArgumentParser, command_prog, counting, description, existing_file, number, positive,
                       writable_file)

COLUMNS = ["t"] + [f"rho[{i}]" for i in range(1, 5)] + [f"F[{i}]" for i in range(1, 5)]


class LogError(ValueError):
    pass


def read_log(path):
    """(t, rho, F) from the CSV at `path`; LogError says what is wrong and
    where. The samples go into one array as they are read (72 bytes each)."""
    path = Path(path)
    if path.is_dir():
        raise LogError(f"{path}: is a directory, not a CSV file")
    if not path.is_file():
        raise LogError(f"{path}: no such file")
    values = array("d")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        try:
            header = [h.strip() for h in next(reader)]
        except StopIteration:
            raise LogError(f"{path}: empty file") from None
        except (csv.Error, UnicodeDecodeError) as e:
            raise LogError(f"{path}: not a CSV file ({e})") from None
        missing = [c for c in COLUMNS if c not in header]
        if missing:
            raise LogError(f"{path}: missing column(s) {', '.join(missing)} (the header has {', '.join(header)}); "
                           f"needed: {', '.join(COLUMNS)}")
        idx = [header.index(c) for c in COLUMNS]
        try:
            for row in reader:
                if not row:
                    continue
                if len(row) != len(header):
                    raise LogError(f"{path}:{reader.line_num}: {len(row)} field(s), the header has {len(header)}")
                for column, i in zip(COLUMNS, idx):
                    try:
                        values.append(float(row[i]))
                    except ValueError:
                        raise LogError(f"{path}:{reader.line_num}: column {column}: {row[i]!r} is not a number") \
                            from None
        except (csv.Error, UnicodeDecodeError) as e:
            raise LogError(f"{path}:{reader.line_num}: not a CSV row ({e})") from None
    if not values:
        raise LogError(f"{path}: no samples after the header")
    a = np.frombuffer(values, dtype=float).reshape(-1, len(COLUMNS))
    return a[:, 0], a[:, 1:5], a[:, 5:9]


def model_value(text):
    """An argparse type: (NAME, VALUE) from NAME=VALUE with a finite number."""
    name, sep, value = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"{text!r} is not NAME=VALUE")
    try:
        return name, number(value)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"{text!r}: {value!r} is not a finite number") from None


def add_model_arg(ap, help):
    ap.add_argument("--model", metavar="NAME=VALUE", nargs="*", type=model_value, default=[], help=help)


def model_parameters(ap, items, lib):
    """{name: value} from the --model items, each a parameter of the model
    with a value it accepts (calibration.make_plant; ap.error naming the
    item otherwise)."""
    from ..capi import PkmError
    from ..calibration.parameters import make_plant
    model = dict(items)
    for name, value in model.items():
        try:
            with make_plant(lib, {name: value}):
                pass
        except KeyError as e:
            ap.error(f"--model {name}={value:g}: {e.args[0]}")
        except PkmError as e:
            ap.error(f"--model {name}={value:g}: {e}")
    return model


def parser():
    ap = ArgumentParser(prog=command_prog("identify"), description=description(__doc__),
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("log", metavar="LOG.csv", type=existing_file, help="columns t, rho[1..4], F[1..4] (header row)")
    ap.add_argument("--cutoff", type=positive, default=20.0, metavar="HZ",
                    help="low-pass cut-off of rho, Hz (default 20)")
    ap.add_argument("--trim", type=counting(0), default=None, metavar="N",
                    help="samples dropped at either end (default: two periods of the cut-off)")
    add_model_arg(ap, "known FMU parameters (geometry, screw_lead, friction_velocity, payload_mass, ...)")
    ap.add_argument("--no-physical", action="store_true", help="no physical-consistency constraints")
    ap.add_argument("--out", metavar="FILE", type=writable_file, help="write the start values as JSON to FILE")
    return ap


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    extras.require(ap.prog, "scipy")
    from .. import capi
    from ..calibration import IdentificationError, identify
    lib = capi.load()
    model = model_parameters(ap, args.model, lib)
    try:
        t, rho, F = read_log(args.log)
        r = identify(t, rho, F, cutoff=args.cutoff, trim=args.trim, model=model, physical=not args.no_physical,
                     lib=lib)
    except (LogError, IdentificationError) as e:
        print(f"{ap.prog}: error: {e}", file=sys.stderr)
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
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    return 0
