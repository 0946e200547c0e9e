# SPDX-License-Identifier: BSD-2-Clause
"""The machine around the mechanism (docs/model.md "The machine around the
mechanism") checked against independent engines: rotor inertia, viscous
friction, Coulomb friction and an off-centre payload, each alone and all together, on the spec's comparison test
(1.5 s from rest at P0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), F2 = F3 = 0).
The runners and the machine's numbers are in engine_comparison.py
(machine_cases), the engine models in engines/.

- The reference: Pinocchio with the same terms built in its own way (rotor
  inertia as model.armature, the payload as a second body rigidly attached
  to the platform joint, friction as joint forces in the integrator), DOP853
  at rtol 1e-13; it must be decided far below the bounds (fixed-step RK4
  around pinocchio.constraintDynamics within 1e-12 m, 1e-11 rad).
- Gravity is off (the comparison test) except where a payload's weight is to
  be tested: then the forces are Pinocchio's holding forces at P0 plus the
  sine, and in the all-terms case the C API gets the sine as motor torques
  (2 pi / p) tau (pkm_advance_fn's inputs).
- Every term must change the motion (by 1e3 times the bound), and the motion
  must stay clear of the end stops (left at their defaults), so that they are
  not part of the test.
- This model (C API, the machine parameters set by name, CVODE rtol 1e-12 and RK4 1 ms, the
  exact forces at the integrator's own times) within the ideal machine's
  bounds, 1e-10 m and 1e-9 rad, inside the issue's 1e-8 m.
- MuJoCo (joint armature and damping, a payload body, Coulomb friction through
  its passive-force callback; RK4 at 0.125 ms, midpoint-held forces): within
  1e-8 m and 1e-7 rad (1e-8 m over the spec's 0.1 m lever for phi), its own
  ||C(q)|| within 1e-9 m as in the ideal run.
- Inverse dynamics with every term along the auto-test (gravity on):
  pkm_inverse_dynamics's F, tau and lambda against Pinocchio's RNEA
  (armature and payload in the model) with the friction forces, within
  1e-9 N (1e-9 N * p / (2 pi) for tau); the holding forces F_hold likewise.
"""
import math

import numpy as np
import pytest

from pkm4puu.cli.engine_comparison import (AUTOTEST_TIMES, CAPI_SOLVERS, EFFECT_FACTOR, MUJOCO_MACHINE_CONSTRAINT,
                                           STOP_MARGIN, TOL_CONSTRAINT, TOL_MACHINE_ID, TOL_MACHINE_PHI,
                                           TOL_MACHINE_POS, TOL_PHI, TOL_POS, TOL_REF_PHI, TOL_REF_POS,
                                           capi_inverse_machine, deviation, load_capi, machine_cases, machine_run,
                                           pinocchio_inverse_machine)
from pkm4puu.cli.engine_report import format_machine_table
from pkm4puu import capi as pkm_capi, spec
from pkm4puu.references.pinocchio_model import LEG_ROWS, PinocchioPKM

CASES = machine_cases()


@pytest.fixture(scope="module")
def lib(pkm_library):
    return load_capi(pkm_library.parent.parent)


@pytest.fixture(scope="module")
def runs(lib):
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = machine_run(CASES[name], lib)
        return cache[name]

    yield get
    if cache:
        print("\n" + "\n".join(format_machine_table(cache)))


@pytest.mark.parametrize("name", ["rotor_inertia", "viscous_friction", "payload_g0"])
def test_vertical_momentum_balances_the_friction(lib, name):
    """With g = 0, F1 = -F4 and F2 = F3 = 0 nothing but friction acts along z
    (every actuator axis is vertical), so the vertical momentum
    (spec.vertical_momentum: the rotors' reflected mass with the sliders',
    the payload's with the platform's) is minus the friction's impulse,
    b sum (rho - rho(0)) for viscous friction, and 0 without: each term
    enters with the mass the spec gives it (left out, the balance misses by
    EFFECT_FACTOR times the bound at least). The bound: CVODE's local error, rtol |v| + atol on each
    velocity, over every 1 ms step, times the machine's mass (about 1 kg)."""
    c = CASES[name]
    mc, steps, rtol, atol = c.machine, 300, 1e-10, 1e-12
    rows = []
    with pkm_capi.Plant(lib, **mc.parameters(), g=0.0) as m:
        m.set_solver(solver=0, rtol=rtol, atol=atol)
        m.init_pose(0.0, list(spec.P0))
        for k in range(1, steps + 1):
            m.advance_fn(k * spec.STEP, c.forces)
            o = m.outputs(F=list(c.forces(k * spec.STEP)))
            rows.append([*o.drho, *o.rho, o.velocity[2]])
    drho, rho, dz = np.array(rows)[:, :4], np.array(rows)[:, 4:8], np.array(rows)[:, 8]
    momentum = spec.vertical_momentum(drho, dz, mc.payload_mass, mc.reflected_mass)
    impulse = -mc.friction_viscous * (rho - spec.leg_inverse_kinematics(spec.P0)[:, 0]).sum(axis=1)
    mass = spec.M_PLATFORM + 4 * (spec.M_SLIDER + spec.M_ROD) + mc.payload_mass + 4 * mc.reflected_mass
    bound = mass * (rtol * np.abs(drho).max() + atol) * steps
    worst = np.abs(momentum - impulse).max()
    print(f"\n{name}: vertical momentum up to {np.abs(momentum).max():.2e} kg m/s, "
          f"minus the friction's impulse within {worst:.2e} (bound {bound:.1e})")
    assert worst <= bound
    ignored = np.abs(spec.vertical_momentum(drho, dz)).max()  # the balance with the case's term left out
    assert ignored >= EFFECT_FACTOR * bound, f"{name}: the term is not tested ({ignored:.2e} kg m/s)"


