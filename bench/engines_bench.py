# SPDX-License-Identifier: BSD-2-Clause
"""Speed against independent multibody engines, side by side in one run (a
benchmark, not a test): one simulated second of the spec's comparison test
(g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), from rest at P0) at a 1 ms
step, through

  this project   the C API (libpkm.so) with RK4 and with CVODE, and the plant
                 FMU through the C harness (build/bench/pkm_fmu_bench compare,
                 plain C: no Python in any timed loop);
  MuJoCo         mj_step, RK4, 1 ms, the stiffest connect constraints
                 (pkm4puu.references.mujoco_model), timed in
                 mujoco.rollout (MuJoCo's own C loop) and, for context, in a
                 Python loop of mj_step (its Python overhead per step is
                 printed);
  Pinocchio      constrained forward dynamics: fixed-step RK4 at 1 ms around
                 pinocchio.constraintDynamics (C++), the loop in Python; and,
                 for context, the 4000 bare constraintDynamics calls alone;
                 and the cost of its derivatives,
                 computeConstraintDynamicsDerivatives after constraintDynamics,
                 printed beside this project's (pkm_bench item 1b, run here:
                 state_derivative_jacobians over state_derivative).

For each: the median wall time per simulated second, the ratio of MuJoCo's
time to it (how many times faster than MuJoCo), the largest ||C(q)|| over the
whole 1.5 s test (the project's own constraint_residual, and ||C(q)|| from
docs/model.md's formula on the engines' coordinates), and the largest difference
from Pinocchio's tightly integrated reference (engine_comparison.py: DOP853,
rtol 1e-13, exact forces).

Timing: --rounds R (default 5) rounds, each timing every case with --batches
B (default 5) batches of one simulated second (Pinocchio: 1), interleaved so
that a burst of load on a shared machine spreads over all cases; the table
gives the median of the rounds' medians and the best batch. The C harness
also runs two one-call C API cases (the simulated second as a single
pkm_advance_fn: RK4 at 1 ms, and CVODE rtol 1e-12 taking its own steps).

two control-tick cases of the plant FMU (step + the 12
controller outputs: RK4 with midpoint-held forces, and CVODE at its default
tolerances with the forces as a continuous ramp, value and slope each tick)
are printed against their targets (15x and 10x MuJoCo's mj_step). Both sides
are C loops (the C harness, mujoco.rollout), so neither pays Python's
per-call overhead.

usage: .venv/bin/python bench/engines_bench.py [--build DIR] [--rounds R] [--batches B] [--markdown FILE] [--quick]
"""
import argparse
import csv
import math
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import mujoco
import mujoco.rollout
import pinocchio as pin

from pkm4puu import motions, spec
from pkm4puu.cli.engine_comparison import deviation, pinocchio_reference
from pkm4puu.program import add_build_arg, find_build, machine_description, prefixed_log
from pkm4puu.references import mujoco_model
from pkm4puu.references.pinocchio_model import PinocchioPKM

# This benchmark's programs, in the build directory (bench/CMakeLists.txt).
BENCH_PROGRAM = "bench/pkm_bench"  # the C++ benchmark (bench/pkm_bench.cpp)
FMU_BENCH_PROGRAM = "bench/pkm_fmu_bench"  # the FMU's C harness; its `compare` is run here

H = 1e-3
STEPS_TIMED = 1000  # one simulated second
STEPS_TEST = 1500  # the whole comparison test, for ||C|| and the accuracy


def _rows_from_q(Q):
    Q = np.asarray(Q)
    return {"x": Q[:, 12], "y": Q[:, 13], "z": Q[:, 14], "phi": Q[:, 15], "delta_rho1": Q[:, 0] - Q[0, 0],
            "constraint": np.array([np.linalg.norm(spec.constraint_residual(q)) for q in Q])}


