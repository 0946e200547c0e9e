# SPDX-License-Identifier: BSD-2-Clause
"""The independent engine models (engines/pinocchio_model.py, engines/mujoco_model.py)
checked against docs/model.md itself, never against this project, so that
test_engines_inverse.py and test_engines_forward.py compare the project with
a trustworthy second implementation:

- the leg frames follow the spec's DH table: Pinocchio's Q_i equals the
  spec's multiplied-out p_Q, the platform anchors are p + Rz(phi) r_Qi, and
  the closed-form inverse kinematics reproduces the spec's golden poses;
- the inertia conventions (rod inertia about its centre of mass in DH frame 3
  axes, slider mass translating only, massless U-joint crosses, platform
  rotating about z only) and gravity: Pinocchio's mass matrix reproduces the
  kinetic energy summed body by body from the spec's table, and its gravity
  vector the gradient of the spec's potential energy;
- the spec's derivable static check, 2.655616050 N per actuator at P0;
- MuJoCo's model is the same mechanism: the same sites, mass matrix and bias
  forces as Pinocchio's tree;
- Pinocchio's own constraintDynamics gives the same accelerations as the
  KKT solve used for the reference.
"""
import math

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from pkm4puu import motions, spec
from pkm4puu.references import mujoco_model
from pkm4puu.references.pinocchio_model import PinocchioPKM

RNG = np.random.default_rng(20261121)

GOLDEN = [  # docs/model.md "Bodies": pose, then (rho, theta1, theta2) of legs 1..4
    ((0.0, 0.0, 0.05, 0.0),
     [(0.0443193423, 3.2655932943, -0.8606121019), (0.0443193423, -1.3393164414, -0.8606121019),
      (0.0443193423, 3.2655932943, -0.8606121019), (0.0443193423, -1.3393164414, -0.8606121019)]),
    ((0.005, -0.005, 0.07, math.radians(4.0)),
     [(0.0676488698, 3.3244509641, -0.9270633736), (0.0608871697, -1.3561168385, -0.7971100074),
      (0.0407700625, 3.1413311322, -0.4823651758), (0.0792527515, -1.0390941300, -1.2373176895)]),
]


def random_q():
    q = np.empty(16)
    for i in range(4):
        q[3 * i:3 * i + 3] = (RNG.uniform(0.02, 0.08), RNG.uniform(-math.pi, math.pi), RNG.uniform(-1.4, -0.2))
    q[12:] = (*RNG.uniform(-0.01, 0.01, 2), RNG.uniform(0.04, 0.08), RNG.uniform(-0.3, 0.3))
    return q


def spec_kinetic_energy(q, v):
    """T summed body by body from docs/model.md "Bodies" (nothing from Pinocchio)."""
    T = 0.5 * spec.M_PLATFORM * v[12:15] @ v[12:15] + 0.5 * spec.IZZ_PLATFORM * v[15] ** 2
    for i in range(4):
        rho_d, th1, th2 = v[3 * i], q[3 * i + 1], q[3 * i + 2]
        th1_d, th2_d = v[3 * i + 1], v[3 * i + 2]
        c1, s1, c2, s2 = math.cos(th1), math.sin(th1), math.cos(th2), math.sin(th2)
        x3 = np.array([c1 * c2, s1 * c2, s2])
        z3 = np.array([s1, -c1, 0.0])
        y3 = np.cross(z3, x3)
        omega = th1_d * np.array([0.0, 0.0, 1.0]) + th2_d * z3  # leg frame 0_i
        v_com = np.array([0.0, 0.0, rho_d]) + np.cross(omega, 0.5 * spec.L * x3)
        R3 = np.column_stack([x3, y3, z3])
        I_leg = R3 @ np.diag(spec.I_ROD) @ R3.T
        T += 0.5 * spec.M_SLIDER * rho_d**2 + 0.5 * spec.M_ROD * v_com @ v_com + 0.5 * omega @ I_leg @ omega
    return T


def spec_gravity(q):
    """dU/dq of U = g (sum_i (m_s rho_i + m_r (rho_i + h + l/2 sin theta2_i)) + m_p z)."""
    G = np.zeros(16)
    for i in range(4):
        G[3 * i] = spec.G * (spec.M_SLIDER + spec.M_ROD)
        G[3 * i + 2] = spec.G * spec.M_ROD * 0.5 * spec.L * math.cos(q[3 * i + 2])
    G[14] = spec.G * spec.M_PLATFORM
    return G


@pytest.fixture(scope="module")
def pm():
    return PinocchioPKM()


def test_leg_frames_follow_the_dh_table(pm):
    for _ in range(20):
        q = random_q()
        pin.framesForwardKinematics(pm.model, pm.data, q)
        for i in range(4):
            expected_q = spec.leg_end_point(i, *q[3 * i:3 * i + 3])
            expected_r = q[12:15] + spec.rz(q[15]) @ spec.platform_point(i)
            assert np.abs(pm.data.oMf[pm.q_frames[i]].translation - expected_q).max() < 1e-15
            assert np.abs(pm.data.oMf[pm.r_frames[i]].translation - expected_r).max() < 1e-15