def test_holding_forces_carry_the_payload():
    """The gravity cases start in equilibrium: Pinocchio's holding forces at P0
    sum to the total weight, the payload's included (docs/model.md's check plus
    m_payload g); an off-centre payload's moment is carried by the legs'
    constraints, not the actuators (the platform cannot tilt)."""
    c = CASES["payload_gravity"]
    weight = spec.TOTAL_WEIGHT + c.machine.payload_mass * spec.G
    assert abs(c.hold.sum() - weight) < 1e-9, (c.hold, weight)
    pm = PinocchioPKM(g=c.g, machine=c.machine)
    q = pm.q_from_pose(spec.P0)
    a, _ = pm.forward_dynamics(q, np.zeros(16), c.hold)
    assert np.abs(a).max() < 1e-10


@pytest.mark.parametrize("name", list(CASES))
def test_reference_is_converged(runs, name):
    r = runs(name)
    d_pos, d_phi = deviation(r["ref_rk4"], r["ref"])
    c = r["ref"]["constraint"].max()
    print(f"\n{name}: reference vs constraintDynamics + RK4 0.5 ms: {d_pos:.2e} m, {d_phi:.2e} rad; "
          f"max ||C|| {c:.1e} m")
    assert c <= TOL_CONSTRAINT
    assert d_pos <= TOL_REF_POS and d_phi <= TOL_REF_PHI, (d_pos, d_phi)


@pytest.mark.parametrize("name", list(CASES))
def test_term_changes_the_motion(runs, name):
    """Against the same test on the ideal machine: a term that changed nothing would be untested."""
    r = runs(name)
    d_pos, d_phi = deviation(r["ref"], r["ideal"])
    print(f"\n{name}: the machine's terms change the motion by {d_pos:.2e} m, {d_phi:.2e} rad")
    assert d_pos >= EFFECT_FACTOR * TOL_MACHINE_POS, d_pos
    assert d_phi >= EFFECT_FACTOR * TOL_MACHINE_PHI, d_phi


@pytest.mark.parametrize("name", list(CASES))
def test_motion_stays_clear_of_the_end_stops(runs, name):
    r = runs(name)
    rho = r["ref"]["q"][:, LEG_ROWS]
    lo, hi = rho.min(), rho.max()
    print(f"\n{name}: rho in [{lo:.4f}, {hi:.4f}] m (stops at {spec.RHO_MIN}, {spec.RHO_MAX} m)")
    assert spec.RHO_MIN + STOP_MARGIN <= lo and hi <= spec.RHO_MAX - STOP_MARGIN
    for solver, run in r["capi"].items():
        assert np.all(run["stop_force"] == 0.0), f"C API {solver}: an end stop acted"
        assert spec.RHO_MIN + STOP_MARGIN <= run["rho"].min() and run["rho"].max() <= spec.RHO_MAX - STOP_MARGIN


@pytest.mark.parametrize("solver", list(CAPI_SOLVERS))
@pytest.mark.parametrize("name", list(CASES))
def test_capi_machine_matches_pinocchio(runs, name, solver):
    run, ref = runs(name)["capi"][solver], runs(name)["ref"]
    d_pos, d_phi = deviation(run, ref)
    c = run["constraint"].max()
    print(f"\n{name}: C API {solver} vs Pinocchio: {d_pos:.3e} m, {d_phi:.3e} rad; max ||C|| {c:.1e} m")
    assert d_pos <= TOL_POS, f"{name}, C API {solver}: {d_pos:.3e} m > {TOL_POS} m"
    assert d_phi <= TOL_PHI, f"{name}, C API {solver}: {d_phi:.3e} rad > {TOL_PHI} rad"
    assert c <= TOL_CONSTRAINT


