"""What the command-line programs share (the examples and `python -m
pkm4puu.autotest`): progress on stderr, the --build/--out arguments,
finding the FMUs with a message that says how to build them, an example's
main (run_program) and writing the output files."""
import os
import platform
import sys
import time
from pathlib import Path

from .fmu import REPO, find_fmu


class Log:
    """Progress on stderr, prefixed by the program's name and the elapsed time."""

    def __init__(self, prog):
        self.prog = prog
        self.t0 = time.perf_counter()

    def __call__(self, msg):
        print(f"{self.prog} [{time.perf_counter() - self.t0:6.1f} s]: {msg}", file=sys.stderr, flush=True)


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


def add_common_args(ap):
    ap.add_argument("--build", type=Path, default=REPO / "build",
                    help="directory holding PKM4PUU.fmu and PKM4PUU_Inverse.fmu (default: %(default)s)")
    ap.add_argument("--out", type=Path, default=REPO / "results",
                    help="directory for the CSV, PNG and GIF files (default: %(default)s)")


def find_fmus(build, log, models=("PKM4PUU", "PKM4PUU_Inverse")):
    """The FMI 2.0 archives of `models` in `build`, or None after logging what
    is missing and how to build it."""
    try:
        return [find_fmu(m, 2, build) for m in models]
    except FileNotFoundError as e:
        log(f"error: {e}, or pass --build DIR")
        return None


def start(ap, argv, models=("PKM4PUU", "PKM4PUU_Inverse")):
    """Parses argv with ap, starts a Log named after the program and finds the
    FMUs: (args, log, fmus), fmus None when they are missing (logged)."""
    args = ap.parse_args(argv)
    log = Log(ap.prog)
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
