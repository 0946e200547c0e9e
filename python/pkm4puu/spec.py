# SPDX-License-Identifier: BSD-2-Clause
"""The mechanism's numbers, copied once from docs/model.md (the project's
authoritative definition), and the geometry they define: for the checks, the
independent reference models (Pinocchio, MuJoCo) and the examples. Nothing
here is read from this project's code or outputs.

This is the checks' independent copy, not the product's list of
parameters: that is the parameter table of the C++ sources, which the FMUs'
model descriptions, the C API (pkm_parameter_info) and pkm4puu.capi read;
the tests compare the two (test_fmu_interface.py, test_capi_binding.py).

SI units: the spec's Tables II-III are already converted there (m, kg, kg m^2).
"""
import math

import numpy as np

# --- Geometry defaults (Table II) -----------------------------------------------
H = 0.06634  # m, offset of the prismatic joint (d1 = rho + h)
L = 0.080  # m, rod length (a3)
H_PRIME = 0.075  # m, d4: Q lies h' along the third revolute axis z3
R_B = 0.09273  # m, base radius
R_Q = 0.075  # m, platform radius

# --- Leg placement ------------------------------------------------------------------
BETA = [(i - 1) * math.pi / 2 for i in range(1, 5)]  # rad
GAMMA = [math.radians(g) for g in (65.0, -65.0, 65.0, -65.0)]  # rad

# --- Bodies (Table III; U-joint crosses, links 2 and 4, massless) ----------------------
M_SLIDER = 0.09331  # kg, link 1: translates only
M_ROD = 0.06371  # kg, link 3
I_ROD = (3.83e-6, 49.86e-6, 52.64e-6)  # kg m^2, about its COM, DH frame 3 axes (x3, y3, z3)
M_PLATFORM = 0.45474  # kg
IZZ_PLATFORM = 2874.21e-6  # kg m^2 (Ixx = Iyy = 0)
G = 9.81  # m/s^2 along -z_G

# "A check anyone can derive": each actuator's share of the weight at P0, and
# the weight of everything that moves.
STATIC_FORCE_P0 = 2.655616050  # N
TOTAL_WEIGHT = 10.622464200  # N

# --- Auto-test (paper 5.1) ----------------------------------------------------------------
T_MOVE = 2.0  # s
P0 = np.array([0.0, 0.0, 0.05, 0.0])  # x, y, z (m), phi (rad)
P1 = np.array([0.005, -0.005, 0.07, math.radians(4.0)])

# --- Comparison test (paper 5.2) ------------------------------------------------------------
CMP_DURATION = 1.5  # s
CMP_AMPLITUDE = 0.02  # N

# --- Pick-and-place: the standard cycle (docs/pick_and_place.md) -----------------------------
# The arch x = -a cos(pi s), y = 0, z = z0 + h sin(pi s), phi = -(theta/2) cos(pi s),
# s in [0, 1], from A (s = 0) to B (s = 1) with the payload (at P), back empty.
CYCLE_A = 0.010  # m
CYCLE_H = 0.020  # m
CYCLE_Z0 = 0.050  # m
CYCLE_THETA = math.radians(10.0)  # rad
CYCLE_F_MAX = 10.0  # N, |F_i|
CYCLE_V_MAX = 0.5  # m/s, |drho_i/dt|
CYCLE_PAYLOAD = 0.25  # kg

# The paper's RK4 step, and the communication step of the tests and examples.
STEP = 1e-3  # s


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def base_point(i):
    """B_i (leg i = 0..3) in the base frame G."""
    return R_B * np.array([math.cos(BETA[i]), math.sin(BETA[i]), 0.0])


def platform_point(i):
    """r_Qi (leg i = 0..3) in the platform frame."""
    a = BETA[i] + GAMMA[i]
    return R_Q * np.array([math.cos(a), math.sin(a), 0.0])


def leg_inverse_kinematics(pose):
    """The spec's closed-form elbow-down leg inverse kinematics: (rho, theta1,
    theta2) for each leg at pose (x, y, z, phi), as a 4x3 array."""
    p = np.asarray(pose[:3], dtype=float)
    out = np.empty((4, 3))
    for i in range(4):
        qt = rz(BETA[i]).T @ (p + rz(pose[3]) @ platform_point(i) - base_point(i))
        a = math.sqrt(qt[0] ** 2 + qt[1] ** 2 - H_PRIME**2)
        th1 = math.atan2(qt[1], qt[0]) + math.atan2(H_PRIME, a)
        th2 = -math.acos(a / L)
        out[i] = (qt[2] - H - L * math.sin(th2), th1, th2)
    return out


def leg_end_point(i, rho, th1, th2):
    """Q_i in G from the spec's multiplied-out DH product (for checks)."""
    c1, s1, c2, s2 = math.cos(th1), math.sin(th1), math.cos(th2), math.sin(th2)
    pq = np.array([L * c1 * c2 + H_PRIME * s1, L * s1 * c2 - H_PRIME * c1, rho + H + L * s2])
    return base_point(i) + rz(BETA[i]) @ pq


