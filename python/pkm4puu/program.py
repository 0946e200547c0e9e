# SPDX-License-Identifier: BSD-2-Clause
"""What command-line programs over the FMUs share: the pkm4puu command's
programs (pkm4puu.cli), the examples and the benchmarks. Progress on
stderr; the --build and --out arguments (the build directory as
locate.build_dir finds it, the output in ./results of the current directory
by default), each checked when parsed, so that a wrong one fails at once;
argparse types that name a bad value; finding the FMUs with a message that
says how to build them; an example's main (run_program); running cases and
writing the output files."""
import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path

from . import extras, plots
from .fmu import find_fmu
from .locate import BUILD_ENV, DEFAULT_BUILD

COMMAND = "pkm4puu"


def invoked_as():
    """The pkm4puu command as it was invoked: "python -m pkm4puu" when run as
    a module, else "pkm4puu" (the console command)."""
    spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    return f"python -m {COMMAND}" if spec is not None and spec.name == f"{COMMAND}.__main__" else COMMAND


def command_prog(command):
    """The usage name of a subcommand: "pkm4puu COMMAND" as invoked."""
    return f"{invoked_as()} {command}"


def description(doc):
    """A program's --help description from its module's docstring: the first
    paragraph without its "pkm4puu COMMAND ...: " head, capitalised."""
    text = doc.split("\n\n")[0].split(": ", 1)[1]
    return text[0].upper() + text[1:]


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser whose usage errors are one line, "<prog>: error:
    <message>", with exit status 2 (--help shows the usage)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


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


DEFAULT_OUT = Path("results")  # relative to the current directory
BUILD_HELP = f"(default: ${BUILD_ENV}, else the installed package's own, else ./{DEFAULT_BUILD})"


# --- argparse types: each names the bad value ------------------------------------------------
def number(text, check=None, wanted=""):
    """An argparse type: float(text) when it is a finite number (and
    check(value) holds), else argparse.ArgumentTypeError naming the text and
    what is `wanted`."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or (check is not None and not check(value)):
        raise argparse.ArgumentTypeError(f"{text!r} is not {wanted or 'a finite number'}")
    return value


def positive(text):
    """An argparse type: a finite number > 0."""
    return number(text, lambda v: v > 0, "a finite number > 0")


def non_negative(text):
    """An argparse type: a finite number >= 0."""
    return number(text, lambda v: v >= 0, "a finite number >= 0")


def counting(minimum):
    """An argparse type: an integer >= minimum."""
    def integer(text):
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or value < minimum:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer >= {minimum}")
        return value
    integer.__name__ = f"integer >= {minimum}"
    return integer


def add_build_arg(ap, holding="PKM4PUU.fmu and PKM4PUU_Inverse.fmu"):
    """--build DIR; None when not given, for locate.build_dir to decide."""
    ap.add_argument("--build", type=Path, default=None, metavar="DIR",
                    help=f"build directory holding {holding} {BUILD_HELP}")


def _unwritable_dir(path, must_exist=False):
    """Why `path` cannot be written as a directory, or None: it is a
    writable directory or, unless `must_exist`, can be created as one (its
    nearest existing ancestor is a writable directory)."""
    probe = path
    while not must_exist and not probe.exists() and probe.parent != probe:
        probe = probe.parent
    if not probe.exists():
        return "no such directory"
    if not probe.is_dir():
        return f"{probe} is not a directory"
    try:  # the file system's answer, not the permission bits' (root passes those, yet /proc refuses it)
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as e:
        return f"{probe} is not writable ({e.strerror})"
    return None


def writable_dir(text, must_exist=False):
    """An argparse type: Path(text) when it is a writable directory or, unless
    `must_exist`, can be created as one; otherwise argparse.ArgumentTypeError
    naming the path and why, so that a wrong --out fails at once, before any
    run."""
    why = _unwritable_dir(Path(text), must_exist)
    if why:
        raise argparse.ArgumentTypeError(f"{text}: {why}")
    return Path(text)


def existing_file(text):
    """An argparse type: Path(text) when it is a file, else
    argparse.ArgumentTypeError naming the path and why."""
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text}: is a directory, not a file")
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"{text}: no such file")
    return path


def writable_file(text):
    """An argparse type: Path(text) when a file can be written there (it is
    no directory, and its directory is writable or can be created), else
    argparse.ArgumentTypeError naming the path and why."""
    path = Path(text)
    if path.is_dir():
        why = "is a directory"
    elif path.exists():
        why = None if os.access(path, os.W_OK) else "is not writable"
    else:
        why = _unwritable_dir(path.parent)
    if why:
        raise argparse.ArgumentTypeError(f"{text}: {why}")
    return path


def add_out_arg(ap, files):
    """--out DIR for the `files` a program writes (its help names them)."""
    ap.add_argument("--out", type=writable_dir, default=str(DEFAULT_OUT), metavar="DIR",
                    help=f"directory for {files} (default: ./%(default)s)")


def add_common_args(ap, files):
    """--build DIR and --out DIR (add_out_arg)."""
    add_build_arg(ap)
    add_out_arg(ap, files)


def figures_available(log):
    """True when the figures can be drawn (plots.available()); otherwise
    logs that they are left out, matplotlib missing, and how to install it."""
    if plots.available():
        return True
    log(f"figures skipped: matplotlib is not installed ({extras.install_command(['matplotlib'])} draws them)")
    return False


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


def start_report(command, description, files, argv, models=("PKM4PUU", "PKM4PUU_Inverse")):
    """The start of a report program of the pkm4puu command: its parser
    (--build, and --out for `files`), argv parsed, the FMUs found:
    (args, log, fmus, figures), fmus None when they are missing (logged),
    figures whether they can be drawn (figures_available)."""
    ap = ArgumentParser(prog=command_prog(command), description=description)
    add_common_args(ap, files)
    args, log, fmus = start(ap, argv, models, name=command)
    return args, log, fmus, fmus is not None and figures_available(log)


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
