# SPDX-License-Identifier: BSD-2-Clause
"""An independent model of the 4-PUU mechanism in Pinocchio, built from
docs/model.md's numbers only (pkm4puu.spec), used as the reference for the
project's dynamics.

Structure (a kinematic tree plus loop closures):
- each leg i is a chain from the base: prismatic rho_i along z of the leg
  frame 0_i (origin B_i + h z, orientation Rz(beta_i): the DH row 1 offset h
  is folded into the placement), then revolute theta1_i about the same z
  (DH row 2's theta), then a fixed Rx(pi/2) (row 2's alpha) and revolute
  theta2_i about the new z (row 3's theta); the body of that last joint is
  the rod (link 3), whose joint frame has the DH frame 3 axes (the row 3
  translation a = l does not rotate), so its centre of mass is at (l/2, 0, 0)
  and its inertia diag(I_rod) is given in these axes. The slider (link 1) is
  a point mass on the prismatic joint; the U-joint cross (link 2, between
  theta1 and theta2) is massless. Q_i, the end of DH row 4 (h' along z3), is
  the point (l, 0, h') of the rod joint frame: a frame "Q{i}".
- the platform is a chain of four joints from the base: PX, PY, PZ, RZ, so
  its configuration is exactly (x, y, z, phi); its body (mass m_platform,
  inertia diag(0, 0, Izz) about P) sits on the RZ joint. The anchor r_Qi is
  the frame "R{i}" on it.
- the legs are added first, so Pinocchio's q is the spec's order
  [rho1, th1_1, th2_1, ..., rho4, th1_4, th2_4, x, y, z, phi].
- the loop closures are 12 point constraints C_i = p(Q_i) - p(R_i) = 0
  (docs/model.md Eq. 15, same sign), with Jacobian J = J_Q - J_R from the frame
  Jacobians (LOCAL_WORLD_ALIGNED, linear rows) and the bias
  gamma = (classical acceleration of Q_i - of R_i at qdd = 0), so
  C_dd = J qdd + gamma.

The machine around the mechanism (docs/model.md; spec.Machine, optional):
- rotor inertia: Pinocchio's model.armature on the rho_i joints,
  J (2 pi / p)^2, which crba and rnea add to M's diagonal and to the joint
  torque (armature * rho_i_dd);
- the payload: a second body rigidly attached to the platform joint at
  (payload_com, payload_z) in the platform frame, with its own inertia
  diag(Ixx, Iyy, Izz) about its centre of mass (Pinocchio's spatial
  inertia algebra moves it to the joint, as for a URDF fixed joint);
- joint friction: a joint force -b rhod_i - F_c tanh(rhod_i / v_s) on rho_i,
  added to S F in the forward dynamics and taken from it in the inverse.

The dynamics use the project's sign convention for the multipliers,
M qdd + nle + J^T lambda = S F (S puts F_i on rho_i): then lambda is the
spec's lambda.

Constrained forward dynamics is done here, in full: the KKT system
[[M, J^T], [J, 0]] [qdd; lambda] = [S F - nle; -gamma] with M from CRBA and
nle from RNEA (pinocchio), solved densely. pinocchio's own constraintDynamics
(RigidConstraintModel CONTACT_3D between the two joints) is set up too, as a
cross-check and for the benchmark.
"""
import math

import numpy as np
import pinocchio as pin

from .. import spec

NQ = 16
LEG_ROWS = [3 * i for i in range(4)]  # index of rho_i in q
PLATFORM = slice(12, 16)
WORLD = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


