# SPDX-License-Identifier: BSD-2-Clause
"""Checks against bounds, one line each: what was measured, the value, the
bound, PASS or FAIL. The main job's stages (pkm_autotest, `pkm4puu
autotest`, `pkm4puu comparison`) each write theirs to a <stage>_checks.csv
beside their results, in the one format below (the C++ program writes the
same columns); `pkm4puu verdict FILE...` prints them all as one block and
exits 1 when any failed or a file is missing.

CSV columns: case, quantity, measured, relation ("<=" or ">"), bound, unit,
verdict (PASS or FAIL). A measured value that is not finite fails.
"""
import csv
import math
from pathlib import Path
from typing import NamedTuple

from ..program import ArgumentParser, command_prog

COLUMNS = ["case", "quantity", "measured", "relation", "bound", "unit", "verdict"]
RELATIONS = {"<=": lambda value, bound: value <= bound, ">": lambda value, bound: value > bound}


class Check(NamedTuple):
    case: str  # e.g. "FMU auto-test midpoint/CVODE"
    quantity: str  # e.g. "max position error"
    measured: float
    relation: str  # a key of RELATIONS
    bound: float
    unit: str

    @property
    def passed(self):
        return math.isfinite(self.measured) and bool(RELATIONS[self.relation](self.measured, self.bound))


def check(case, quantity, measured, bound, unit, relation="<="):
    """A Check of `measured` (made a float) against `bound`."""
    return Check(case, quantity, float(measured), relation, bound, unit)


def verdict(passed):
    return "PASS" if passed else "FAIL"


def format_line(case, quantity, measured, relation, bound, unit, result, width=48):
    """One check's line; `measured` and `bound` are numbers or their text."""
    try:
        measured = f"{float(measured):.3e}"
    except ValueError:
        pass
    return f"  {case + ': ' + quantity:<{width}} {measured:>10} {unit:<3} {relation:>2} {bound:<8} {result}"


def format_check(c, width=48):
    return format_line(c.case, c.quantity, c.measured, c.relation, f"{c.bound:g}", c.unit, verdict(c.passed), width)


def format_checks(checks):
    """One line per check (format_check), aligned."""
    width = max((len(c.case) + len(c.quantity) + 2 for c in checks), default=0)
    return "\n".join(format_check(c, width) for c in checks)


def finish_checks(status, checks, log):
    """The end of a stage that checks: prints `checks`; returns `status` when
    it is not 0 (the stage failed before checking), else 1 when a check
    failed (logged), else 0."""
    print(format_checks(checks), flush=True)
    failed = sum(not c.passed for c in checks)
    if failed:
        log(f"{failed} of {len(checks)} checks FAILED")
    return status or int(failed > 0)


def write_checks(path, checks):
    """Writes `checks` to the CSV file `path`; returns path."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for c in checks:
            w.writerow([c.case, c.quantity, f"{c.measured:.6e}", c.relation, f"{c.bound:g}", c.unit,
                        verdict(c.passed)])
    return Path(path)


def read_rows(path):
    """The rows of a checks CSV file as dicts of COLUMNS; ValueError when its
    header is not COLUMNS."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
        if rows and list(rows[0]) != COLUMNS:
            raise ValueError(f"{path}: columns {list(rows[0])}, expected {COLUMNS}")
    return rows


def report(paths):
    """(the verdict block's lines, True when every check of every file
    passed). A missing or unreadable file, or one with no check, is a FAIL
    line of its own: its stage did not get as far as checking."""
    entries, ok = [], True  # a row of a file, or the FAIL line of a file without rows
    for path in map(Path, paths):
        try:
            rows, why = read_rows(path), "holds no check"
        except (OSError, ValueError, csv.Error) as exc:
            rows, why = [], f"unreadable: {exc}" if path.exists() else "missing: its stage did not finish"
        entries += rows or [f"  {path}: {why}  FAIL"]
        ok = ok and bool(rows) and all(row["verdict"] == "PASS" for row in rows)
    width = max((len(e["case"]) + len(e["quantity"]) + 2 for e in entries if isinstance(e, dict)), default=0)
    return [e if isinstance(e, str) else format_line(*(e[k] for k in COLUMNS), width) for e in entries], ok


def main(argv=None):
    ap = ArgumentParser(prog=command_prog("verdict"),
                        description="The main job's verdict: every check of the given <stage>_checks.csv "
                        "files (measured value, bound, PASS/FAIL); exit status 1 when any failed or a file "
                        "is missing.")
    ap.add_argument("files", type=Path, nargs="+", metavar="CHECKS_CSV", help="a checks file written by a stage")
    args = ap.parse_args(argv)
    lines, ok = report(args.files)
    print("\n".join(["verdict: one line per check (measured, bound, result)", *lines,
                     f"verdict: {'PASS' if ok else 'FAIL'}"]), flush=True)
    return 0 if ok else 1
