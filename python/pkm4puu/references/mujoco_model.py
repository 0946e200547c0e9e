# SPDX-License-Identifier: BSD-2-Clause
"""An independent model of the 4-PUU mechanism in MuJoCo (MJCF), built from
docs/model.md's numbers only (pkm4puu.spec).

Bodies (the same tree as engines/pinocchio_model.py):
- leg i: body "slider{i}" at B_i + h z, oriented Rz(beta_i), with a slide
  joint rho_i along its z (mass m_slider; it only translates, so its
  rotational inertia never enters the dynamics: a tiny positive value keeps
  MuJoCo's compiler happy); child body "rod{i}" at the U-joint centre O2 with
  two hinges, theta1_i about z, then theta2_i about -y (MuJoCo applies a
  body's joints in order, each about its axis in the frame already moved by
  the previous ones: this is DH row 2's Rz(theta1) Rx(pi/2) followed by row
  3's Rz(theta2), written in the leg frame, since Rx(pi/2) maps z onto -y).
  In the rod's body frame the DH frame 3 axes are x3 = x, y3 = z, z3 = -y,
  so the spec's diag(I_x3, I_y3, I_z3) is diaginertia (I_x3, I_z3, I_y3);
  the centre of mass is (l/2, 0, 0) and Q_i = l x3 + h' z3 = (l, -h', 0)
  (site "Q{i}").
- the platform: body "platform" with slide joints x, y, z and a hinge phi
  about z (mass m_platform, Izz_platform; its Ixx, Iyy never enter, since it
  cannot tilt: Izz/2 each keeps the compiler's triangle inequality); sites
  "R{i}" at r_Qi.
- loop closures: <connect site1="Q{i}" site2="R{i}"/>, 3 scalar equality
  constraints each, with solref / solimp as given (MuJoCo's constraints are
  soft by design).
- actuators: a motor with gear 1 on each rho_i, so ctrl = F (N).
- contacts disabled (there are no geoms that matter).
- the machine around the mechanism (docs/model.md; spec.Machine, optional):
  rotor inertia as the slider joints' armature, J (2 pi / p)^2; viscous
  friction as their damping b (MuJoCo's joint damper, -b qvel; the damper
  flag is on only when a machine is given); the payload as a body
  "payload" without joints inside the platform body (rigidly attached) at
  (payload_com, payload_z), its own inertia diag(Ixx, Iyy, Izz). Coulomb
  friction with tanh regularisation has no MuJoCo element: coulomb_passive()
  adds it through MuJoCo's passive-force callback.

The joints are declared legs first, so qpos is the spec's order
[rho1, th1_1, th2_1, ..., x, y, z, phi].
"""
import contextlib

import numpy as np
import mujoco

from .. import motions, spec

# The stiffest setting (engine_comparison.py prints a sweep around it): the
# smallest time constant MuJoCo accepts with refsafe on (2 timesteps), critical
# damping, and the largest impedance it allows, d = 0.9999 (mjMAXIMP). At 1 ms
# with RK4 this leaves max ||C(q)|| ~ 1.5e-10 m on the comparison test; with
# refsafe off, shorter time constants do not reduce it further (0.0015 s:
# 3e-10 m, 0.001 s: 9e-10 m, 0.0001 s: unstable), nor does d < 0.9999.
DEFAULT_SOLREF = (0.002, 1.0)
DEFAULT_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def _v(a):
    return " ".join(f"{float(x):.17g}" for x in a)


