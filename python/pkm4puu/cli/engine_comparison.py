# SPDX-License-Identifier: BSD-2-Clause
"""Validation against independent multibody engines (the paper's section 5.2,
done with open tools): Pinocchio and MuJoCo models of the same mechanism,
built from docs/model.md's numbers only (pkm4puu.references), against this
project's C API (libpkm.so) and FMUs.

This module holds the runners and the quantities the checks look at;
engine_report.py turns their results into tables, files and the verdict,
and the checks are in test_engines_*.py. `pkm4puu engines` (engines.py)
runs everything, prints the tables and writes to --out DIR:

  engines_comparison.csv    the comparison test: Pinocchio (reference), C API,
                            plant FMU and MuJoCo, pose and delta rho1 at 1 ms
  engines_pose.png          platform pose over time (the paper's Figs. 9-10):
                            engines solid, this model dashed
  engines_delta_rho1.png    displacement of actuator 1 (the paper's Fig. 11)
  engines_differences.png   |this model - Pinocchio| and |MuJoCo - Pinocchio|
                            over time, and each one's ||C(q)||

What is compared:
- inverse dynamics along the auto-test (docs/model.md "The paper's two tests", every 1 ms
  sample of the 2 s): F1..F4 from the C API (pkm_inverse_dynamics) and the
  inverse FMU against Pinocchio's (RNEA on the tree, then the 16 equations
  J^T lambda - S F = -tau for the 12 multipliers and 4 forces);
- forward dynamics, the comparison test (docs/model.md "The paper's two tests", g = 0,
  F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), 1.5 s from rest at P0): the
  reference is Pinocchio's constrained forward dynamics (KKT system with
  M from CRBA, nle from RNEA and the 12 point-constraint Jacobians, all
  16 + 16 states integrated by scipy's DOP853 at rtol 1e-13, atol 1e-15, with
  the exact forces); against it the C API (forces from a callback at the
  integrator's own times: CVODE rtol 1e-12 / atol 1e-14, and RK4 at 1 ms),
  the plant FMU (1 ms communication step, forces held at each step's
  midpoint value: RK4 1 ms and CVODE rtol 1e-10, fmu_comparison.SOLVERS) and
  MuJoCo (mj_step, RK4, 1 ms, midpoint-held forces, the stiffest equality
  constraints it allows). A second Pinocchio run with the same midpoint-held
  forces (each 1 ms interval integrated at the same tolerance) separates the
  hold's own error from the integrators' and MuJoCo's constraint softness.
- the machine around the mechanism (docs/model.md; machine_cases): rotor
  inertia, viscous and Coulomb friction, an off-centre payload (with g = 0
  and with gravity on, then from the holding forces plus the sine) and all
  terms together (the C API driven by motor torques), each built into
  Pinocchio and MuJoCo independently; the C API by its parameters. The
  same reference, the C API as above, MuJoCo at 0.125 ms; and inverse
  dynamics with every term along the auto-test
  (pkm_inverse_dynamics against Pinocchio's RNEA with armature,
  payload and friction).

The figures need matplotlib (the extra `plots`).
"""
import math
import time

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

from .. import capi as pkm_capi, motions, spec
from ..references import mujoco_model
from ..references.pinocchio_model import PinocchioPKM

H = 1e-3  # s, output grid and communication step
N = round(spec.CMP_DURATION / H)
TIMES = np.arange(N + 1) * H
AUTOTEST_TIMES = np.arange(round(spec.T_MOVE / H) + 1) * H  # every 1 ms sample of the auto-test

# The bounds (the tests assert exactly these).
TOL_ID = 1e-8  # N, inverse dynamics, C API and inverse FMU vs Pinocchio
TOL_POS = 1e-10  # m, C API vs Pinocchio: x, y, z and delta rho1
TOL_PHI = 1e-9  # rad
TOL_FMU_POS = 1e-8  # m, plant FMU (1 ms, midpoint-held forces) vs Pinocchio
TOL_FMU_PHI = 3e-7  # rad
TOL_CONSTRAINT = 1e-12  # m, ||C(q)|| of this project's runs
# The reference must be far below TOL_POS / TOL_PHI to decide them: a
# different integrator (RK4, 0.5 ms) around a different constraint solver
# (pinocchio.constraintDynamics) must agree with it to these.
TOL_REF_POS = 1e-12  # m
TOL_REF_PHI = 1e-11  # rad