def test_golden_poses(pm):
    for pose, legs in GOLDEN:
        got = spec.leg_inverse_kinematics(np.array(pose))
        assert np.abs(got - np.array(legs)).max() < 1e-9, f"inverse kinematics at {pose}"
        q = pm.q_from_pose(np.array(pose))
        assert np.linalg.norm(pm.constraints(q)) < 1e-15
        assert np.linalg.norm(spec.constraint_residual(q)) < 1e-15


def test_mass_matrix_is_the_spec_kinetic_energy(pm):
    """Checks the inertia conventions: 1/2 v^T M v against the bodies of the spec."""
    for _ in range(20):
        q, v = random_q(), RNG.normal(size=16)
        T_pin = 0.5 * v @ pm.mass_matrix(q) @ v
        T_spec = spec_kinetic_energy(q, v)
        assert abs(T_pin - T_spec) <= 1e-14 * max(1.0, T_spec), (T_pin, T_spec)


def test_gravity_is_the_spec_potential(pm):
    for _ in range(20):
        q = random_q()
        G = pin.computeGeneralizedGravity(pm.model, pm.data, q)
        assert np.abs(G - spec_gravity(q)).max() < 1e-14


def test_static_check(pm):
    """docs/model.md "Bodies", from Pinocchio."""
    F, _, _ = pm.inverse_dynamics(spec.P0, np.zeros(4), np.zeros(4))
    print(f"\nPinocchio: static forces at P0 {F} N")
    assert np.abs(F - spec.STATIC_FORCE_P0).max() < 1e-9
    assert abs(F.sum() - 10.622464200) < 1e-9


def test_mujoco_is_the_same_mechanism(pm):
    """Sites, mass matrix and bias forces (gravity on) of the MJCF against Pinocchio's tree."""
    model, data = mujoco_model.build(g=spec.G)
    assert model.nq == 16 and model.nv == 16
    M = np.zeros((16, 16))
    for _ in range(20):
        q, v = random_q(), RNG.normal(size=16)
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        for i in range(4):
            assert np.abs(data.site_xpos[i] - spec.leg_end_point(i, *q[3 * i:3 * i + 3])).max() < 1e-15
            assert np.abs(data.site_xpos[4 + i] - q[12:15] - spec.rz(q[15]) @ spec.platform_point(i)).max() < 1e-15
        mujoco.mj_fullM(model, data, M)  # MuJoCo >= 3.6 signature
        M_pin = pm.mass_matrix(q)
        # the slider's rotational inertia (1e-9 kg m^2, never used) stays out of M: it only translates
        assert np.abs(M - M_pin).max() <= 1e-12 * np.abs(M_pin).max()
        nle = pin.nonLinearEffects(pm.model, pm.data, q, v)
        assert np.abs(data.qfrc_bias - nle).max() <= 1e-12 * max(1.0, np.abs(nle).max())


def test_kkt_equals_pinocchio_constraint_dynamics():
    pm = PinocchioPKM(g=spec.G)
    pm.setup_constraint_dynamics()
    for pose in (spec.P0, spec.P1):
        q = pm.q_from_pose(pose)
        v = pm.complete_velocity(q, RNG.normal(scale=0.05, size=4))
        F = spec.STATIC_FORCE_P0 + RNG.normal(scale=0.1, size=4)
        a_kkt, lam = pm.forward_dynamics(q, v, F)
        a_pin = pm.constraint_dynamics(q, v, F)
        assert np.abs(a_kkt - a_pin).max() <= 1e-10 * np.abs(a_kkt).max()
        # the accelerations keep the constraints: J a + gamma = 0
        assert np.abs(pm.jacobian(q) @ a_kkt + pm.bias(q, v)).max() < 1e-12


# --- the machine around the mechanism in the engine models (docs/model.md) --------------------------------------
MACHINE = spec.Machine(screw_lead=0.005, rotor_inertia=6e-8, friction_viscous=0.5, friction_coulomb=0.005,
                       friction_velocity=2e-3, payload_mass=0.2, payload_com=(0.02, -0.015), payload_Izz=1.5e-4,
                       payload_z=-0.03, payload_Ixx=1.0e-4, payload_Iyy=1.2e-4)