class PinocchioPKM:
    def __init__(self, g=spec.G, machine=None):
        self.machine = machine if machine is not None else spec.Machine()
        model = pin.Model()
        model.name = "pkm4puu"
        self.q_frames, self.r_frames = [], []
        self.rod_joints = []
        for i in range(4):
            b = spec.base_point(i)
            j_rho = model.addJoint(0, pin.JointModelPZ(),
                                   pin.SE3(spec.rz(spec.BETA[i]), b + np.array([0.0, 0.0, spec.H])), f"rho{i + 1}")
            model.appendBodyToJoint(j_rho, pin.Inertia(spec.M_SLIDER, np.zeros(3), np.zeros((3, 3))), pin.SE3.Identity())
            j_th1 = model.addJoint(j_rho, pin.JointModelRZ(), pin.SE3.Identity(), f"theta1_{i + 1}")
            # the U-joint cross (link 2) is massless: no body on j_th1
            j_th2 = model.addJoint(j_th1, pin.JointModelRZ(), pin.SE3(_rx(math.pi / 2), np.zeros(3)),
                                   f"theta2_{i + 1}")
            rod = pin.Inertia(spec.M_ROD, np.array([spec.L / 2, 0.0, 0.0]), np.diag(spec.I_ROD))
            model.appendBodyToJoint(j_th2, rod, pin.SE3.Identity())
            self.rod_joints.append(j_th2)
            self.q_frames.append(model.addFrame(pin.Frame(
                f"Q{i + 1}", j_th2, 0, pin.SE3(np.eye(3), np.array([spec.L, 0.0, spec.H_PRIME])),
                pin.FrameType.OP_FRAME)))
        j = 0
        for name, jm in (("x", pin.JointModelPX()), ("y", pin.JointModelPY()), ("z", pin.JointModelPZ()),
                         ("phi", pin.JointModelRZ())):
            j = model.addJoint(j, jm, pin.SE3.Identity(), name)
        self.platform_joint = j
        model.appendBodyToJoint(j, pin.Inertia(spec.M_PLATFORM, np.zeros(3),
                                               np.diag([0.0, 0.0, spec.IZZ_PLATFORM])), pin.SE3.Identity())
        mc = self.machine
        if mc.payload_mass > 0.0:
            at = np.array([mc.payload_com[0], mc.payload_com[1], mc.payload_z])
            model.appendBodyToJoint(j, pin.Inertia(mc.payload_mass, np.zeros(3),
                                                   np.diag([mc.payload_Ixx, mc.payload_Iyy, mc.payload_Izz])),
                                    pin.SE3(np.eye(3), at))
        for i in range(4):
            self.r_frames.append(model.addFrame(pin.Frame(
                f"R{i + 1}", j, 0, pin.SE3(np.eye(3), spec.platform_point(i)), pin.FrameType.OP_FRAME)))
        model.gravity = pin.Motion(np.array([0.0, 0.0, -g]), np.zeros(3))
        assert model.nq == NQ and model.nv == NQ
        for i in range(4):
            model.armature[model.joints[model.getJointId(f"rho{i + 1}")].idx_v] = mc.reflected_mass
        self.model = model
        self.data = model.createData()
        self.S = np.zeros((NQ, 4))
        for i, r in enumerate(LEG_ROWS):
            self.S[r, i] = 1.0
        self._zero = np.zeros(NQ)
        self._cd = None

    # --- kinematics --------------------------------------------------------------------------
    def q_from_pose(self, pose):
        """Consistent q from the platform pose (spec's closed-form leg inverse kinematics)."""
        q = np.empty(NQ)
        q[:12] = spec.leg_inverse_kinematics(pose).ravel()
        q[12:] = pose
        return q

    def constraints(self, q):
        """C(q), 12 values, from Pinocchio's frame placements."""
        m, d = self.model, self.data
        pin.framesForwardKinematics(m, d, q)
        return np.concatenate([d.oMf[fq].translation - d.oMf[fr].translation
                               for fq, fr in zip(self.q_frames, self.r_frames)])

    def jacobian(self, q):
        """J = dC/dq (12 x 16)."""
        m, d = self.model, self.data
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        return np.vstack([pin.getFrameJacobian(m, d, fq, WORLD)[:3] - pin.getFrameJacobian(m, d, fr, WORLD)[:3]
                          for fq, fr in zip(self.q_frames, self.r_frames)])

    def bias(self, q, v):
        """gamma(q, v): C_dd = J qdd + gamma."""
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, q, v, self._zero)
        return np.concatenate([pin.getFrameClassicalAcceleration(m, d, fq, WORLD).linear
                               - pin.getFrameClassicalAcceleration(m, d, fr, WORLD).linear
                               for fq, fr in zip(self.q_frames, self.r_frames)])

    def complete_velocity(self, q, pose_rate, J=None):
        """Leg rates from the platform rates: J_legs v_legs = -J_platform v_platform."""
        J = self.jacobian(q) if J is None else J
        v = np.empty(NQ)
        v[12:] = pose_rate
        v[:12] = np.linalg.solve(J[:, :12], -J[:, 12:] @ pose_rate)
        return v

    def complete_acceleration(self, q, v, pose_acc, J=None):
        J = self.jacobian(q) if J is None else J
        a = np.empty(NQ)
        a[12:] = pose_acc
        a[:12] = np.linalg.solve(J[:, :12], -self.bias(q, v) - J[:, 12:] @ pose_acc)
        return a

    def project(self, q, v, iterations=5):
        """Projects q onto C(q) = 0 (Newton on the leg coordinates, platform held)
        and v onto J v = 0 (leg rates from the platform rates)."""
        q = q.copy()
        for _ in range(iterations):
            c = self.constraints(q)
            if np.abs(c).max() < 1e-16:
                break
            J = self.jacobian(q)
            q[:12] -= np.linalg.solve(J[:, :12], c)
        return q, self.complete_velocity(q, v[12:])

    # --- dynamics -------------------------------------------------------------------------------
    def mass_matrix(self, q):
        M = pin.crba(self.model, self.data, q)
        return np.triu(M) + np.triu(M, 1).T

    def inverse_dynamics(self, pose, pose_rate, pose_acc):
        """Actuator forces F (4) and multipliers lambda (12) that produce the
        platform motion (pose, rate, acceleration): RNEA for the tree, then
        J^T lambda - S F = -tau_rnea + S F_fric (16 equations, 16 unknowns)."""
        q = self.q_from_pose(pose)
        J = self.jacobian(q)
        v = self.complete_velocity(q, pose_rate, J)
        a = self.complete_acceleration(q, v, pose_acc, J)
        tau = pin.rnea(self.model, self.data, q, v, a)  # armature * rho_dd included
        tau -= self.S @ self.machine.friction(v[LEG_ROWS])
        x = np.linalg.solve(np.hstack([J.T, -self.S]), -tau)
        return x[12:], x[:12], (q, v, a)

    def forward_dynamics(self, q, v, F):
        """qdd and lambda from the KKT system (M from CRBA, nle from RNEA)."""
        M = self.mass_matrix(q)
        nle = pin.nonLinearEffects(self.model, self.data, q, v)
        J = self.jacobian(q)
        gamma = self.bias(q, v)
        K = np.zeros((28, 28))
        K[:16, :16] = M
        K[:16, 16:] = J.T
        K[16:, :16] = J
        rhs = np.concatenate([self.S @ (F + self.machine.friction(v[LEG_ROWS])) - nle, -gamma])
        x = np.linalg.solve(K, rhs)
        return x[:16], x[16:]

    # --- pinocchio's own constraint dynamics (cross-check, benchmark) --------------------------------
    def setup_constraint_dynamics(self):
        """Pinocchio's RigidConstraintModel CONTACT_3D between Q_i (on the rod
        joint) and R_i (on the platform joint); LOCAL_WORLD_ALIGNED, no
        Baumgarte correction."""
        m = self.model
        models = []
        for i in range(4):
            fq, fr = m.frames[self.q_frames[i]], m.frames[self.r_frames[i]]
            cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, m, fq.parentJoint, fq.placement,
                                          fr.parentJoint, fr.placement, WORLD)
            models.append(cm)
        self._cm = pin.StdVec_RigidConstraintModel()
        self._cd = pin.StdVec_RigidConstraintData()
        for cm in models:
            self._cm.append(cm)
            self._cd.append(cm.createData())
        pin.initConstraintDynamics(m, self.data, self._cm, self._cd)
        self._prox = pin.ProximalSettings(1e-14, 0.0, 1)

    def constraint_dynamics(self, q, v, F):
        """qdd from pinocchio.constraintDynamics (call setup_constraint_dynamics first)."""
        tau = self.S @ (F + self.machine.friction(v[LEG_ROWS]))
        return pin.constraintDynamics(self.model, self.data, q, v, tau, self._cm, self._cd, self._prox)
