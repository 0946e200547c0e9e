"""What the command-line programs share (the examples and `python -m
pkm4puu.autotest`): progress on stderr, the --build/--out arguments, and
finding the FMUs with a message that says how to build them."""
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