REF_RTOL, REF_ATOL = 1e-13, 1e-15
CAPI_SOLVERS = {
    "CVODE": {"solver": spec.SOLVER_CVODE, "rtol": 1e-12, "atol": 1e-14},
    "RK4": {"solver": spec.SOLVER_RK4, "rk4_step": 1e-3},
}
OUT = ["x", "y", "z", "phi", "delta_rho1"]


# --- Pinocchio ------------------------------------------------------------------------------------
def _rows_from_q(Q):
    """dict of the compared quantities from q (rows: times, columns: spec order)."""
    Q = np.asarray(Q)
    return {"x": Q[:, 12], "y": Q[:, 13], "z": Q[:, 14], "phi": Q[:, 15], "delta_rho1": Q[:, 0] - Q[0, 0],
            "constraint": np.array([np.linalg.norm(spec.constraint_residual(q)) for q in Q])}


def pinocchio_reference(force_law="exact", machine=None, g=0.0, forces=motions.comparison_forces):
    """The comparison test with Pinocchio's constrained forward dynamics
    (PinocchioPKM.forward_dynamics, the KKT system), state (q, v) in the 16
    coordinates, DOP853 at REF_RTOL / REF_ATOL. force_law "exact": F(t) at
    the integrator's own times, one integration over 1.5 s; "midpoint": F
    held at F(t_k + H/2) over each [t_k, t_k + H], each interval integrated
    on its own. Returns {"t", "q", x, y, z, phi, delta_rho1, "constraint"
    (||C(q)|| from the spec's formula), "nfev", "seconds"}. machine
    (spec.Machine), g and forces (F1..F4 of t) default to the comparison
    test's ideal mechanism."""
    pm = PinocchioPKM(g=g, machine=machine)
    y0 = np.concatenate([pm.q_from_pose(spec.P0), np.zeros(16)])
    nfev = 0
    t0 = time.perf_counter()

    def rhs_for(force):
        def rhs(t, y):
            a, _ = pm.forward_dynamics(y[:16], y[16:], force(t))
            return np.concatenate([y[16:], a])
        return rhs

    if force_law == "exact":
        sol = solve_ivp(rhs_for(forces), (0.0, spec.CMP_DURATION), y0, method="DOP853",
                        t_eval=TIMES, rtol=REF_RTOL, atol=REF_ATOL)
        if sol.status != 0:
            raise RuntimeError(f"Pinocchio reference: solve_ivp failed: {sol.message}")
        Y = sol.y.T
        nfev = sol.nfev
    elif force_law == "midpoint":
        Y = [y0]
        y = y0
        for k in range(N):
            F = forces(TIMES[k] + H / 2)
            sol = solve_ivp(rhs_for(lambda t, F=F: F), (TIMES[k], TIMES[k + 1]), y, method="DOP853",
                            rtol=REF_RTOL, atol=REF_ATOL)
            if sol.status != 0:
                raise RuntimeError(f"Pinocchio reference (midpoint-held): solve_ivp failed: {sol.message}")
            y = sol.y[:, -1]
            Y.append(y)
            nfev += sol.nfev
        Y = np.array(Y)
    else:
        raise ValueError(force_law)
    out = {"t": TIMES.copy(), "q": Y[:, :16], **_rows_from_q(Y[:, :16])}
    out["nfev"] = nfev
    out["seconds"] = time.perf_counter() - t0
    return out


