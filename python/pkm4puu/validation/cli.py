# SPDX-License-Identifier: BSD-2-Clause
"""What the command-line programs share (the examples and `python -m
pkm4puu autotest` and the other reports): progress on stderr, the
--build/--out arguments (the build directory as locate.build_dir finds it,
the output in ./results of the current directory by default),
finding the FMUs with a message that says how to build them, an example's
main (run_program) and writing the output files."""
import argparse
import os
import platform
import sys
import time
from pathlib import Path

from ..fmu import find_fmu
from ..locate import BUILD_ENV, DEFAULT_BUILD, build_dir


class Log:
    """Progress on stderr, prefixed by the program's name and the elapsed time."""

    def __init__(self, prog):
        self.prog = prog
        self.t0 = time.perf_counter()

    def __call__(self, msg):
        print(f"{self.prog} [{time.perf_counter() - self.t0:6.1f} s]: {msg}", file=sys.stderr, flush=True)


def prefixed_log(prog):
    """log(message): "<prog>: <message>" on stderr (without Log's elapsed time)."""
    def log(msg):
        print(f"{prog}: {msg}", file=sys.stderr, flush=True)
    return log


def machine_description():
    """"Linux x86_64, <CPU model>, <n> cores": the machine a benchmark ran on."""
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{platform.system()} {platform.machine()}, {cpu}, {os.cpu_count()} cores"


DEFAULT_OUT = Path("results")  # relative to the current directory
BUILD_HELP = f"(default: ${BUILD_ENV}, else the installed package's own, else ./{DEFAULT_BUILD})"


def add_build_arg(ap, holding="PKM4PUU.fmu and PKM4PUU_Inverse.fmu"):
    """--build DIR; None when not given, for locate.build_dir to decide."""
    ap.add_argument("--build", type=Path, default=None, metavar="DIR",
                    help=f"build directory holding {holding} {BUILD_HELP}")


def writable_dir(text, must_exist=False):
    """An argparse type: Path(text) when it is a writable directory or, unless
    `must_exist`, can be created as one (its nearest existing ancestor is a
    writable directory); otherwise argparse.ArgumentTypeError naming the
    path and why, so that a wrong --out fails at once, before any run."""
    path = Path(text)
    probe = path
    while not must_exist and not probe.exists() and probe.parent != probe:
        probe = probe.parent
    if not probe.exists():
        raise argparse.ArgumentTypeError(f"{text}: no such directory")
    if not probe.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: {probe} is not a directory")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(f"{text}: {probe} is not writable")
    return path


def add_out_arg(ap, files="CSV, PNG and GIF files"):
    ap.add_argument("--out", type=writable_dir, default=str(DEFAULT_OUT), metavar="DIR",
                    help=f"directory for the {files} (default: ./%(default)s)")


def add_common_args(ap):
    add_build_arg(ap)
    add_out_arg(ap)


def find_build(build, log):
    """The build directory (locate.build_dir(build): --build, else
    $PKM_BUILD_DIR, else ./build), or None after logging why there is none."""
    try:
        return build_dir(build)
    except FileNotFoundError as e:
        log(f"error: {e}")
        return None


def find_fmus(build, log, models=("PKM4PUU", "PKM4PUU_Inverse")):
    """The FMI 2.0 archives of `models` in `build`, or None after logging what
    is missing and how to build it."""
    try:
        return [find_fmu(m, 2, build) for m in models]
    except FileNotFoundError as e:
        log(f"error: {e}")
        return None


def start(ap, argv, models=("PKM4PUU", "PKM4PUU_Inverse"), name=None):
    """Parses argv with ap, starts a Log named `name` (default: the
    program's) and finds the FMUs: (args, log, fmus), fmus None when they are
    missing (logged)."""
    args = ap.parse_args(argv)
    log = Log(name or ap.prog)
    return args, log, find_fmus(args.build, log, models)


def run_program(ap, argv, compute, invalid=None, models=("PKM4PUU", "PKM4PUU_Inverse")):
    """An example's main after its arguments are declared: parses argv and
    finds the FMUs (1 when they are missing); invalid(args), when given,
    returns what is wrong with the arguments or None (logged, 2);
    compute(args, fmus, log) returns (the summary to print, {file name:
    writer(path)} for write_outputs into --out); an exception it raises (an
    FMU error, a diverging loop) is logged, 1. Returns the exit status."""
    args, log, fmus = start(ap, argv, models)
    if fmus is None:
        return 1
    wrong = invalid(args) if invalid else None
    if wrong:
        log(f"error: {wrong}")
        return 2
    try:
        summary, writers = compute(args, fmus, log)
    except Exception as exc:
        log(f"error: {exc}")
        return 1
    print(summary, flush=True)
    write_outputs(args.out, log, writers)
    return 0


def run_cases(cases, run_one, label, log=None, errors=None, running="", result=lambda r: ""):
    """{case: run_one(case)} for every case. log(message), when given, is
    told when each starts ("<label(case)>: <running>") and ends (with
    result(r)). When `errors` is a dict, a case that raises is recorded
    there (case -> exception) and left out; otherwise the exception
    propagates."""
    out = {}
    for case in cases:
        name = label(case)
        if log:
            log(f"{name}: {running}")
        t0 = time.perf_counter()
        try:
            out[case] = r = run_one(case)
        except Exception as exc:
            if errors is None:
                raise
            errors[case] = exc
            if log:
                log(f"{name}: FAILED: {exc}")
            continue
        if log:
            log(f"{name}: done in {time.perf_counter() - t0:.2f} s{result(r)}")
    return out


def case_table(head, cases, runs, errors, label, row):
    """The lines of a results table: `head`, then for each case that ran
    "<label(case)> <row(case, result)>", for each that raised (in `errors`)
    "<label(case)> FAILED: <exception>"."""
    lines = list(head)
    for case in cases:
        if case in runs:
            lines.append(f"{label(case)} {row(case, runs[case])}")
        elif errors and case in errors:
            lines.append(f"{label(case)} FAILED: {errors[case]}")
    return lines


def finish(log, table, errors, bad, total, kind, write):
    """The end of a program that runs cases (run_cases): prints `table`;
    when a case raised (`errors`, logged already) or gave a bad result (`bad`:
    a message each, logged here) writes nothing and returns 1; otherwise
    write() writes the results, each path it returns is logged, 0."""
    print(table, flush=True)
    if errors or bad:
        for message in bad:
            log(message)
        log(f"{len(errors) + len(bad)} of {total} {kind} failed; nothing written")
        return 1
    for path in write():
        log(f"wrote {path}")
    return 0


def write_outputs(out, log, writers):
    """Calls writer(path) for each {file name: writer} into the directory out
    (created if missing), logs each path written, and returns the paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, write in writers.items():
        write(out / name)
        log(f"wrote {out / name}")
        paths.append(out / name)
    return paths