def spec_machine_kinetic_energy(q, v, mc):
    """T of the mechanism plus the rotors, 1/2 J (2 pi / p)^2 rhod_i^2 each, and
    the payload: 1/2 m |v_P + phid z x Rz(phi) c|^2 + 1/2 Izz phid^2
    (docs/model.md "The machine around the mechanism", "Payload"; nothing from the engines)."""
    T = spec_kinetic_energy(q, v)
    gear = 2.0 * math.pi / mc.screw_lead
    T += sum(0.5 * mc.rotor_inertia * (gear * v[3 * i]) ** 2 for i in range(4))
    c = spec.rz(q[15]) @ np.array([mc.payload_com[0], mc.payload_com[1], mc.payload_z])
    v_com = v[12:15] + np.cross([0.0, 0.0, v[15]], c)
    return T + 0.5 * mc.payload_mass * v_com @ v_com + 0.5 * mc.payload_Izz * v[15] ** 2


def test_machine_mass_matrix_is_the_spec_kinetic_energy():
    pm = PinocchioPKM(machine=MACHINE)
    for _ in range(20):
        q, v = random_q(), RNG.normal(size=16)
        T_pin = 0.5 * v @ pm.mass_matrix(q) @ v
        T_spec = spec_machine_kinetic_energy(q, v, MACHINE)
        assert abs(T_pin - T_spec) <= 1e-14 * max(1.0, T_spec), (T_pin, T_spec)


def test_machine_gravity_and_rnea():
    """The payload's weight on z only (wherever its centre of mass), and
    Pinocchio's RNEA with the armature is M a + nle (so the inverse dynamics
    includes the rotors)."""
    pm = PinocchioPKM(machine=MACHINE)
    for _ in range(10):
        q, v, a = random_q(), RNG.normal(size=16), RNG.normal(size=16)
        G = pin.computeGeneralizedGravity(pm.model, pm.data, q)
        expected = spec_gravity(q)
        expected[14] += MACHINE.payload_mass * spec.G
        assert np.abs(G - expected).max() < 1e-14
        tau = pin.rnea(pm.model, pm.data, q, v, a)
        ref = pm.mass_matrix(q) @ a + pin.nonLinearEffects(pm.model, pm.data, q, v)
        assert np.abs(tau - ref).max() <= 1e-12 * np.abs(ref).max()


def test_machine_friction_forces():
    """The spec's law, F = -b rhod - F_c tanh(rhod / v_s), in the Pinocchio model's
    forward dynamics: the same accelerations as extra actuator forces."""
    pm = PinocchioPKM(g=spec.G, machine=MACHINE)
    pm_nf = PinocchioPKM(g=spec.G, machine=spec.Machine(
        screw_lead=MACHINE.screw_lead, rotor_inertia=MACHINE.rotor_inertia, payload_mass=MACHINE.payload_mass,
        payload_com=MACHINE.payload_com, payload_Izz=MACHINE.payload_Izz, payload_z=MACHINE.payload_z,
        payload_Ixx=MACHINE.payload_Ixx, payload_Iyy=MACHINE.payload_Iyy))
    q = pm.q_from_pose(spec.P1)
    v = pm.complete_velocity(q, np.array([0.01, -0.02, 0.015, 0.2]))
    rhod = v[[0, 3, 6, 9]]
    fric = np.array([-MACHINE.friction_viscous * r - MACHINE.friction_coulomb * math.tanh(r / MACHINE.friction_velocity)
                     for r in rhod])
    F = spec.STATIC_FORCE_P0 * np.ones(4)
    a, _ = pm.forward_dynamics(q, v, F)
    a_ref, _ = pm_nf.forward_dynamics(q, v, F + fric)
    assert np.abs(fric).min() > 1e-3
    assert np.abs(a - a_ref).max() <= 1e-12 * np.abs(a_ref).max()


def test_mujoco_is_the_same_machine():
    """Armature, payload body and joint damping of the MJCF against the Pinocchio model
    (M, bias forces, and MuJoCo's passive forces with the Coulomb callback)."""
    pm = PinocchioPKM(g=spec.G, machine=MACHINE)
    model, data = mujoco_model.build(g=spec.G, machine=MACHINE)
    M = np.zeros((16, 16))
    with mujoco_model.coulomb_passive(MACHINE):
        for _ in range(10):
            q, v = random_q(), RNG.normal(scale=0.01, size=16)
            data.qpos[:], data.qvel[:] = q, v
            mujoco.mj_forward(model, data)
            mujoco.mj_fullM(model, data, M)
            M_pin = pm.mass_matrix(q)
            assert np.abs(M - M_pin).max() <= 1e-12 * np.abs(M_pin).max()
            nle = pin.nonLinearEffects(pm.model, pm.data, q, v)
            assert np.abs(data.qfrc_bias - nle).max() <= 1e-12 * max(1.0, np.abs(nle).max())
            expected = np.zeros(16)
            expected[[0, 3, 6, 9]] = MACHINE.friction(v[[0, 3, 6, 9]])
            assert np.abs(data.qfrc_passive - expected).max() < 1e-15
    # the callback is removed again: the ideal model has no passive forces
    model0, data0 = mujoco_model.build(g=spec.G)
    data0.qvel[:] = 0.1
    mujoco.mj_forward(model0, data0)
    assert np.all(data0.qfrc_passive == 0.0)