def rk4_on_manifold(model, q, v, h, n, acc, after_step=None):
    """n fixed RK4 steps of h on the model's configuration manifold from (q,
    v): acc(q, v, k, stage) the accelerations at t_k + (0, h/2, h)[stage];
    after_step(k, q) after step k (bench/engines_bench.py times it too)."""
    for k in range(n):
        a1 = acc(q, v, k, 0)
        v2 = v + a1 * h / 2
        a2 = acc(pin.integrate(model, q, v * h / 2), v2, k, 1)
        v3 = v + a2 * h / 2
        a3 = acc(pin.integrate(model, q, v2 * h / 2), v3, k, 1)
        v4 = v + a3 * h
        a4 = acc(pin.integrate(model, q, v3 * h), v4, k, 2)
        q = pin.integrate(model, q, h / 6 * (v + 2 * v2 + 2 * v3 + v4))
        v = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if after_step:
            after_step(k, q)
    return q, v


def pinocchio_rk4(h=5e-4, machine=None, g=0.0, forces=motions.comparison_forces):
    """Cross-check of the reference: fixed-step RK4 at h on the manifold's
    coordinates, accelerations from pinocchio.constraintDynamics (Pinocchio's
    own constrained dynamics, RigidConstraintModel CONTACT_3D), exact F at
    the stage times. Same keys and arguments as pinocchio_reference."""
    pm = PinocchioPKM(g=g, machine=machine)
    pm.setup_constraint_dynamics()
    q = pm.q_from_pose(spec.P0)
    sub = round(H / h)
    Q = [q]
    t0 = time.perf_counter()
    rk4_on_manifold(pm.model, q, np.zeros(16), h, N * sub,
                    lambda q, v, k, stage: pm.constraint_dynamics(q, v, forces(k * h + (0.0, h / 2, h)[stage])),
                    lambda k, q: Q.append(q) if (k + 1) % sub == 0 else None)
    out = {"t": TIMES.copy(), "q": np.array(Q), **_rows_from_q(Q)}
    out["seconds"] = time.perf_counter() - t0
    return out


def pinocchio_inverse(times=AUTOTEST_TIMES):
    """F1..F4 (rows) and lambda along the auto-test, from PinocchioPKM.inverse_dynamics."""
    pm = PinocchioPKM(g=spec.G)
    F, lam = np.empty((len(times), 4)), np.empty((len(times), 12))
    for k, t in enumerate(times):
        F[k], lam[k], _ = pm.inverse_dynamics(*motions.autotest_motion(t))
    return F, lam


# --- this project -----------------------------------------------------------------------------------
def load_capi(build=None):
    """libpkm.so as locate.library_path finds it: the build directory `build`
    when given (or $PKM_BUILD_DIR), else the installed package's own, else
    ./build's."""
    path = pkm_capi.library_path(build)
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist: build libpkm first (./scripts/build.sh builds it into "
                                f"build/), and pass the directory that holds it (--build DIR) or set PKM_BUILD_DIR")
    return pkm_capi.load(path)


def capi_inverse(lib, times=AUTOTEST_TIMES):
    F, lam = np.empty((len(times), 4)), np.empty((len(times), 12))
    with pkm_capi.Plant(lib) as m:
        for k, t in enumerate(times):
            r = m.inverse_dynamics(*motions.autotest_motion(t))
            F[k], lam[k] = r.F, r.lambda_
    return F, lam


def fmu_inverse(inverse_fmu, times=AUTOTEST_TIMES):
    from ..fmu import Fmu, inverse_forces
    with Fmu(inverse_fmu) as inv:
        return inverse_forces(inv, times)


def capi_run(lib, settings, machine=None, g=0.0, forces=motions.comparison_forces, torques=None):
    """The comparison test through the C API: pkm_advance_fn to each 1 ms
    point with the forces from a callback at the integrator's own times
    (continuous: CVODE is not restarted), outputs read at each point.
    With a machine (spec.Machine) the model has its parameters (end stops at
    their defaults) and the run also returns "rho" (4 columns) and
    "stop_force" (pkm_get_outputs); torques (tau1..tau4 of t, N m) are then
    applied through the same callback, on top of forces."""
    rows, res, rho, stop = [], [], [], []
    calls = []

    def inputs(t):
        calls.append(t)
        return forces(t)

    t0 = time.perf_counter()
    with pkm_capi.Plant(lib, g=g, **({} if machine is None else machine.parameters())) as m:
        m.set_solver(**settings)
        m.init_pose(0.0, spec.P0)
        for k, t in enumerate(TIMES):
            if k > 0:
                m.advance_fn(t, inputs, torques, continuous=True)
            o = m.outputs(forces(t), tau=None if torques is None else torques(t))
            rows.append(list(o.pose) + [o.rho[0]])
            res.append(o.constraint_residual)
            rho.append(list(o.rho))
            if machine is not None:
                stop.append(list(o.stop_force))
    Y = np.array(rows)
    out = {"t": TIMES.copy(), "x": Y[:, 0], "y": Y[:, 1], "z": Y[:, 2], "phi": Y[:, 3],
           "delta_rho1": Y[:, 4] - Y[0, 4], "constraint": np.array(res), "input_times": np.array(calls),
           "rho": np.array(rho), "seconds": time.perf_counter() - t0}
    if machine is not None:
        out["stop_force"] = np.array(stop)
    return out


