# SPDX-License-Identifier: BSD-2-Clause
"""The pkm4puu command: pkm4puu COMMAND [ARGS...] (or python -m pkm4puu).

The programs, one module of this subpackage per command with main(argv),
each imported only when its command runs. They use the library (the rest
of the package) and nothing of theirs is the library's. A command that
needs an extra the installation lacks (the figures: plots; the engine
comparison: references; the identification: calibration) says in one line
which to install and exits 2; `pkm4puu COMMAND --help` works without any.
"""
import argparse
import importlib
import sys

from .._version import __version__
from ..extras import MissingExtra
from ..program import ArgumentParser, invoked_as

# command -> (module of pkm4puu.cli with main(argv), what it does)
COMMANDS = {
    "autotest": ("autotest", "the paper's auto-test (section 5.1) through the FMUs: table, CSV and figures"),
    "comparison": ("comparison", "the paper's comparison test (section 5.2) through the plant FMU"),
    "plot-autotest": ("plot_cpp_autotest", "figures of the C++ auto-test's CSV files (pkm_autotest --out DIR)"),
    "engines": ("engines", "validation against independent Pinocchio and MuJoCo models"),
    "verdict": ("checks", "the main job's verdict: the checks its stages wrote, PASS/FAIL per bound"),
    "excitation": ("excitation", "an exciting trajectory for the identification: its condition number, CSV"),
    "identify": ("identify", "the dynamic parameters from a drive log (CSV of t, rho, F): FMU start values"),
    "cycle": ("cycle", "the time-optimal pick-and-place cycle within the drives' limits: time, CSV, figure"),
}


def parser():
    prog = invoked_as()
    width = max(map(len, COMMANDS))
    listing = "\n".join(f"  {name:<{width}}  {what}" for name, (_, what) in COMMANDS.items())
    ap = ArgumentParser(prog=prog, formatter_class=argparse.RawDescriptionHelpFormatter,
                        description="The 4-PUU robot's programs: the paper's tests and reports through the\n"
                        "FMUs and the C API, the identification of its dynamic parameters.",
                        epilog=f"commands:\n{listing}\n\n'{prog} COMMAND --help' tells a command's "
                        "arguments.")
    ap.add_argument("--version", action="version", version=f"pkm4puu {__version__}")
    ap.add_argument("command", metavar="COMMAND", choices=list(COMMANDS), help="one of the commands below")
    ap.add_argument("args", metavar="ARGS", nargs="*", help="the command's arguments")
    return ap


def main(argv=None):
    """Runs the command argv[0] with the arguments argv[1:]; its exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = parser()
    if not argv:
        ap.print_help(sys.stderr)
        return 2
    if argv[0] in ("-h", "--help", "--version"):
        ap.parse_args(argv[:1])  # prints the commands or the version, exits 0
    if argv[0].startswith("-"):
        ap.error(f"unrecognized option {argv[0]}: the first argument must be a command")
    ap.parse_args(argv[:1])  # an unknown command is an error that lists the commands
    module = importlib.import_module(f"{__name__}.{COMMANDS[argv[0]][0]}")
    try:
        return module.main(argv[1:])
    except MissingExtra as e:
        print(f"{invoked_as()} {argv[0]}: error: {e.needs}", file=sys.stderr)
        return 2