# --- this project, through the C harness ---------------------------------------------------------------
def run_c_harness(build, batches, log, keep_runs=True):
    """One run of the C harness: {case: {"what", "median", "min", "max_c", "run"}}, and its stdout."""
    exe = build / FMU_BENCH_PROGRAM
    if not exe.is_file():
        raise FileNotFoundError(f"{exe} not found: build the project first (cmake --build {build})")
    with tempfile.TemporaryDirectory() as tmp:
        log(f"running {exe} compare --batches {batches}")
        proc = subprocess.run([str(exe), "compare", "--out", tmp, "--batches", str(batches)], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"{exe} failed:\n{proc.stdout}\n{proc.stderr}")
        cases = {}
        with open(Path(tmp) / "summary.csv") as f:
            for row in csv.DictReader(f):
                run = None
                if keep_runs:
                    data = np.genfromtxt(Path(tmp) / f"{row['case']}.csv", delimiter=",", names=True)
                    run = {"t": data["t"], "x": data["x"], "y": data["y"], "z": data["z"], "phi": data["phi"],
                           "delta_rho1": data["rho1"] - data["rho1"][0]}
                cases[row["case"]] = {
                    "what": row["what"], "median": float(row["median_s_per_sim_s"]),
                    "min": float(row["min_s_per_sim_s"]), "max_c": float(row["max_constraint_residual"]),
                    "run": run}
    return cases, proc.stdout


# --- MuJoCo -------------------------------------------------------------------------------------------------
class MuJoCoBench:
    """MuJoCo's comparison test: (a) mujoco.rollout, MuJoCo's own C loop of
    mj_step; (b) a Python loop of mj_step (context)."""

    def __init__(self):
        self.model, self.data = mujoco_model.build(g=0.0)
        self.sp = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self.s0 = np.empty(mujoco.mj_stateSize(self.model, self.sp))
        mujoco.mj_getState(self.model, self.data, self.s0, self.sp)
        self.ctrl = np.array([motions.comparison_forces((k + 0.5) * H) for k in range(STEPS_TEST)])
        self.rollout(1)  # warm-up

    def rollout(self, batches):
        c1 = self.ctrl[None, :STEPS_TIMED]
        per = []
        for _ in range(batches):
            t0 = time.perf_counter()
            mujoco.rollout.rollout(self.model, self.data, self.s0[None], c1)
            per.append(time.perf_counter() - t0)
        return per

    def python_loop(self, batches):
        m, d = self.model, self.data
        per = []
        for _ in range(batches):
            mujoco.mj_setState(m, d, self.s0, self.sp)
            t0 = time.perf_counter()
            for k in range(STEPS_TIMED):
                d.ctrl[:] = self.ctrl[k]
                mujoco.mj_step(m, d)
            per.append(time.perf_counter() - t0)
        return per

    def test_run(self):
        """The whole 1.5 s test, for ||C(q)|| and the accuracy."""
        state, _ = mujoco.rollout.rollout(self.model, self.data, self.s0[None], self.ctrl[None])
        nq = self.model.nq
        Q = np.vstack([self.s0[1:1 + nq], state[0][:, 1:1 + nq]])  # FULLPHYSICS: time, qpos, ...
        out = _rows_from_q(Q)
        out["t"] = np.arange(len(Q)) * H
        return out


