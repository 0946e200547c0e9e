"""The cost of the dynamics' derivatives, this project's beside Pinocchio's, in
one run (a benchmark, not a test; issue 13, item 5). At one state, the
auto-test at t = 1 s (MODEL_SPEC: pose, rates and the inverse dynamics'
forces there), per call:

  this project, through the C API (ctypes, buffers made once):
    jacobian   pkm_forward_derivatives: ydot, A (8x8) and B (8x12)
    one ydot   pkm_get_outputs at the state pkm_init_pose set: the C API's
               one state derivative (the C API has no bare ydot: its outputs
               also carry the leg coordinates, lambda, ||C(q)|| and the
               actuator Jacobian's condition number, so through the C API
               the ratio Jacobian / one ydot comes out below 1; pkm_bench's
               item 1b gives the ratio of the bare evaluations)
    a call     pkm_get_state: what a ctypes call costs by itself
  Pinocchio, on the independent model (pkm4puu.validation.references), from Python:
    dynamics   constraintDynamics (qdd of the 16 coordinates, 12 loop closures)
    derivs     constraintDynamics + computeConstraintDynamicsDerivatives
               (d qdd / d(q, v, tau), 16 x 48)
    reduced    the reduced ydot, A, B assembled from those
               (pinocchio_derivatives.py: what this project's call returns)

and, if built, pkm_bench's item 1b: the same two evaluations in C++ with no
Python between the calls.

Printed ratios: Jacobian / one state derivative (the project's, with and
without the call cost; Pinocchio's); the project's Jacobian against
Pinocchio's derivatives. Also the largest difference between the two
Jacobians at this state, so that both are seen to compute the same thing.

Timing: --rounds R rounds (default 7), each timing every case over --calls N
calls (default 2000), interleaved, so that a burst of load on a shared
machine spreads over all of them; the table gives the median of the rounds
and the best round.

usage: .venv/bin/python bench/derivatives_bench.py [--build DIR] [--rounds R] [--calls N] [--no-pkm-bench]
"""
import argparse
import ctypes as ct
import platform
import subprocess
import sys
import time

import numpy as np
import pinocchio as pin

from pkm4puu import capi, motions
from pkm4puu.validation.cli import add_build_arg, find_build, machine_description, prefixed_log
from pkm4puu.locate import BENCH_PROGRAM, build_path
from pkm4puu.validation.references.pinocchio_derivatives import PinocchioReducedDerivatives

T_STATE = 1.0  # s into the auto-test


def per_call(fn, calls):
    t0 = time.perf_counter()
    for _ in range(calls):
        fn()
    return (time.perf_counter() - t0) / calls


class Cases:
    """The timed calls, each a closure over buffers made once."""

    def __init__(self, lib):
        self.model = capi.Plant(lib)
        pose, rate, acc = motions.autotest_motion(T_STATE)
        F = np.array(self.model.inverse_dynamics(pose, rate, acc).F[:])
        self.y = np.concatenate([pose, rate])
        self.u = np.concatenate([F, np.zeros(8)])
        self.model.init_pose(0.0, pose, rate)
        h = self.model.handle
        t = ct.c_double()
        y = (ct.c_double * 8)(*self.y)
        u = (ct.c_double * 12)(*self.u)
        ydot, A, B = (ct.c_double * 8)(), (ct.c_double * 64)(), (ct.c_double * 96)()
        F4 = (ct.c_double * 4)(*F)
        out = capi.Outputs()

        def jacobian():
            lib.pkm_forward_derivatives(h, y, u, ydot, A, B)

        def one_ydot():
            lib.pkm_get_outputs(h, F4, None, ct.byref(out))

        y_back = (ct.c_double * 8)()

        def a_call():
            lib.pkm_get_state(h, ct.byref(t), y_back, None)

        ref = PinocchioReducedDerivatives()
        pm = ref.pm
        q = pm.q_from_pose(pose)
        T, _ = ref.tangent(q)
        v = T @ rate
        tau = ref.generalized_forces(v, self.u)
        m, d, cm, cd, prox = pm.model, pm.data, pm._cm, pm._cd, pm._prox
        cdyn, cder = pin.constraintDynamics, pin.computeConstraintDynamicsDerivatives

        def pin_dynamics():
            cdyn(m, d, q, v, tau, cm, cd, prox)

        def pin_derivatives():
            cdyn(m, d, q, v, tau, cm, cd, prox)
            cder(m, d, cm, cd, prox)

        def pin_reduced():
            ref(self.y, self.u)

        self.ref = ref
        self.cases = {"capi_jacobian": jacobian, "capi_ydot": one_ydot,
                      "capi_call": a_call,
                      "pin_dynamics": pin_dynamics, "pin_derivatives": pin_derivatives, "pin_reduced": pin_reduced}
        # the two Jacobians at this state, and ydot from the two C API routes
        jacobian()
        one_ydot()
        self.A, self.B = np.array(A[:]).reshape(8, 8), np.array(B[:]).reshape(8, 12)
        self.ydot, self.acc_outputs = np.array(ydot[:]), np.array(out.acceleration[:])

    def agreement(self):
        _, Ar, Br = self.ref(self.y, self.u)
        return (np.abs(self.A - Ar).max() / np.abs(Ar).max(), np.abs(self.B - Br).max() / np.abs(Br).max(),
                np.abs(self.ydot[4:] - self.acc_outputs).max())


