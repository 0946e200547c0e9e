# SPDX-License-Identifier: BSD-2-Clause
"""The plant FMU in a sampled control loop: the errors against the desired
pose, the loop itself (closed_loop) and its run along the auto-test with
the inverse FMU as the reference (run_closed_loop: examples/
closed_loop_control.py's joint PD, linearize_lqr.py's LQR; ssp_cosim.py's
libcosim run uses the errors; the pick-and-place cycle's loop,
pkm4puu.planning.tracking, the plan as the reference)."""
from dataclasses import dataclass

import numpy as np

from .fmu import Fmu
from .interface import ACC, DRHO, F, POSE, RHO, RUN_COLUMNS, VEL
from .motions import motion
from .spec import STEP as H, T_MOVE


class PoseErrors:
    """For a run with the plant's `pose` and the prescribed `pose_d` (n, 4):
    ``pos_err`` = ‖(x, y, z) − prescribed‖ (m) and ``phi_err`` = abs(phi − prescribed)
    (rad) at each time, as pkm4puu.cli.autotest measures them."""

    @property
    def pos_err(self):
        return np.linalg.norm(self.pose[:, :3] - self.pose_d[:, :3], axis=1)

    @property
    def phi_err(self):
        return np.abs(self.pose[:, 3] - self.pose_d[:, 3])


@dataclass
class LoopResult(PoseErrors):
    """One closed-loop run: times t (n,), the desired and measured actuator
    positions rho_d, rho and rates drho_d, drho (n, 4) (m, m/s), the desired
    and actual pose and their rates (n, 4), the applied forces F and the feed-forward part
    F_ff (n, 4) (N; F is the force held over the step starting at t, the last
    row repeats the one before), and the plant's run (t, RUN_COLUMNS) for
    render_robot.py."""
    t: np.ndarray
    rho_d: np.ndarray
    rho: np.ndarray
    drho_d: np.ndarray
    drho: np.ndarray
    pose_d: np.ndarray
    pose: np.ndarray
    dpose_d: np.ndarray
    dpose: np.ndarray
    F: np.ndarray
    F_ff: np.ndarray
    run: np.ndarray

    @property
    def e_rho(self):
        return self.rho_d - self.rho

    @property
    def de_rho(self):
        return self.drho_d - self.drho

    @property
    def F_pd(self):
        """The PD's part of the applied force (N)."""
        return self.F - self.F_ff

    @property
    def rms(self):
        """RMS of the actuator position errors over time and the 4 actuators (m)."""
        return float(np.sqrt(np.mean(self.e_rho ** 2)))


def run_closed_loop(plant_fmu, inverse_fmu, plant_start, model, control, progress, t_end, T=T_MOVE, h=H,
                    log=None, name="closed loop"):
    """The loop sampled at h for t_end seconds: at each t_k the plant's
    outputs are read, the inverse FMU (start values `model`) gives the
    reference along motion(t_k, T): F_ref, rho_d, drho_d; then
    control(r, k, F_ref) -> (F_ff, F) gives the feed-forward part and the
    force held over the step, r the LoopResult filled up to row k. The plant
    starts from `plant_start` (its start values). Every 500 steps
    log("  <name>: t = ..., <progress(r, k)>"). Raises when the plant's
    outputs are not finite."""
    n = round(t_end / h)
    with Fmu(plant_fmu, start=plant_start, instance_name="plant") as plant, \
            Fmu(inverse_fmu, start=model, instance_name="feed_forward") as inv:
        vr_motion = inv.vrs(POSE + VEL + ACC)
        vr_ref = inv.vrs(F + RHO + DRHO)

        def reference(r, k):
            m = motion(r.t[k], T)
            inv.fmu.setReal(vr_motion, m)
            ref = np.array(inv.fmu.getReal(vr_ref))
            r.pose_d[k], r.dpose_d[k], r.rho_d[k], r.drho_d[k] = m[:4], m[4:8], ref[4:8], ref[8:12]
            return ref[:4]

        return closed_loop(plant, np.arange(n + 1) * h, reference, control, progress, log, name, h=h)


def closed_loop(plant, t, reference, control, progress=None, log=None, name="closed loop", at_sample=None, h=None):
    """The loop of an initialised plant (an Fmu, FMI 2.0) over the sample
    times t (n + 1,): at each t_k the plant's outputs are read into the
    LoopResult r, at_sample(r, k) if given (a change of the plant's tunable
    parameters, say), reference(r, k) fills the desired pose, rho and their
    rates at t_k and returns F_ref; then control(r, k, F_ref) -> (F_ff, F)
    gives the feed-forward part and the force held over [t_k, t_k+1], and
    the plant steps there (by h when the samples are uniform, else by
    t_k+1 - t_k). Every 500 steps log("  <name>: t = ..., <progress(r, k)>").
    Raises when the plant's outputs are not finite."""
    n = len(t) - 1
    r = LoopResult(t, *(np.empty((n + 1, 4)) for _ in range(8)), np.zeros((n + 1, 4)), np.zeros((n + 1, 4)),
                   np.empty((n + 1, len(RUN_COLUMNS))))
    vr_sense = plant.vrs(RUN_COLUMNS + DRHO + VEL)  # pose, rho, theta1, theta2, drho, dpose
    vr_F = plant.vrs(F)
    for k in range(n + 1):
        y = np.array(plant.fmu.getReal(vr_sense))
        r.run[k], r.pose[k], r.rho[k], r.drho[k], r.dpose[k] = y[:16], y[:4], y[4:8], y[16:20], y[20:24]
        if at_sample:
            at_sample(r, k)
        F_ref = reference(r, k)
        if k == n:
            break
        r.F_ff[k], r.F[k] = control(r, k, F_ref)
        plant.fmu.setReal(vr_F, list(r.F[k]))
        plant.do_step(t[k], h or t[k + 1] - t[k])
        if log and (k + 1) % 500 == 0:
            log(f"  {name}: t = {t[k + 1]:.2f} s, {progress(r, k)}")
    r.F[n], r.F_ff[n] = r.F[n - 1], r.F_ff[n - 1]
    if not (np.all(np.isfinite(r.rho)) and np.all(np.isfinite(r.pose))):
        raise RuntimeError(f"{name}: the plant's outputs are not finite")
    return r