def mjcf(g=spec.G, timestep=1e-3, integrator="RK4", solref=DEFAULT_SOLREF, solimp=DEFAULT_SOLIMP,
         tolerance=1e-15, iterations=100, refsafe=True, machine=None):
    legs, eqs, acts, sites = [], [], [], []
    slide = ""
    if machine is not None:
        slide = f' armature="{machine.reflected_mass:.17g}" damping="{machine.friction_viscous:.17g}"'
    payload = ""
    if machine is not None and machine.payload_mass > 0.0:
        # Ixx + Iyy >= Izz etc. (MuJoCo's triangle inequality): Ixx, Iyy never enter (no tilt)
        at = (machine.payload_com[0], machine.payload_com[1], machine.payload_z)
        inertia = (machine.payload_Ixx, machine.payload_Iyy, machine.payload_Izz)
        payload = f"""
      <body name="payload" pos="{_v(at)}">
        <inertial pos="0 0 0" mass="{machine.payload_mass:.17g}" diaginertia="{_v(inertia)}"/>
      </body>"""
    tiny = 1e-9  # kg m^2: rotational inertia of the slider, never used (it only translates)
    rod_inertia = (spec.I_ROD[0], spec.I_ROD[2], spec.I_ROD[1])
    for i in range(4):
        n = i + 1
        pos = spec.base_point(i) + np.array([0.0, 0.0, spec.H])
        legs.append(f"""
    <body name="slider{n}" pos="{_v(pos)}" euler="0 0 {spec.BETA[i]:.17g}">
      <joint name="rho{n}" type="slide" axis="0 0 1"{slide}/>
      <inertial pos="0 0 0" mass="{spec.M_SLIDER:.17g}" diaginertia="{tiny} {tiny} {tiny}"/>
      <body name="rod{n}">
        <joint name="theta1_{n}" type="hinge" axis="0 0 1"/>
        <joint name="theta2_{n}" type="hinge" axis="0 -1 0"/>
        <inertial pos="{spec.L / 2:.17g} 0 0" mass="{spec.M_ROD:.17g}" diaginertia="{_v(rod_inertia)}"/>
        <site name="Q{n}" pos="{spec.L:.17g} {-spec.H_PRIME:.17g} 0"/>
      </body>
    </body>""")
        sites.append(f'      <site name="R{n}" pos="{_v(spec.platform_point(i))}"/>')
        eqs.append(f'    <connect site1="Q{n}" site2="R{n}" solref="{_v(solref)}" solimp="{_v(solimp)}"/>')
        acts.append(f'    <motor name="F{n}" joint="rho{n}" gear="1"/>')
    izz = spec.IZZ_PLATFORM
    # Everything this model does not use is switched off (contacts, springs,
    # dampers, limits, friction loss, sensors, control clamping, collision
    # filtering, midphase) and so is the solver's warm start: the results are
    # bit-identical and mj_step faster, so the engines benchmark times MuJoCo
    # at its best.
    damper = "" if machine is not None else ' damper="disable"'
    flags = (f'<flag contact="disable" spring="disable"{damper} limit="disable" frictionloss="disable" '
             'sensor="disable" clampctrl="disable" filterparent="disable" midphase="disable" warmstart="disable"'
             + ('' if refsafe else ' refsafe="disable"') + '/>')
    return f"""<mujoco model="pkm4puu">
  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>
  <option timestep="{timestep:.17g}" integrator="{integrator}" gravity="0 0 {-g:.17g}" solver="Newton"
          tolerance="{tolerance:.17g}" iterations="{iterations}" ls_tolerance="1e-12" ls_iterations="100">
    {flags}
  </option>
  <worldbody>{''.join(legs)}
    <body name="platform">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="y" type="slide" axis="0 1 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <joint name="phi" type="hinge" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{spec.M_PLATFORM:.17g}" diaginertia="{izz / 2:.17g} {izz / 2:.17g} {izz:.17g}"/>
{chr(10).join(sites)}{payload}
    </body>
  </worldbody>
  <equality>
{chr(10).join(eqs)}
  </equality>
  <actuator>
{chr(10).join(acts)}
  </actuator>
</mujoco>
"""


def build(**kw):
    """(model, data) at the spec's home pose P0, at rest (qpos from the spec's
    closed-form leg inverse kinematics)."""
    model = mujoco.MjModel.from_xml_string(mjcf(**kw))
    data = mujoco.MjData(model)
    set_pose(model, data, spec.P0)
    return model, data


def set_pose(model, data, pose):
    mujoco.mj_resetData(model, data)
    data.qpos[:12] = spec.leg_inverse_kinematics(pose).ravel()
    data.qpos[12:] = pose
    data.qvel[:] = 0.0
    mujoco.mj_forward(model, data)


def run_comparison(model, data, duration=spec.CMP_DURATION, forces=motions.comparison_forces):
    """The comparison test with mj_step at model.opt.timestep; forces (F1..F4
    as a function of t, default the spec's) held over each step at the
    step's midpoint value. Returns (t, qpos rows)."""
    h = model.opt.timestep
    n = round(duration / h)
    t = np.arange(n + 1) * h
    Q = np.empty((n + 1, model.nq))
    Q[0] = data.qpos
    for k in range(n):
        data.ctrl[:] = forces((k + 0.5) * h)
        mujoco.mj_step(model, data)
        Q[k + 1] = data.qpos
    return t, Q


@contextlib.contextmanager
def coulomb_passive(machine):
    """Regularised Coulomb friction -F_c tanh(qvel / v_s) on the slider joints
    (qvel indices 0, 3, 6, 9), added to qfrc_passive by MuJoCo's passive-force
    callback (global to the process: installed for the with block only).
    mj_passive calls it at every evaluation, so RK4 sees it at each stage."""
    if machine is None or machine.friction_coulomb == 0.0:
        yield
        return
    idx = np.array([0, 3, 6, 9])
    fc, vs = machine.friction_coulomb, machine.friction_velocity

    def passive(_model, data):
        data.qfrc_passive[idx] -= fc * np.tanh(data.qvel[idx] / vs)

    mujoco.set_mjcb_passive(passive)
    try:
        yield
    finally:
        mujoco.set_mjcb_passive(None)
