# SPDX-License-Identifier: BSD-2-Clause
"""Speed against independent multibody engines, in one run (a benchmark, not
a test): one simulated second of the comparison test through this project
(`pkm_fmu_bench compare`, in C), MuJoCo and Pinocchio, the rounds
interleaved, each with its accuracy; then the inverse FMU's tick against
mj_inverse (`pkm_fmu_bench inverse`). Targets printed, never asserted.
"""
import argparse
import csv
import os
import platform
import subprocess
import sys
import tempfile
import timeit
from pathlib import Path

import numpy as np

import mujoco
import mujoco.rollout
import pinocchio as pin

from pkm4puu import motions, spec
from pkm4puu.cli import engine_comparison as ec
from pkm4puu.references import mujoco_model
from pkm4puu.references.pinocchio_model import PinocchioPKM

H = 1e-3
STEPS_TIMED = 1000  # one simulated second
PROGRAM = Path("bench") / "pkm_fmu_bench"  # in the build directory
OTHERS = {  # the other engines' rows: key -> (label, how the forces reach the integrator)
    "mujoco_rollout": ("MuJoCo: mj_step, RK4, 1 ms (mujoco.rollout, C loop)", "midpoint-held"),
    "mujoco_loop": ("MuJoCo: mj_step, RK4, 1 ms (Python loop)", "midpoint-held"),
    "pinocchio_rk4": ("Pinocchio: constraintDynamics, RK4, 1 ms (Python loop)", "at stage times"),
    "pinocchio_bare": ("Pinocchio: the 4000 constraintDynamics calls alone (4000 x one call below)", "")}


def log(msg):
    print(f"engines_bench: {msg}", file=sys.stderr, flush=True)