def fmu_runs(plant_fmu):
    """The comparison test through the plant FMU (fmu_comparison's runner:
    1 ms communication step, midpoint-held forces), CVODE and RK4."""
    from . import comparison as fmu_comparison
    out = {}
    for name in fmu_comparison.SOLVERS:
        t0 = time.perf_counter()
        r = fmu_comparison.run_solver(plant_fmu, name)
        out[name] = {"t": r["t"], "x": r["x"], "y": r["y"], "z": r["z"], "phi": r["phi"],
                     "delta_rho1": r["rho[1]"] - r["rho[1]"][0], "constraint": r["constraint_residual"],
                     "seconds": time.perf_counter() - t0}
    return out


# --- MuJoCo -------------------------------------------------------------------------------------------
def mujoco_run(g=0.0, forces=motions.comparison_forces, machine=None, **kw):
    """The comparison test in MuJoCo (engines/mujoco_model.py; keyword
    arguments go to its mjcf()): mj_step at 1 ms, midpoint-held forces.
    "constraint" is ||C(q)|| from the spec's formula on MuJoCo's qpos.
    machine (spec.Machine): armature, damping and payload body in the MJCF,
    Coulomb friction through the passive-force callback."""
    model, data = mujoco_model.build(g=g, machine=machine, **kw)
    t0 = time.perf_counter()
    with mujoco_model.coulomb_passive(machine):
        mujoco_model.set_pose(model, data, spec.P0)
        t, Q = mujoco_model.run_comparison(model, data, forces=forces)
    out = {"t": t, "q": Q, **_rows_from_q(Q)}
    out["seconds"] = time.perf_counter() - t0
    return out


def mujoco_sweep():
    """MuJoCo's equality-constraint settings around the stiffest, as
    (label, keyword arguments of mujoco_model.mjcf); run_sweep runs them."""
    cases = [("solref (0.02, 1), solimp default (MuJoCo's defaults)",
              {"solref": (0.02, 1.0), "solimp": (0.9, 0.95, 0.001, 0.5, 2.0)})]
    for d in (0.99, 0.999, 0.9999):
        for tc, refsafe in ((0.001, False), (0.0015, False), (0.002, True), (0.003, True), (0.005, True)):
            cases.append((f"solref ({tc:g}, 1), solimp d = {d:g}" + ("" if refsafe else ", refsafe off"),
                          {"solref": (tc, 1.0), "solimp": (d, d, 0.001, 0.5, 2.0), "refsafe": refsafe}))
    return cases