def pkm_bench_1b(build, log):
    exe = build_path(BENCH_PROGRAM, build)
    if not exe.is_file():
        return [f"{exe} not built"]
    log(f"running {exe} (about 10 s) for its item 1b")
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=False).stdout
    return [" ".join(line.split()) for line in out.splitlines()
            if "state_derivative (LegPartitioned, baseline)" in line or "state_derivative_jacobians:" in line]


LABELS = {
    "capi_jacobian": "this project, C API: pkm_forward_derivatives (ydot, A 8x8, B 8x12)",
    "capi_ydot": "this project, C API: pkm_get_outputs (one ydot, and more)",
    "capi_call": "this project, C API: pkm_get_state (the cost of a ctypes call)",
    "pin_dynamics": "Pinocchio: constraintDynamics (16 coordinates, 12 closures)",
    "pin_derivatives": "Pinocchio: constraintDynamics + computeConstraintDynamicsDerivatives",
    "pin_reduced": "Pinocchio: reduced ydot, A, B assembled (pinocchio_derivatives.py)",
}


def main(argv=None):
    prog = "derivatives_bench"
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    add_build_arg(ap, f"libpkm.so and {BENCH_PROGRAM}")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds (default %(default)s)")
    ap.add_argument("--calls", type=int, default=2000, help="calls per case and round (default %(default)s)")
    ap.add_argument("--no-pkm-bench", action="store_true", help="do not run pkm_bench for its C++ item 1b")
    args = ap.parse_args(argv)
    if args.rounds < 1 or args.calls < 1:
        ap.error("--rounds and --calls must be >= 1")
    log = prefixed_log(prog)
    build = find_build(args.build, log)
    if build is None:
        return 1
    lib_path = capi.library_path(build)
    if not lib_path.is_file():
        log(f"error: {lib_path} not found: build the project first, or pass --build DIR")
        return 1
    cases = Cases(capi.load(lib_path))
    times = {k: [] for k in cases.cases}
    for r in range(args.rounds):
        log(f"round {r + 1} of {args.rounds}")
        for key, fn in cases.cases.items():
            fn()  # warm
            times[key].append(per_call(fn, args.calls))
    med = {k: float(np.median(v)) for k, v in times.items()}
    best = {k: float(np.min(v)) for k, v in times.items()}
    c1b = [] if args.no_pkm_bench else pkm_bench_1b(build, log)
    dA, dB, dydot = cases.agreement()

    print(f"{prog}: {machine_description()}; python {platform.python_version()}, pinocchio {pin.__version__}")
    print(f"at the auto-test's state at t = {T_STATE:g} s with its inverse-dynamics forces; {args.rounds} interleaved "
          f"rounds of {args.calls} calls per case: median of the rounds (best round)")
    print()
    print("| | per call, median (best) |")
    print("|---|---|")
    for key, label in LABELS.items():
        print(f"| {label} | {1e6 * med[key]:.2f} µs ({1e6 * best[key]:.2f}) |")
    print()
    call = med["capi_call"]
    print("ratios (medians):")
    print(f"  this project, Jacobian / one ydot, through ctypes:                 "
          f"{med['capi_jacobian'] / med['capi_ydot']:.2f}x")
    print(f"  this project, the same less the cost of a ctypes call:             "
          f"{(med['capi_jacobian'] - call) / (med['capi_ydot'] - call):.2f}x  (pkm_get_outputs computes more than ydot)")
    print(f"  Pinocchio, derivatives with dynamics / dynamics alone:             "
          f"{med['pin_derivatives'] / med['pin_dynamics']:.2f}x")
    print(f"  Pinocchio, reduced ydot, A, B / dynamics alone:                    "
          f"{med['pin_reduced'] / med['pin_dynamics']:.2f}x")
    print(f"  this project's Jacobian / Pinocchio's derivatives (16 x 48):       "
          f"{med['capi_jacobian'] / med['pin_derivatives']:.3f}x  (Pinocchio's takes "
          f"{med['pin_derivatives'] / med['capi_jacobian']:.1f}x as long)")
    print(f"  this project's Jacobian / Pinocchio's reduced A, B:                "
          f"{med['capi_jacobian'] / med['pin_reduced']:.4f}x  (Pinocchio's takes "
          f"{med['pin_reduced'] / med['capi_jacobian']:.0f}x as long, most of it Python)")
    print(f"same state, same thing: |A - A_pinocchio| / max|A_pinocchio| = {dA:.1e}, B: {dB:.1e}; "
          f"ydot from pkm_forward_derivatives and pkm_get_outputs within {dydot:.1e}")
    for line in c1b:
        print(f"C++ (pkm_bench 1b, no Python): {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
