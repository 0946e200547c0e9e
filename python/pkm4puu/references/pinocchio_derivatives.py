# SPDX-License-Identifier: BSD-2-Clause
"""Derivatives of the reduced forward dynamics from Pinocchio, on the
independent model of pinocchio_model.py: the reference for this project's
analytic A = dydot/dy and B = dydot/du (pkm_forward_derivatives, the plant
FMU's directional derivatives).

The reduced state is y = (p, pd), p = (x, y, z, phi) the platform pose and pd
its rates; ydot = (pd, pdd). The inputs u are the plant's, in pkm.h's order:
F[1..4], Fe[1..3], Me_z, tau[1..4].

Taken from Pinocchio (its C++, analytic):
- qdd(q, v, tau) of the closed-loop tree: pinocchio.constraintDynamics with
  the 12 point constraints as RigidConstraintModels (CONTACT_3D between the
  rod's Q_i frame and the platform's R_i frame, no Baumgarte term), and its
  analytic derivatives d qdd / d(q, v, tau) from
  pinocchio.computeConstraintDynamicsDerivatives;
- the constraint Jacobian J = dC/dq (frame Jacobians, LOCAL_WORLD_ALIGNED);
- the derivatives of each frame's velocity in its LOCAL frame,
  d v_loc / dq at fixed v: pinocchio.computeForwardKinematicsDerivatives and
  getFrameVelocityDerivatives(LOCAL); the frame's rotation R and the angular
  rows J_w of its frame Jacobian. (Pinocchio's LOCAL_WORLD_ALIGNED velocity
  derivative is not the coordinate derivative of the world-aligned velocity
  -- Pinocchio issue #2702 on its conventions; measured here, it disagrees
  with differences by the size of the derivative itself -- so the LOCAL one is
  rotated by hand, below.)

Assembled here (the chain rule from the reduced state to Pinocchio's
coordinates; all joints are 1-DOF, so Pinocchio's tangent space is dq):
- d(J v)/dq at fixed v, the derivative of the loop-closure velocity
  v_Q - v_R, each point's world velocity being R v_loc (linear part):
  d(R v_loc)/dq = R d v_loc/dq - [R v_loc]x J_w  (dR/dq_k = [J_w e_k]x R);
- q(p): the spec's closed-form elbow-down leg inverse kinematics; its tangent
  T = dq/dp (16 x 4): T = [-J_L^-1 J_P; I] (J_L the 12 leg columns of J, J_P
  the platform's), the implicit-function derivative of C(q(p)) = 0;
- v(p, pd) = T(p) pd; dv/dpd = T; dv/dp_k = [-J_L^-1 (d(J v)/dq T e_k); 0],
  from differentiating J(q(p)) v(p, pd) = 0 along p;
- the generalised forces tau(u, v) = S (F + (2 pi/p_screw) tau_m + F_fric(rho_d))
  + E (Fe, Me_z) (S puts F_i on rho_i, E the wrench on x, y, z, phi), so
  dtau/du = [S, E, (2 pi/p_screw) S] and dtau/dv = S diag(F_fric'(rho_d)) S^T;
- A = [[0, I], [dpdd/dp, dpdd/dpd]], B = [[0], [dpdd/du]] with
  dpdd/dp  = qdd_q T + (qdd_v + qdd_tau dtau/dv) dv/dp  (platform rows),
  dpdd/dpd = (qdd_v + qdd_tau dtau/dv) T,
  dpdd/du  = qdd_tau dtau/du.

The machine's rotor inertia (Pinocchio's armature) and payload (a second body)
are in the model; the end stops are not (keep the states clear of them).
"""
import numpy as np
import pinocchio as pin

from .pinocchio_model import LEG_ROWS, NQ, WORLD, PinocchioPKM

N_STATES = 8
N_INPUTS = 12  # F[1..4], Fe[1..3], Me_z, tau[1..4]