# --- the machine around the mechanism (docs/model.md) ---------------------------------------------------
# Each term of the machine is checked on the comparison test against the
# same term built into the engines independently: rotor inertia (Pinocchio's
# armature, MuJoCo's joint armature), viscous friction (a joint force in the
# Pinocchio integrator, MuJoCo's joint damping), Coulomb friction with the
# spec's tanh law (a joint force in both: MuJoCo through its passive-force
# callback) and an off-centre payload (a second body rigidly attached to the
# platform in both). The C API gets the same numbers as parameters, its end
# stops at their defaults.
#
# Bounds: the 1e-8 m for x, y, z and delta rho1; for phi 1e-7 rad,
# 1e-8 m over the spec's 0.1 m lever for phi (the actuator Jacobian's
# condition number uses the same scale; at the anchors, r_Q = 0.075 m, it is
# 7.5e-9 m). The C API, with the exact forces and the tight solver settings,
# is held to the ideal machine's own bounds, TOL_POS / TOL_PHI, well inside.
TOL_MACHINE_POS = 1e-8  # m
TOL_MACHINE_PHI = 1e-7  # rad
TOL_MACHINE_ID = 1e-9  # N, inverse dynamics with the machine along the auto-test
# MuJoCo for the machine: its connect constraints are soft, and their
# deflection grows with the load they carry and with the square of their
# time constant. With gravity on they carry the weight (~6 N instead of
# ~0.02 N at g = 0): at 1 ms (time constant 2 ms) MuJoCo's ||C(q)|| reaches
# 2.3e-8 m, a static sag of z that alone breaks 1e-8 m. So the machine runs
# use RK4 at 0.125 ms with the same rule as the ideal run (time constant two
# steps, the stiffest with refsafe on, impedance 0.9999), forces held at each
# step's midpoint (the hold then costs ~1/64 of the 1 ms hold's 1e-9 m,
# 1e-8 rad); every case, g = 0 ones included, so that all are run alike.
MUJOCO_MACHINE_STEP = 1.25e-4  # s
MUJOCO_MACHINE_CONSTRAINT = 1e-9  # m, max ||C(q)|| of MuJoCo's machine runs, as for the ideal run
# The comparison test must stay clear of the end stops (default 0 and 0.15 m),
# so that they are not part of it: every slider within this margin of both.
STOP_MARGIN = 0.02  # m
# A term is tested only if it changes the motion: by this factor above the bound.
EFFECT_FACTOR = 1e3

# The machine's numbers. A non-default screw lead, so the lead enters too.
M_SCREW_LEAD = 0.005  # m/rev
M_ROTOR_INERTIA = 6e-8  # kg m^2: reflected mass J (2 pi / p)^2 = 0.0947 kg, about the slider's 0.0933 kg
M_VISCOUS = 0.5  # N s/m: 0.0125 N at the test's peak slider speed (25 mm/s), comparable with the 0.02 N drive
M_COULOMB = 0.005  # N, a quarter of the drive's amplitude
M_FRICTION_VELOCITY = 2e-3  # m/s (not the default 1e-3): about 1/10 of the peak slider speed
# 0.2 kg, centre of mass 25 mm off P, 30 mm below the platform's plane (the
# spec says that height cannot matter: the engines put the body there, the
# C API has no such parameter), own Izz 1.5e-4 kg m^2, and Ixx, Iyy that
# must not matter either (no tilt).
M_PAYLOAD = {"payload_mass": 0.2, "payload_com": (0.02, -0.015), "payload_Izz": 1.5e-4, "payload_z": -0.03,
             "payload_Ixx": 1.0e-4, "payload_Iyy": 1.2e-4}


class MachineCase:
    """One machine on the comparison test. With gravity on (g > 0) the forces
    are the holding forces at P0, from Pinocchio's static inverse dynamics
    of this machine, plus the spec's sine on F1 and F4: the machine then
    starts in equilibrium and the sine moves it. torques: the C API gets the
    sine as motor torques (2 pi / p) tau = F instead of forces, through
    pkm_advance_fn's inputs (the engines get the forces)."""

    def __init__(self, name, machine, g=0.0, torques=False, mujoco=True):
        self.name, self.machine, self.g, self.use_torques, self.mujoco = name, machine, g, torques, mujoco
        self.hold = np.zeros(4)
        if g > 0.0:
            pm = PinocchioPKM(g=g, machine=machine)
            self.hold = pm.inverse_dynamics(spec.P0, np.zeros(4), np.zeros(4))[0]

    def forces(self, t):
        """F1..F4 (N) at t, as the engines see them."""
        return self.hold + motions.comparison_forces(t)

    def capi_inputs(self):
        """(forces(t), torques(t) or None) for the C API."""
        if not self.use_torques:
            return self.forces, None
        lead = self.machine.screw_lead
        return (lambda t: self.hold.copy()), (lambda t: motions.comparison_forces(t) * lead / (2.0 * math.pi))

    def without_machine(self):
        """The same test on the ideal machine (its own holding forces): what the terms change."""
        return MachineCase(self.name + " (ideal)", spec.Machine(), self.g)