# --- Pinocchio -------------------------------------------------------------------------------------------------
class PinocchioBench:
    """Pinocchio's constrained forward dynamics: RK4 at 1 ms around
    pinocchio.constraintDynamics (C++), the loop in Python, forces at the
    stage times; and the bare constraintDynamics calls alone."""

    def __init__(self):
        pm = PinocchioPKM(g=0.0)
        pm.setup_constraint_dynamics()
        self.pm = pm
        self.q0, self.v0 = pm.q_from_pose(spec.P0), np.zeros(16)
        self.tau = [pm.S @ motions.comparison_forces(j * H / 2) for j in range(2 * STEPS_TEST + 1)]
        self.run(10)  # warm-up

    def run(self, n, keep=False):
        pm = self.pm
        cd, m, data, cm, cdata, prox = pin.constraintDynamics, pm.model, pm.data, pm._cm, pm._cd, pm._prox
        integrate, tau = pin.integrate, self.tau
        q, v = self.q0, self.v0
        Q = [q] if keep else None
        for k in range(n):
            f0, fm, f1 = tau[2 * k], tau[2 * k + 1], tau[2 * k + 2]
            a1 = cd(m, data, q, v, f0, cm, cdata, prox)
            v2 = v + a1 * (H / 2)
            a2 = cd(m, data, integrate(m, q, v * (H / 2)), v2, fm, cm, cdata, prox)
            v3 = v + a2 * (H / 2)
            a3 = cd(m, data, integrate(m, q, v2 * (H / 2)), v3, fm, cm, cdata, prox)
            v4 = v + a3 * H
            a4 = cd(m, data, integrate(m, q, v3 * H), v4, f1, cm, cdata, prox)
            q = integrate(m, q, (H / 6) * (v + 2 * v2 + 2 * v3 + v4))
            v = v + (H / 6) * (a1 + 2 * a2 + 2 * a3 + a4)
            if keep:
                Q.append(q)
        return Q

    def rk4(self, batches):
        per = []
        for _ in range(batches):
            t0 = time.perf_counter()
            self.run(STEPS_TIMED)
            per.append(time.perf_counter() - t0)
        return per

    def bare(self, batches):
        pm = self.pm
        cd, m, data, cm, cdata, prox = pin.constraintDynamics, pm.model, pm.data, pm._cm, pm._cd, pm._prox
        per = []
        for _ in range(batches):
            t0 = time.perf_counter()
            for _ in range(4 * STEPS_TIMED):
                cd(m, data, self.q0, self.v0, self.tau[1], cm, cdata, prox)
            per.append(time.perf_counter() - t0)
        return per

    def derivatives(self, calls=2000):
        """Per call: constraintDynamics alone, and followed by
        computeConstraintDynamicsDerivatives (d ddq / d(q, v, tau), 16 x 48)."""
        pm = self.pm
        cd, m, data, cm, cdata, prox = pin.constraintDynamics, pm.model, pm.data, pm._cm, pm._cd, pm._prox
        dd = pin.computeConstraintDynamicsDerivatives
        q, v, f = self.q0, self.v0, self.tau[1]
        t0 = time.perf_counter()
        for _ in range(calls):
            cd(m, data, q, v, f, cm, cdata, prox)
        t1 = time.perf_counter()
        for _ in range(calls):
            cd(m, data, q, v, f, cm, cdata, prox)
            dd(m, data, cm, cdata, prox)
        t2 = time.perf_counter()
        return (t1 - t0) / calls, (t2 - t1) / calls

    def test_run(self):
        out = _rows_from_q(self.run(STEPS_TEST, keep=True))
        out["t"] = np.arange(STEPS_TEST + 1) * H
        return out


# --- derivatives -----------------------------------------------------------------------------------------------
def derivatives_comparison(build, median, bench_args=()):
    """The cost of the dynamics' derivatives over the cost of the dynamics:
    Pinocchio's computeConstraintDynamicsDerivatives after constraintDynamics
    (this run, Python calls), and this project's state_derivative_jacobians
    over state_derivative (pkm_bench item 1b, run now, if built)."""
    t_cd, t_dd = median["pinocchio_dynamics_call"], median["pinocchio_derivatives_call"]
    print(f"derivatives, Pinocchio: constraintDynamics {1e6 * t_cd:.1f} us, with "
          f"computeConstraintDynamicsDerivatives {1e6 * t_dd:.1f} us per call (16 coordinates, 4 constraints, "
          f"from Python): {t_dd / t_cd:.2f}x")
    exe = build / BENCH_PROGRAM
    if not exe.exists():
        print(f"derivatives, this project: {exe} not built")
        return
    out = subprocess.run([str(exe), *bench_args], capture_output=True, text=True, check=False).stdout
    rows = [line.strip() for line in out.splitlines()
            if "state_derivative (LegPartitioned, baseline)" in line or "state_derivative_jacobians:" in line]
    for line in rows:
        print(f"derivatives, this project (pkm_bench 1b): {' '.join(line.split())}")


# --- the table -----------------------------------------------------------------------------------------------------
def deviation_at(run, ref):
    """deviation() at the run's own output times (one-call cases have only a few)."""
    idx = np.rint(np.asarray(run["t"]) / H).astype(int)
    sub = {n: ref[n][idx] for n in ("x", "y", "z", "phi", "delta_rho1")}
    return deviation({n: run[n] for n in sub}, sub)