def run_program(program, args):
    proc = subprocess.run([str(program), *args], capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{program} {' '.join(args)} failed:\n{proc.stdout}\n{proc.stderr}")
    return proc.stdout


def c_cases(program, batches):
    """One run of `pkm_fmu_bench compare`: {case: its summary row, with its "run"}, and its output."""
    with tempfile.TemporaryDirectory() as tmp:
        out = run_program(program, ["compare", "--out", tmp, "--batches", str(batches)])
        with open(Path(tmp) / "summary.csv") as f:
            cases = {row["case"]: row for row in csv.DictReader(f)}
        runs = np.genfromtxt(Path(tmp) / "runs.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
        for key, c in cases.items():  # t, x, y, z, phi, delta_rho1, constraint
            c["run"] = {n: runs[n][runs["case"] == key] for n in runs.dtype.names[1:]}
    return cases, out


def mujoco_timers():
    """mj_step over the test: (in mujoco.rollout, MuJoCo's own C loop; in a Python loop; the reset before it)."""
    model, data = mujoco_model.build(g=0.0)
    sp = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(model, sp))
    mujoco.mj_getState(model, data, s0, sp)
    ctrl = np.array([motions.comparison_forces((k + 0.5) * H) for k in range(STEPS_TIMED)])

    def python_loop():
        for k in range(STEPS_TIMED):
            data.ctrl[:] = ctrl[k]
            mujoco.mj_step(model, data)
    return (lambda: mujoco.rollout.rollout(model, data, s0[None], ctrl[None]), python_loop,
            lambda: mujoco.mj_setState(model, data, s0, sp))


def pinocchio_timers(calls=2000):
    """constraintDynamics (C++) inside RK4 at 1 ms in Python, the forces at the stage times; and per call (each of
    `calls` at one state): constraintDynamics, and it followed by computeConstraintDynamicsDerivatives."""
    pm = PinocchioPKM(g=0.0)
    pm.setup_constraint_dynamics()
    q0, v0 = pm.q_from_pose(spec.P0), np.zeros(16)
    tau = [pm.S @ motions.comparison_forces(j * H / 2) for j in range(2 * STEPS_TIMED + 1)]

    def cd(q=q0, v=v0, f=tau[1]):
        return pin.constraintDynamics(pm.model, pm.data, q, v, f, pm._cm, pm._cd, pm._prox)

    def with_derivatives():
        cd()
        pin.computeConstraintDynamicsDerivatives(pm.model, pm.data, pm._cm, pm._cd, pm._prox)
    return (lambda: ec.rk4_on_manifold(pm.model, q0, v0, H, STEPS_TIMED, lambda q, v, k, i: cd(q, v, tau[2 * k + i])),
            lambda: (timeit.timeit(cd, number=calls) / calls, timeit.timeit(with_derivatives, number=calls) / calls))


def inverse_tick(program, batches):
    """`pkm_fmu_bench inverse` with MuJoCo's model of the same mechanism (the spec's gravity, no machine)."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "pkm4puu.xml").write_text(mujoco_model.mjcf())
        return run_program(program, ["inverse", "--batches", str(batches), "--mjcf", str(Path(tmp) / "pkm4puu.xml")])


def main(argv=None):
    ap = argparse.ArgumentParser(prog="engines_bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", type=Path, default=Path(os.environ.get("PKM_BUILD_DIR", "build")),
                    help=f"the build directory holding {PROGRAM} (default $PKM_BUILD_DIR, else ./build)")
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds of every case (default 5)")
    ap.add_argument("--batches", type=int, default=5, help="batches of 1 s simulated per case and round (default 5)")
    ap.add_argument("--quick", action="store_true", help="a short run (the documentation build's): few inverse batches")
    args = ap.parse_args(argv)
    program = args.build / PROGRAM
    if not program.is_file():
        ap.exit(2, f"engines_bench: no {program}: build it (cmake --build {args.build} --target pkm_fmu_bench)\n")

    rollout, python_loop, reset = mujoco_timers()
    rk4, per_call = pinocchio_timers()
    rollout(), rk4()  # warm-up
    rounds = []  # each round's {case: (median, best batch)}
    for r in range(args.rounds):
        log(f"round {r + 1} of {args.rounds}")
        cases, out = c_cases(program, args.batches)
        if r == 0:
            first, c_out = cases, out
        times = {key: (float(c["median_s_per_sim_s"]), float(c["min_s_per_sim_s"])) for key, c in cases.items()}
        for key, t in (("mujoco_rollout", timeit.repeat(rollout, repeat=args.batches, number=1)),
                       ("mujoco_loop", timeit.repeat(python_loop, reset, repeat=args.batches, number=1)),
                       ("pinocchio_rk4", timeit.repeat(rk4, repeat=1, number=1))):
            times[key] = (float(np.median(t)), float(np.min(t)))
        cd, dd = per_call()
        times.update(pinocchio_dynamics_call=(cd, cd), pinocchio_derivatives_call=(dd, dd),
                     pinocchio_bare=(4 * STEPS_TIMED * cd,) * 2)  # RK4's calls, at that cost
        rounds.append(times)
    median = {key: float(np.median([t[key][0] for t in rounds])) for key in rounds[0]}
    best = {key: min(t[key][1] for t in rounds) for key in rounds[0]}
    log("inverse dynamics: the inverse FMU's tick against mj_inverse")
    inverse_out = inverse_tick(program, 5 if args.quick else 51)

    log("accuracy: Pinocchio's reference (DOP853, rtol 1e-13) and each engine's whole 1.5 s run")
    ref = ec.pinocchio_reference("exact")
    runs = {key: c["run"] for key, c in first.items()}
    runs.update(mujoco_rollout=ec.mujoco_run(), pinocchio_rk4=ec.pinocchio_rk4(h=H))  # the whole test, untimed
    t_mj = median["mujoco_rollout"]

    def accuracy(run):  # ‖C(q)‖, and deviation() at the run's own output times (one-call cases have only a few)
        d = ec.deviation(run, {n: ref[n][np.rint(run["t"] / H).astype(int)] for n in ec.OUT})
        return f"{run['constraint'].max():.1e} | {d[0]:.1e} / {d[1]:.1e}"

    lines = ["| | time per simulated second, median (best) | MuJoCo's time / this | max ‖C(q)‖ (m) "
             "| max difference from the reference, position (m) / φ (rad) | forces |", "|---|---|---|---|---|---|"]
    ours = {key: (f"this project, {c['what']}", c["forces"]) for key, c in first.items()}
    for key, (label, forces) in {**ours, **OTHERS}.items():
        lines.append(f"| {label} | {1e3 * median[key]:.2f} ms ({1e3 * best[key]:.2f}) | {t_mj / median[key]:.1f}× | "
                     f"{accuracy(runs[key]) if key in runs else ' | '} | {forces} |")

    print(c_out.rstrip() + "\n")
    print(f"engines_bench: python {platform.python_version()}, mujoco {mujoco.__version__}, "
          f"pinocchio {pin.__version__}")
    print(f"one simulated second of the comparison test at a 1 ms step; {args.rounds} interleaved rounds of "
          f"{args.batches} batches (Pinocchio: 1 per round): median of the rounds' medians, and the best batch; "
          "‖C(q)‖ and the differences over the whole 1.5 s test (one-call rows: at 0.5, 1 and 1.5 s), against "
          "Pinocchio's DOP853 reference (rtol 1e-13, exact forces)\n")
    print("\n".join(lines) + "\n")
    t_cd, t_dd = median["pinocchio_dynamics_call"], median["pinocchio_derivatives_call"]
    print(f"derivatives, Pinocchio: constraintDynamics {1e6 * t_cd:.1f} us, with computeConstraintDynamicsDerivatives "
          f"{1e6 * t_dd:.1f} us per call (16 coordinates, 4 constraints, from Python): {t_dd / t_cd:.2f}x; this "
          "project's Jacobians A, B over one state derivative: pkm_bench, item 1b")
    adds = [1e3 * (t["mujoco_loop"] - t["mujoco_rollout"]) for t in (median, best)]  # us per 1 ms step
    print(f"a Python loop (mj_step + setting ctrl) adds {adds[0]:+.2f} us per mj_step to mujoco.rollout's C loop "
          f"(best batches: {adds[1]:+.2f} us)")
    print("the targets compare C loop with C loop (the FMU's ticks: step + 12-output read, against mj_step RK4 1 ms)")
    for key, c in first.items():  # each case's target: pkm_fmu_bench compare's table (bench/fmu/compare.c)
        target, ratio = float(c["target_vs_mujoco"]), t_mj / median[key]
        if target > 0:
            print(f"target (>= {target:.0f}x faster than MuJoCo): this project, {c['what']}: {ratio:.1f}x (best "
                  f"batches: {best['mujoco_rollout'] / best[key]:.1f}x): {'met' if ratio >= target else 'NOT met'}")
    print("\n" + inverse_out.rstrip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