def machine_cases():
    """The cases the checks run, by name (items 1-4 of the issue's check)."""
    M = spec.Machine
    full = dict(screw_lead=M_SCREW_LEAD, rotor_inertia=M_ROTOR_INERTIA, friction_viscous=M_VISCOUS,
                friction_coulomb=M_COULOMB, friction_velocity=M_FRICTION_VELOCITY, **M_PAYLOAD)
    cases = [
        MachineCase("rotor_inertia", M(screw_lead=M_SCREW_LEAD, rotor_inertia=M_ROTOR_INERTIA)),
        MachineCase("viscous_friction", M(friction_viscous=M_VISCOUS)),
        MachineCase("coulomb_friction", M(friction_coulomb=M_COULOMB, friction_velocity=M_FRICTION_VELOCITY)),
        MachineCase("payload_g0", M(**M_PAYLOAD)),
        MachineCase("payload_gravity", M(**M_PAYLOAD), g=spec.G),
        MachineCase("all_terms", M(**full), g=spec.G, torques=True),
    ]
    return {c.name: c for c in cases}


def mujoco_machine_run(case, step=MUJOCO_MACHINE_STEP):
    """MuJoCo on a machine case: RK4 at `step`, time constant two steps,
    midpoint-held forces; sampled on the 1 ms grid."""
    sub = round(H / step)
    model, data = mujoco_model.build(g=case.g, machine=case.machine, timestep=step, solref=(2.0 * step, 1.0))
    t0 = time.perf_counter()
    with mujoco_model.coulomb_passive(case.machine):
        mujoco_model.set_pose(model, data, spec.P0)
        _, Q = mujoco_model.run_comparison(model, data, forces=case.forces)
    Q = Q[::sub]
    out = {"t": TIMES.copy(), "q": Q, **_rows_from_q(Q)}
    out["seconds"] = time.perf_counter() - t0
    return out


def machine_run(case, lib, parts=("ref", "ref_rk4", "ideal", "capi", "mujoco")):
    """Everything one machine case is checked on: {"ref": Pinocchio (DOP853),
    "ref_rk4": its cross-check, "ideal": Pinocchio on the ideal machine,
    "capi": {solver: run}, "mujoco": run}."""
    out = {}
    kw = {"machine": case.machine, "g": case.g, "forces": case.forces}
    if "ref" in parts:
        out["ref"] = pinocchio_reference("exact", **kw)
    if "ref_rk4" in parts:
        out["ref_rk4"] = pinocchio_rk4(**kw)
    if "ideal" in parts:
        ideal = case.without_machine()
        out["ideal"] = pinocchio_reference("exact", machine=ideal.machine, g=ideal.g, forces=ideal.forces)
    if "capi" in parts:
        forces, torques = case.capi_inputs()
        out["capi"] = {name: capi_run(lib, s, machine=case.machine, g=case.g, forces=forces, torques=torques)
                       for name, s in CAPI_SOLVERS.items()}
    if "mujoco" in parts and case.mujoco:
        out["mujoco"] = mujoco_machine_run(case)
    return out


def pinocchio_inverse_machine(machine, times=AUTOTEST_TIMES, g=spec.G):
    """F1..F4 (rows) and lambda along the auto-test (gravity on unless g says
    otherwise) with the machine: Pinocchio's RNEA (armature and payload in
    the model) plus the friction joint forces, then J^T lambda - S F = -tau."""
    pm = PinocchioPKM(g=g, machine=machine)
    F, lam = np.empty((len(times), 4)), np.empty((len(times), 12))
    for k, t in enumerate(times):
        F[k], lam[k], _ = pm.inverse_dynamics(*motions.autotest_motion(t))
    return F, lam


