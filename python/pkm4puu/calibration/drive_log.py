# SPDX-License-Identifier: BSD-2-Clause
"""A drive log made by the plant FMU: the machine with "true" parameters
driven along a platform trajectory, as a real machine's drives would log it
(docs/calibration.md, the closed-loop example and test).

The forces: the inverse FMU (PKM4PUU_Inverse) with the true parameters as
feed-forward along the reference motion, plus a PD on each slider's
position error; the plant FMU (PKM4PUU) integrates the motion under them,
each force given to the FMU with its rate over the step (input
derivatives), so that the force logged at t_k is the one acting at t_k.
The log then gets the measurement's imperfections: Gaussian force noise
(a fraction of each leg's RMS force) and encoder quantisation of rho.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from fmpy.fmi1 import FMICallException

from ..fmu import Fmu, find_fmu
from ..interface import ACC, DRHO, F, POSE, RHO, VEL


@dataclass
class DriveLog:
    t: np.ndarray        # (n,) s
    rho: np.ndarray      # (n, 4) m, as measured (quantised)
    F: np.ndarray        # (n, 4) N, as measured (noisy)
    rho_true: np.ndarray  # (n, 4) m, the plant's
    F_true: np.ndarray   # (n, 4) N, the forces applied
    pose_ref: np.ndarray  # (n, 4) the reference motion
    vel_ref: np.ndarray
    acc_ref: np.ndarray


def feedforward(trajectory, t, params, build=None, inverse=None):
    """The inverse FMU's forces, sliders' positions and rates along the
    trajectory at times t, with the FMU parameters `params`."""
    pose, vel, acc = trajectory.evaluate(t)
    Fs, rho, drho = np.empty((len(t), 4)), np.empty((len(t), 4)), np.empty((len(t), 4))
    with Fmu(inverse or find_fmu("PKM4PUU_Inverse", 2, build), start=params) as inv:
        names = POSE + VEL + ACC
        for k in range(len(t)):
            inv.set(names, np.concatenate([pose[k], vel[k], acc[k]]))
            out = inv.get(F + RHO + DRHO)
            Fs[k], rho[k], drho[k] = out[:4], out[4:8], out[8:]
    return Fs, rho, drho, (pose, vel, acc)


def replay(forces, t, params, pose0, vel0, build=None, plant=None):
    """The plant FMU with `params` from (pose0, vel0) at t[0] under the
    logged forces (linear between the samples): the sliders' positions at
    t, and the time reached if the FMU stopped early (a singularity guard:
    the rest is NaN)."""
    start = dict(params)
    start.update(zip(("x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0"), map(float, [*pose0, *vel0])))
    rho = np.full((len(t), 4), np.nan)
    with Fmu(plant or find_fmu("PKM4PUU", 2, build), start=start, start_time=float(t[0])) as fmu:
        rho[0] = fmu.get(RHO)
        for k in range(len(t) - 1):
            h = t[k + 1] - t[k]
            fmu.set(F, forces[k])
            fmu.set_derivatives(F, (forces[k + 1] - forces[k]) / h)
            try:
                fmu.do_step(t[k], h)
            except FMICallException:  # the FMU refused the step (its guards): the motion left the workspace
                return rho, t[k]
            rho[k + 1] = fmu.get(RHO)
    return rho, t[-1]


def simulate_drive_log(trajectory, duration, params, *, step=1e-3, kp=3000.0, kd=60.0, force_noise=0.01,
                       quantum=1e-6, seed=0, build=None) -> DriveLog:
    """The plant FMU with the true parameters `params` (FMU names) driven
    along `trajectory` (evaluate(t) -> pose, vel, acc) for `duration` s,
    logged every `step` s; force_noise: the noise's standard deviation as a
    fraction of each leg's RMS force; quantum: the encoder's resolution (m)."""
    n = int(round(duration / step)) + 1
    t = np.arange(n) * step
    FF, rho_ref, drho_ref, (pose, vel, acc) = feedforward(trajectory, t, params, build)
    start = dict(params)
    start.update(zip(("x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0"), map(float, [*pose[0], *vel[0]])))
    rho_true, F_applied = np.empty((n, 4)), np.empty((n, 4))
    with Fmu(find_fmu("PKM4PUU", 2, build), start=start) as fmu:
        for k in range(n):
            out = fmu.get(RHO + DRHO)
            rho, drho = out[:4], out[4:]
            Fk = FF[k] + kp * (rho_ref[k] - rho) + kd * (drho_ref[k] - drho)
            rho_true[k], F_applied[k] = rho, Fk
            if k == n - 1:
                break
            # The force's rate over the step: the feed-forward's and the
            # PD's position term's (its rate term needs the acceleration).
            dF = (FF[k + 1] - FF[k]) / step + kp * (drho_ref[k] - drho)
            fmu.set(F, Fk)
            fmu.set_derivatives(F, dF)
            fmu.do_step(t[k], step)
    rng = np.random.default_rng(seed)
    F_meas = F_applied + rng.standard_normal(F_applied.shape) * force_noise * np.sqrt(np.mean(F_applied ** 2, axis=0))
    rho_meas = np.round(rho_true / quantum) * quantum if quantum > 0 else rho_true.copy()
    return DriveLog(t, rho_meas, F_meas, rho_true, F_applied, pose, vel, acc)