@pytest.mark.parametrize("name", list(CASES))
def test_mujoco_machine_matches_pinocchio(runs, name):
    run, ref = runs(name)["mujoco"], runs(name)["ref"]
    d_pos, d_phi = deviation(run, ref)
    c = run["constraint"].max()
    print(f"\n{name}: MuJoCo vs Pinocchio: {d_pos:.3e} m, {d_phi:.3e} rad; MuJoCo's max ||C(q)|| {c:.1e} m")
    assert d_pos <= TOL_MACHINE_POS, f"{name}, MuJoCo: {d_pos:.3e} m > {TOL_MACHINE_POS} m"
    assert d_phi <= TOL_MACHINE_PHI, f"{name}, MuJoCo: {d_phi:.3e} rad > {TOL_MACHINE_PHI} rad"
    assert 0.0 < c <= MUJOCO_MACHINE_CONSTRAINT, f"{name}: MuJoCo's constraint violation {c:.3e} m"


# --- inverse dynamics with the machine, along the auto-test --------------------------------------------------
FULL = CASES["all_terms"].machine


@pytest.fixture(scope="module")
def inverse_pinocchio():
    return pinocchio_inverse_machine(FULL)


@pytest.fixture(scope="module")
def inverse_capi(lib):
    return capi_inverse_machine(lib, FULL)


def test_inverse_terms_matter():
    """Each term alone changes Pinocchio's forces along the auto-test by far
    more than the bound; the payload also without gravity (its inertia, not
    only its weight)."""
    payload = {k: getattr(FULL, k) for k in ("payload_mass", "payload_com", "payload_Izz", "payload_z",
                                             "payload_Ixx", "payload_Iyy")}
    parts = {"rotor inertia": (spec.Machine(screw_lead=FULL.screw_lead, rotor_inertia=FULL.rotor_inertia), spec.G),
             "viscous friction": (spec.Machine(friction_viscous=FULL.friction_viscous), spec.G),
             "Coulomb friction": (spec.Machine(friction_coulomb=FULL.friction_coulomb,
                                               friction_velocity=FULL.friction_velocity), spec.G),
             "payload": (spec.Machine(**payload), spec.G),
             "payload, g = 0": (spec.Machine(**payload), 0.0)}
    for label, (mc, g) in parts.items():
        F, _ = pinocchio_inverse_machine(mc, g=g)
        F_ideal, _ = pinocchio_inverse_machine(spec.Machine(), g=g)
        d = np.abs(F - F_ideal).max()
        print(f"\n{label}: changes F by up to {d:.2e} N")
        assert d >= 1e3 * TOL_MACHINE_ID, (label, d)


def test_inverse_machine_matches_pinocchio(inverse_capi, inverse_pinocchio):
    F_pin, lam_pin = inverse_pinocchio
    dF = np.abs(inverse_capi["F"] - F_pin)
    k = np.unravel_index(dF.argmax(), dF.shape)
    dlam = np.abs(inverse_capi["lambda"] - lam_pin).max()
    print(f"\npkm_inverse_dynamics vs Pinocchio: max |dF| {dF.max():.3e} N (t = {AUTOTEST_TIMES[k[0]]:.3f} s, "
          f"F{k[1] + 1}), max |d lambda| {dlam:.3e} N")
    assert dF.max() <= TOL_MACHINE_ID
    assert dlam <= TOL_MACHINE_ID
    assert np.all(inverse_capi["beyond_stops"] == 0)  # the auto-test stays within 0.040-0.080 m


def test_inverse_machine_motor_torques(inverse_capi, inverse_pinocchio):
    """tau = F p / (2 pi) (docs/model.md), from Pinocchio's F."""
    tau_pin = inverse_pinocchio[0] * FULL.screw_lead / (2.0 * math.pi)
    d = np.abs(inverse_capi["tau"] - tau_pin).max()
    print(f"\nmotor torques vs Pinocchio's F p / (2 pi): {d:.3e} N m")
    assert d <= TOL_MACHINE_ID * FULL.screw_lead / (2.0 * math.pi)


@pytest.mark.parametrize("pose", [spec.P0, spec.P1], ids=["P0", "P1"])
def test_holding_forces_match_pinocchio(lib, pose):
    """F_hold (pkm_get_outputs) at rest against Pinocchio's static inverse dynamics with the payload."""
    F_pin = PinocchioPKM(g=spec.G, machine=FULL).inverse_dynamics(pose, np.zeros(4), np.zeros(4))[0]
    with pkm_capi.Plant(lib, **FULL.parameters()) as m:
        m.init_pose(0.0, pose)
        F_hold = m.outputs().F_hold
    d = np.abs(F_hold - F_pin).max()
    print(f"\nF_hold vs Pinocchio: {d:.3e} N")
    assert d <= TOL_MACHINE_ID
