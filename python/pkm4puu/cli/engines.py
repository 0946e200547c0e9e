# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu engines: validation against Pinocchio and MuJoCo models of the
same mechanism: inverse dynamics along the auto-test, the comparison test,
the machine's terms (engine_comparison.py runs them, engine_report.py
reports them). Prints the tables, writes engines_comparison.csv and the
figures to --out DIR, exits 1 when a bound is not met. Needs the extra `references` (Pinocchio, MuJoCo, SciPy);
the figures the extra `plots`.
"""

from .. import extras
from ..fmu import find_fmu
from ..locate import library_path
from ..program import (ArgumentParser, add_build_arg, add_out_arg, command_prog, description, figures_available,
                       prefixed_log)

NEEDS = ("pinocchio", "mujoco", "scipy")


def parser():
    ap = ArgumentParser(prog=command_prog("engines"), description=description(__doc__))
    add_build_arg(ap, "libpkm and the FMUs")
    add_out_arg(ap, "engines_comparison.csv and, with matplotlib, engines_pose.png, engines_delta_rho1.png and "
                "engines_differences.png")
    ap.add_argument("--no-sweep", action="store_true", help="skip the table of MuJoCo constraint settings")
    return ap


def main(argv=None):
    ap = parser()
    args = ap.parse_args(argv)
    extras.require(ap.prog, *NEEDS)
    import mujoco
    import pinocchio

    from . import engine_comparison as ec, engine_report
    log = prefixed_log(ap.prog)
    try:
        plant, inverse = (find_fmu(model, 2, args.build) for model in ("PKM4PUU", "PKM4PUU_Inverse"))
        ec.load_capi(args.build)
    except FileNotFoundError as e:
        log(f"error: {e}")
        return 1
    figures = figures_available(log)
    print(f"engines: pinocchio {pinocchio.__version__}, mujoco {mujoco.__version__}; "
          f"{library_path(args.build)}, {plant}, {inverse}", flush=True)
    r = ec.run_all(args.build, plant, inverse, log=log)
    sweep = None
    if not args.no_sweep:
        log("MuJoCo constraint settings")
        sweep = ec.run_sweep(r["ref_held"])
    print(engine_report.format_tables(r, sweep), flush=True)
    for path in engine_report.write_results(r, args.out, figures):
        log(f"wrote {path}")
    bad = engine_report.check(r)
    for msg in bad:
        log(f"FAILED: {msg}")
    return 1 if bad else 0