LABELS = {  # harness case: (label, how the forces reach the integrator)
    "capi_rk4": ("this project, C API: RK4, 1 ms", "at stage times"),
    "capi_cvode": ("this project, C API: CVODE (default rtol 1e-8), stop every 1 ms", "at solver times"),
    "capi_cvode_tight": ("this project, C API: CVODE (rtol 1e-12), stop every 1 ms", "at solver times"),
    "fmu_rk4": ("this project, plant FMU (C harness): RK4, 1 ms, + get x, y, z, φ", "midpoint-held"),
    "fmu_cvode": ("this project, plant FMU (C harness): CVODE (rtol 1e-8), + get x, y, z, φ", "midpoint-held"),
    "fmu_rk4_ctrl12": ("this project, plant FMU (C harness): RK4, 1 ms, + get 12 controller outputs", "midpoint-held"),
    "fmu_cvode_ramp_ctrl12": ("this project, plant FMU (C harness): CVODE (rtol 1e-8), continued, "
                              "+ get 12 controller outputs", "ramp: value and slope each tick"),
    "capi_rk4_one_call": ("this project, C API: RK4, 1 ms, one call per second", "at stage times"),
    "capi_cvode_one_call": ("this project, C API: CVODE (rtol 1e-12), own steps, one call", "at solver times"),
}


