# SPDX-License-Identifier: BSD-2-Clause
"""The package's one command line: python -m pkm4puu COMMAND [ARGS...].

Each command is a report program of pkm4puu.validation, imported only when
it is run (the engine comparison needs pinocchio and mujoco, the figures
matplotlib); `python -m pkm4puu COMMAND --help` tells its arguments."""
import argparse
import importlib
import sys

# command -> (module of pkm4puu.validation with main(argv), what it does)
COMMANDS = {
    "autotest": ("autotest", "the paper's auto-test (section 5.1) through the FMUs: table, CSV and figures"),
    "comparison": ("comparison", "the paper's comparison test (section 5.2) through the plant FMU"),
    "plot-autotest": ("plot_cpp_autotest", "figures of the C++ auto-test's CSV files (pkm_autotest --out DIR)"),
    "engines": ("engine_comparison", "validation against independent Pinocchio and MuJoCo models"),
    "verdict": ("checks", "the main job's verdict: the checks its stages wrote, PASS/FAIL per bound"),
    "excitation": ("excitation", "an exciting trajectory for the identification: its condition number, CSV"),
    "identify": ("identify", "the dynamic parameters from a drive log (CSV of t, rho, F): FMU start values"),
    "cycle": ("cycle", "the time-optimal pick-and-place cycle within the drives' limits: time, CSV, figure"),
}


def parser():
    width = max(map(len, COMMANDS))
    listing = "\n".join(f"  {name:<{width}}  {what}" for name, (_, what) in COMMANDS.items())
    ap = argparse.ArgumentParser(prog="python -m pkm4puu", formatter_class=argparse.RawDescriptionHelpFormatter,
                                 description="The 4-PUU robot's reports through the built FMUs and C API.",
                                 epilog=f"commands:\n{listing}\n\n'python -m pkm4puu COMMAND --help' tells a "
                                 "command's arguments.")
    ap.add_argument("command", metavar="COMMAND", choices=list(COMMANDS), help="one of the commands below")
    ap.add_argument("args", metavar="ARGS", nargs="*", help="the command's arguments")
    return ap


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    ap = parser()
    if not argv:
        ap.print_help(sys.stderr)
        return 2
    if argv[0] in ("-h", "--help"):
        ap.parse_args(argv[:1])  # prints the commands, exits 0
    if argv[0].startswith("-"):
        ap.error(f"unrecognized option {argv[0]}: the first argument must be a command")
    ap.parse_args(argv[:1])  # an unknown command is an error that lists the commands
    module = importlib.import_module(f"pkm4puu.validation.{COMMANDS[argv[0]][0]}")
    return module.main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