def capi_inverse_machine(lib, machine, times=AUTOTEST_TIMES):
    """F, tau, lambda and the beyond_stops flags along the auto-test from
    pkm_inverse_dynamics."""
    F, tau, lam = np.empty((len(times), 4)), np.empty((len(times), 4)), np.empty((len(times), 12))
    flags = np.empty(len(times), dtype=int)
    with pkm_capi.Plant(lib, **machine.parameters()) as m:
        for k, t in enumerate(times):
            r = m.inverse_dynamics(*motions.autotest_motion(t))
            F[k], tau[k], lam[k], flags[k] = r.F, r.tau, r.lambda_, r.beyond_stops
    return {"F": F, "tau": tau, "lambda": lam, "beyond_stops": flags}


# --- what the checks look at ------------------------------------------------------------------------
def deviation(run, ref):
    """(max |difference| over x, y, z and delta rho1 (m), max |difference| of phi (rad))."""
    d_pos = max(np.abs(run[n] - ref[n]).max() for n in ("x", "y", "z", "delta_rho1"))
    return d_pos, np.abs(run["phi"] - ref["phi"]).max()


def deviation_series(run, ref):
    d_pos = np.max([np.abs(run[n] - ref[n]) for n in ("x", "y", "z", "delta_rho1")], axis=0)
    return d_pos, np.abs(run["phi"] - ref["phi"])


def run_all(build=None, plant_fmu=None, inverse_fmu=None, log=None):
    """Everything the program reports: {"id": {...}, "ref", "ref_held", "ref_rk4",
    "capi": {solver: run}, "fmu": {solver: run}, "mujoco": run}."""
    def say(msg):
        if log:
            log(msg)

    lib = load_capi(build)
    out = {}
    say("inverse dynamics along the auto-test (Pinocchio, C API, inverse FMU)")
    F_pin, lam_pin = pinocchio_inverse()
    F_capi, lam_capi = capi_inverse(lib)
    out["id"] = {"t": AUTOTEST_TIMES, "pinocchio": F_pin, "capi": F_capi, "lambda_pinocchio": lam_pin,
                 "lambda_capi": lam_capi}
    if inverse_fmu is not None:
        out["id"]["fmu"] = fmu_inverse(inverse_fmu)
    say("comparison test: Pinocchio reference (DOP853, rtol 1e-13)")
    out["ref"] = pinocchio_reference("exact")
    say("comparison test: Pinocchio, midpoint-held forces")
    out["ref_held"] = pinocchio_reference("midpoint")
    say("comparison test: Pinocchio constraintDynamics + RK4 0.5 ms (cross-check of the reference)")
    out["ref_rk4"] = pinocchio_rk4()
    say("comparison test: C API")
    out["capi"] = {name: capi_run(lib, s) for name, s in CAPI_SOLVERS.items()}
    if plant_fmu is not None:
        say("comparison test: plant FMU")
        out["fmu"] = fmu_runs(plant_fmu)
    say("comparison test: MuJoCo")
    out["mujoco"] = mujoco_run()
    say("the machine: comparison test per term (Pinocchio, C API, MuJoCo), inverse dynamics with every term")
    out["machine"] = {name: machine_run(case, lib) for name, case in machine_cases().items()}
    full = machine_cases()["all_terms"].machine
    F_pin, lam_pin = pinocchio_inverse_machine(full)
    out["machine_id"] = {"pinocchio": F_pin, "lambda_pinocchio": lam_pin, "capi": capi_inverse_machine(lib, full),
                         "screw_lead": full.screw_lead}
    return out


def run_sweep(held):
    """Rows of (label, max ||C(q)|| (m), max position and phi difference from
    `held`, the midpoint-held Pinocchio run) for every mujoco_sweep() case."""
    rows = []
    for label, kw in mujoco_sweep():
        with np.errstate(all="ignore"):
            mj = mujoco_run(**kw)
        if not np.all(np.isfinite(mj["q"])) or mj["constraint"].max() > 1.0:
            rows.append((label + " (unstable)", float("nan"), float("nan"), float("nan")))
            continue
        dp, dphi = deviation(mj, held)
        rows.append((label, mj["constraint"].max(), dp, dphi))
    return rows