class PinocchioReducedDerivatives:
    """ydot, A, B of the reduced forward dynamics at (p, pd, u), from
    Pinocchio's constraint dynamics and its derivatives (see the module)."""

    def __init__(self, pm: PinocchioPKM | None = None):
        self.pm = pm if pm is not None else PinocchioPKM()
        if self.pm._cd is None:
            self.pm.setup_constraint_dynamics()
        mc = self.pm.machine
        S = self.pm.S
        E = np.zeros((NQ, 4))
        E[12:, :] = np.eye(4)
        self.dtau_du = np.hstack([S, E, mc.gear * S])
        self._zero = np.zeros(NQ)

    def tangent(self, q):
        """T = dq/dp (16 x 4) on the constraint manifold, and J."""
        J = self.pm.jacobian(q)
        T = np.zeros((NQ, 4))
        T[12:] = np.eye(4)
        T[:12] = -np.linalg.solve(J[:, :12], J[:, 12:])
        return T, J

    def point_velocity_dq(self, frame):
        """d/dq at fixed v of the world velocity of a frame's origin (3 x 16),
        after computeForwardKinematicsDerivatives and computeJointJacobians."""
        m, d = self.pm.model, self.pm.data
        R = d.oMf[frame].rotation
        dv_local = pin.getFrameVelocityDerivatives(m, d, frame, pin.LOCAL)[0][:3]
        v_world = R @ pin.getFrameVelocity(m, d, frame, pin.LOCAL).linear
        J_w = pin.getFrameJacobian(m, d, frame, WORLD)[3:]
        return R @ dv_local - pin.skew(v_world) @ J_w

    def constraint_velocity_dq(self, q, v):
        """d(J v)/dq at fixed v (12 x 16): the derivative of v_Q - v_R."""
        pm = self.pm
        m, d = pm.model, pm.data
        pin.computeForwardKinematicsDerivatives(m, d, q, v, self._zero)
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        return np.vstack([self.point_velocity_dq(fq) - self.point_velocity_dq(fr)
                          for fq, fr in zip(pm.q_frames, pm.r_frames)])

    def generalized_forces(self, v, u):
        mc = self.pm.machine
        return self.dtau_du @ u + self.pm.S @ mc.friction(v[LEG_ROWS])

    def friction_slope(self, v):
        """dtau/dv (16 x 16): the friction's slope on the rho_i diagonal."""
        mc = self.pm.machine
        rd = v[LEG_ROWS]
        slope = -mc.friction_viscous - mc.friction_coulomb / mc.friction_velocity / np.cosh(rd / mc.friction_velocity) ** 2
        out = np.zeros((NQ, NQ))
        out[LEG_ROWS, LEG_ROWS] = slope
        return out

    def state_derivative(self, y, u):
        """ydot only (constraintDynamics)."""
        pm = self.pm
        p, pd = np.asarray(y[:4], float), np.asarray(y[4:], float)
        q = pm.q_from_pose(p)
        T, _ = self.tangent(q)
        v = T @ pd
        a = pin.constraintDynamics(pm.model, pm.data, q, v, self.generalized_forces(v, np.asarray(u, float)),
                                   pm._cm, pm._cd, pm._prox)
        return np.concatenate([pd, a[12:]])

    def __call__(self, y, u):
        """(ydot (8,), A (8, 8), B (8, 12)) at state y = (p, pd) and inputs u."""
        pm = self.pm
        m, d = pm.model, pm.data
        y, u = np.asarray(y, float), np.asarray(u, float)
        if y.shape != (N_STATES,) or u.shape != (N_INPUTS,):
            raise ValueError(f"y must have {N_STATES} values and u {N_INPUTS}, not {y.shape} and {u.shape}")
        p, pd = y[:4], y[4:]
        q = pm.q_from_pose(p)
        T, J = self.tangent(q)
        v = T @ pd
        a = pin.constraintDynamics(m, d, q, v, self.generalized_forces(v, u), pm._cm, pm._cd, pm._prox).copy()
        pin.computeConstraintDynamicsDerivatives(m, d, pm._cm, pm._cd, pm._prox)
        qdd_q, qdd_v, qdd_tau = d.ddq_dq.copy(), d.ddq_dv.copy(), d.ddq_dtau.copy()
        qdd_v_total = qdd_v + qdd_tau @ self.friction_slope(v)
        dv_dp = np.zeros((NQ, 4))
        dv_dp[:12] = -np.linalg.solve(J[:, :12], self.constraint_velocity_dq(q, v) @ T)
        P = slice(12, 16)
        A = np.zeros((N_STATES, N_STATES))
        A[:4, 4:] = np.eye(4)
        A[4:, :4] = qdd_q[P] @ T + qdd_v_total[P] @ dv_dp
        A[4:, 4:] = qdd_v_total[P] @ T
        B = np.zeros((N_STATES, N_INPUTS))
        B[4:] = qdd_tau[P] @ self.dtau_du
        return np.concatenate([pd, a[P]]), A, B