def constraint_residual(q16):
    """C(q) of Eq. 15 (12 values) for q in the spec's order
    [rho1, th1_1, th2_1, ..., rho4, th1_4, th2_4, x, y, z, phi]."""
    q16 = np.asarray(q16, dtype=float)
    p, phi = q16[12:15], q16[15]
    return np.concatenate([leg_end_point(i, *q16[3 * i:3 * i + 3]) - p - rz(phi) @ platform_point(i)
                           for i in range(4)])


def vertical_momentum(drho, dz, payload_mass=0.0, reflected_mass=0.0):
    """The machine's vertical momentum (kg m/s) from the actuator rates drho
    (..., 4) and the platform's vertical rate dz: the sliders (with the
    rotors' reflected mass) move with drho_i; each rod's centre is the
    midpoint of O2 (height rho_i + h) and O3, which is at the platform's
    height (Q = O3 + h' z3 with z3 horizontal), so it moves with
    (drho_i + dz) / 2; platform and payload with dz. All actuator axes are
    vertical: its rate is sum F - weight - sum friction (no stop acting)."""
    drho = np.asarray(drho, dtype=float)
    return ((M_SLIDER + reflected_mass + M_ROD / 2) * drho.sum(axis=-1)
            + (2 * M_ROD + M_PLATFORM + payload_mass) * np.asarray(dz, dtype=float))


# --- The machine around the mechanism (docs/model.md "The machine around the mechanism") ----------
# Defaults of the spec; every one leaves the paper's ideal machine unchanged.
SCREW_LEAD = 0.004  # m per revolution
FRICTION_VELOCITY = 1e-3  # m/s, v_s of the tanh regularisation
RHO_MIN, RHO_MAX = 0.0, 0.15  # m, end stops
STOP_STIFFNESS, STOP_DAMPING = 1e5, 100.0  # N/m, N s/m: the compliant stops' k and d


class Machine:
    """The machine's parameters (docs/model.md names, SI units; defaults: the
    spec's). payload_z (m) is not a spec parameter: the height of the
    payload's centre of mass above P in the platform frame, which the spec
    says cannot matter (the platform only translates and turns about z), so
    the engine models may place the payload body off P's plane to check it;
    payload_Ixx, payload_Iyy likewise (the platform cannot tilt)."""

    def __init__(self, screw_lead=SCREW_LEAD, rotor_inertia=0.0, friction_viscous=0.0, friction_coulomb=0.0,
                 friction_velocity=FRICTION_VELOCITY, payload_mass=0.0, payload_com=(0.0, 0.0), payload_Izz=0.0,
                 payload_z=0.0, payload_Ixx=0.0, payload_Iyy=0.0):
        self.screw_lead = screw_lead
        self.rotor_inertia = rotor_inertia
        self.friction_viscous = friction_viscous
        self.friction_coulomb = friction_coulomb
        self.friction_velocity = friction_velocity
        self.payload_mass = payload_mass
        self.payload_com = tuple(payload_com)
        self.payload_Izz = payload_Izz
        self.payload_z = payload_z
        self.payload_Ixx = payload_Ixx
        self.payload_Iyy = payload_Iyy

    @property
    def gear(self):
        """2 pi / p (rad/m): a motor torque tau adds gear * tau to F."""
        return 2.0 * math.pi / self.screw_lead

    @property
    def reflected_mass(self):
        """J (2 pi / p)^2 (kg), on each rho_i's diagonal of M."""
        return self.rotor_inertia * self.gear**2

    def friction(self, rho_dot):
        """F_fric,i = -b rhod_i - F_c tanh(rhod_i / v_s) (N), elementwise."""
        rho_dot = np.asarray(rho_dot, dtype=float)
        return (-self.friction_viscous * rho_dot
                - self.friction_coulomb * np.tanh(rho_dot / self.friction_velocity))

    def parameters(self):
        """The parameters this machine sets, by the FMUs' names (end stops:
        the defaults), for the C API: ``capi.Plant(lib, **machine.parameters())``."""
        return {"screw_lead": self.screw_lead, "rotor_inertia": self.rotor_inertia,
                "friction_viscous": self.friction_viscous, "friction_coulomb": self.friction_coulomb,
                "friction_velocity": self.friction_velocity, "payload_mass": self.payload_mass,
                "payload_com": self.payload_com, "payload_Izz": self.payload_Izz}


# --- The FMUs' parameter defaults (docs/model.md "The FMUs' names") -------------------------
PARAMETER_DEFAULTS = {
    "h": H, "l": L, "h_prime": H_PRIME, "r_b": R_B, "r_Q": R_Q,
    **{f"beta[{i + 1}]": BETA[i] for i in range(4)},
    **{f"gamma[{i + 1}]": GAMMA[i] for i in range(4)},
    "m_slider": M_SLIDER, "m_rod": M_ROD, **{f"I_rod[{k + 1}]": I_ROD[k] for k in range(3)},
    "m_platform": M_PLATFORM, "Izz_platform": IZZ_PLATFORM, "g": G,
}
# The plant's `solver` parameter: 0 CVODE (the default), 1 fixed-step RK4.
SOLVER_CVODE, SOLVER_RK4 = 0, 1
SOLVER_DEFAULTS = {"solver": SOLVER_CVODE, "rk4_step": 1e-3, "rtol": 1e-8, "atol": 1e-10}