def main(argv=None):
    prog = "engines_bench"
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    add_build_arg(ap, FMU_BENCH_PROGRAM)
    ap.add_argument("--rounds", type=int, default=5,
                    help="rounds; each times every case, interleaved, so that a burst of load on a shared "
                         "machine spreads over all of them (default 5)")
    ap.add_argument("--batches", type=int, default=5,
                    help="timed batches of 1 simulated second per case and round (default 5)")
    ap.add_argument("--markdown", type=Path, help="also write the table, in Markdown, to this file")
    ap.add_argument("--quick", action="store_true",
                    help="a short run (the documentation build's): pkm_bench --quick for the derivatives' row; "
                         "give small --rounds and --batches with it")
    args = ap.parse_args(argv)
    log = prefixed_log(prog)
    build = find_build(args.build, log)
    if build is None:
        return 1

    mj, pb = MuJoCoBench(), PinocchioBench()
    times = {}  # case -> list of per-round medians; best[case] = min over everything
    best = {}

    def add(case, per):
        times.setdefault(case, []).append(float(np.median(per)))
        best[case] = min(best.get(case, math.inf), min(per))

    c_cases, c_stdout = None, ""
    for r in range(args.rounds):
        log(f"round {r + 1} of {args.rounds}")
        cases, out = run_c_harness(build, args.batches, log, keep_runs=(r == 0))
        if r == 0:
            c_cases, c_stdout = cases, out
        for key, c in cases.items():
            times.setdefault(key, []).append(c["median"])
            best[key] = min(best.get(key, math.inf), c["min"])
        add("mujoco_rollout", mj.rollout(args.batches))
        add("mujoco_loop", mj.python_loop(args.batches))
        add("pinocchio_rk4", pb.rk4(1))
        add("pinocchio_bare", pb.bare(1))
        add("pinocchio_dynamics_call", [pb.derivatives()[0]])
        add("pinocchio_derivatives_call", [pb.derivatives()[1]])
    median = {k: float(np.median(v)) for k, v in times.items()}

    log("accuracy: Pinocchio reference (DOP853, rtol 1e-13), and each engine's whole 1.5 s run")
    ref = pinocchio_reference("exact")
    mj_run, pin_run = mj.test_run(), pb.test_run()

    rows = []  # label, case, max ||C|| or None, (d_pos, d_phi) or None, forces
    for key, (label, forces) in LABELS.items():
        c = c_cases[key]
        rows.append((label, key, c["max_c"], deviation_at(c["run"], ref), forces))
    rows.append(("MuJoCo: mj_step, RK4, 1 ms (mujoco.rollout, C loop)", "mujoco_rollout",
                 mj_run["constraint"].max(), deviation_at(mj_run, ref), "midpoint-held"))
    rows.append(("MuJoCo: mj_step, RK4, 1 ms (Python loop)", "mujoco_loop", None, None, "midpoint-held"))
    rows.append(("Pinocchio: constraintDynamics, RK4, 1 ms (Python loop)", "pinocchio_rk4",
                 pin_run["constraint"].max(), deviation_at(pin_run, ref), "at stage times"))
    rows.append(("Pinocchio: the 4000 constraintDynamics calls alone", "pinocchio_bare", None, None, ""))

    t_mj = median["mujoco_rollout"]
    lines = ["| | time per simulated second, median (best) | MuJoCo's time / this | max ‖C(q)‖ (m) "
             "| max difference from the reference, position (m) / φ (rad) | forces |",
             "|---|---|---|---|---|---|"]
    for label, key, c, d, f in rows:
        cs = "" if c is None else f"{c:.1e}"
        ds = "" if d is None else f"{d[0]:.1e} / {d[1]:.1e}"
        lines.append(f"| {label} | {1e3 * median[key]:.2f} ms ({1e3 * best[key]:.2f}) | "
                     f"{t_mj / median[key]:.1f}× | {cs} | {ds} | {f} |")
    table = "\n".join(lines)

    print(c_stdout.rstrip())
    print()
    print(f"engines_bench: {machine_description()}; python {platform.python_version()}, mujoco {mujoco.__version__}, "
          f"pinocchio {pin.__version__}")
    print(f"one simulated second of the comparison test at a 1 ms step; {args.rounds} interleaved rounds of "
          f"{args.batches} batches (Pinocchio: 1 per round): median of the rounds' medians, and the best batch; "
          "‖C(q)‖ and the differences over the whole 1.5 s test (one-call rows: at 0.5, 1 and 1.5 s), against "
          "Pinocchio's DOP853 reference (rtol 1e-13, exact forces)")
    print()
    print(table)
    print()
    derivatives_comparison(build, median, ["--quick"] if args.quick else [])
    for key in ("capi_rk4", "capi_cvode", "capi_cvode_tight", "capi_cvode_one_call"):
        ratio = t_mj / median[key]
        # ||C|| <= 1e-12 m is a test's verdict (python_checks/test_fmu_comparison.py, test_engines_forward.py)
        print(f"target (>= 10x faster than MuJoCo): {LABELS[key][0]}: {ratio:.1f}x "
              f"(best batches: {best['mujoco_rollout'] / best[key]:.1f}x): {'met' if ratio >= 10.0 else 'NOT met'}; "
              f"max ||C|| {c_cases[key]['max_c']:.1e} m")
    # a control tick of the plant FMU (step + the 12 controller outputs) against mj_step, both
    # timed in a C loop (the C harness; mujoco.rollout), so neither carries Python's per-call overhead.
    for how, t in (("median", median), ("best batches", best)):
        per_step_c, per_step_py = t["mujoco_rollout"] / STEPS_TIMED, t["mujoco_loop"] / STEPS_TIMED
        print(f"mj_step per 1 ms step ({how}): {1e6 * per_step_c:.2f} us in mujoco.rollout (C loop), "
              f"{1e6 * per_step_py:.2f} us in a Python loop (mj_step + setting ctrl): the Python loop adds "
              f"{1e6 * (per_step_py - per_step_c):+.2f} us per step")
    print("the ratios below compare C loop with C loop: the C harness's ticks against mujoco.rollout")
    for key, target in (("fmu_rk4_ctrl12", 15.0), ("fmu_cvode_ramp_ctrl12", 10.0)):
        ratio = t_mj / median[key]
        print(f"target (step + 12-output read >= {target:.0f}x faster than mj_step RK4 1 ms): {LABELS[key][0]} "
              f"({LABELS[key][1]}): {1e6 * median[key] / STEPS_TIMED:.2f} us per tick, {ratio:.1f}x "
              f"(best batches: {best['mujoco_rollout'] / best[key]:.1f}x): {'met' if ratio >= target else 'NOT met'}")
    print(f"MuJoCo's own max ||C(q)|| at its stiffest: {mj_run['constraint'].max():.1e} m")
    if args.markdown:
        args.markdown.write_text(table + "\n")
        log(f"wrote {args.markdown}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
