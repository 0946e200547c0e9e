# SPDX-License-Identifier: BSD-2-Clause
"""The planned cycle run closed-loop through the plant FMU
(docs/pick_and_place.md, "The cycle in closed loop"): track_cycle.

The plant FMU (FMI 2.0 Co-Simulation, RK4 inside, one step per sample) is
stepped every 0.1 ms (and at each leg's end); over each sample interval
[t_k, t_k+1] the drives hold

    F = F_ff + M_rho (w^2 (rho_d - rho) + 2 zeta w (drho_d - drho))

- F_ff: the planned forces, the C API's inverse dynamics along the plan
  (payload included) at the interval's midpoint, so that the held force's
  impulse over the interval is the plan's to second order in its length;
- rho_d, drho_d: the plan's slider positions and rates at t_k (the
  closed-form inverse kinematics of the planned pose); rho, drho: the
  plant's outputs at t_k, the drives' encoders;
- M_rho = J^-T M J^-1: the joint-space inertia at the planned pose (J the
  actuator Jacobian, M the platform's reduced mass matrix, the payload
  included), from the inverse dynamics at rest.

A PD on the sliders' errors, because the sliders are what the drives move
and measure, and the feed-forward already carries the coupled dynamics
(inertia, gravity, the payload): the feedback only corrects what the
sampling leaves (the held forces' error, the jumps of the planned forces
between grid intervals). Its gain is the joint-space inertia rather than a
number per slider because that inertia is far from diagonal and badly
conditioned on this path (eigen-masses from about 0.2 kg to 30 kg: a turn
of the platform is heavy through the actuator Jacobian): with M_rho as the
gain every direction of the sliders' error is one critically damped pair
at f_c (the computed-force law's outer loop), where a scalar gain would be
a dozen times too fast in one direction or too slow in another. f_c = 50 Hz,
zeta = 1: at 10 kHz w h = 0.03, so the zero-order hold's lag (w h / 2,
under a degree) leaves the continuous design as it is, and an error of
1 um costs at most 30 kg w^2 1 um = 3 N of feedback.

The payload is grasped at A (t = 0) and released at B (the end of
A -> B) through the plant's tunable payload_mass, between two steps.
"""
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import interface
from ..closed_loop import closed_loop
from .capi_adapter import InverseDynamics, model_parameters
from .segment import sample_times

BANDWIDTH = 50.0  # Hz, the feedback's
LOOP_STEP = 1e-4  # s: the loop's sampling, 10 kHz
TRACKING_BOUND = 1e-4  # m: |p - p_ref| of P in closed loop
ENERGY = ["kinetic_energy", "potential_energy", "actuator_work", "dissipated_energy"]
# The columns of closed_loop.csv, in order (SI units).
COLUMNS = (["t"] + interface.POSE + [f"{name}_ref" for name in interface.POSE] + interface.F
           + interface.indexed_names("F_ff", 4) + ["payload_mass"] + ENERGY)


@dataclass(frozen=True)
class Gains:
    """The feedback's bandwidth f_c (Hz) and damping ratio, and the range of
    the joint-space inertia's eigen-masses along the plan (kg), for the record."""
    f_c: float
    zeta: float
    masses: tuple = (math.nan, math.nan)

    @property
    def w(self):
        return 2 * math.pi * self.f_c

    def describe(self):
        return (f"K_p = w^2 M_rho, K_d = 2 zeta w M_rho (f_c = {self.f_c:g} Hz, zeta = {self.zeta:g}; M_rho's "
                f"eigen-masses {self.masses[0]:.3g} to {self.masses[1]:.3g} kg)")


def slider_inertias(dyn, poses):
    """The joint-space inertia J^-T M J^-1 (n, 4, 4; kg) at each of `poses`
    (n, 4) at rest, from the inverse dynamics: its column i is
    F(p, 0, a_i) - F(p, 0, 0) with a_i the pose acceleration that moves
    slider i alone (J a_i = e_i; J's columns are the slider rates of unit
    pose rates)."""
    poses = np.asarray(poses, dtype=float).reshape(-1, 4)
    n = len(poses)
    P = np.repeat(poses, 4, axis=0)
    zero = np.zeros_like(P)
    _, _, rates = dyn.forces_and_rates(P, np.tile(np.eye(4), (n, 1)), zero)
    J = rates.reshape(n, 4, 4).transpose(0, 2, 1)
    c = dyn.forces(poses, np.zeros_like(poses), np.zeros_like(poses))
    a = np.linalg.inv(J).transpose(0, 2, 1).reshape(-1, 4)
    F = dyn.forces(P, zero, a).reshape(n, 4, 4)
    return (F - c[:, None, :]).transpose(0, 2, 1)


@dataclass
class Tracking:
    """A closed-loop run of the cycle: the loop (closed_loop.LoopResult:
    t, pose, pose_d, rho, F, F_ff, ...), the payload held over each step
    from t_k (kg), the plant's energy outputs at each t_k before any change
    there (n + 1, 4: ENERGY's order), the grasp's and release's booked work
    [(t, J)], the gains, the plan and its force limit."""
    loop: object
    payload: np.ndarray
    energy: np.ndarray
    booked: list
    gains: Gains
    cycle: object
    phi_bound: float

    @property
    def t(self):
        return self.loop.t

    def samples(self):
        """closed_loop.csv's rows (COLUMNS)."""
        r = self.loop
        return np.column_stack([r.t, r.pose, r.pose_d, r.F, r.F_ff, self.payload, self.energy])

    def drive_work(self):
        """The actuator_work increments over each step (J): the drives'
        work, the grasps' booked work left out."""
        return np.diff(self.energy[:, 2]) - self._booked_per_step()

    def _booked_per_step(self):
        out = np.zeros(len(self.t) - 1)
        for t, work in self.booked:
            k = int(np.searchsorted(self.t, t))
            if k < len(out):
                out[k] += work
        return out

    def audit(self):
        """kinetic + potential - actuator_work + dissipated at each t_k (J)."""
        K, P, W, D = self.energy.T
        return K + P - W + D

    def summary(self):
        r, g = self.loop, self.gains
        f_max = self.cycle.segments[0].force_limit
        dt = np.diff(r.t)
        seg = self.cycle.segments[0]
        feedback = np.abs(r.F_pd[:-1]).max()
        peak = np.abs(r.F[:-1]).max()
        work = self.drive_work()
        audit = self.audit()
        grasps = ", ".join(f"{w:+.4f} J at t = {t:.4f} s" for t, w in self.booked)
        return [
            f"closed loop through PKM4PUU.fmu at {1e-3 / dt.max():.4g} kHz (RK4 inside, one step per sample): the "
            f"planned forces as feed-forward and a PD on the sliders' errors",
            f"  gains: {g.describe()}",
            f"  payload: {seg.payload_mass:g} kg grasped at A (t = 0) and released at B (t = {seg.duration:.4f} s) "
            f"through the plant's payload_mass",
            f"  tracking: max |p - p_ref| = {1e6 * r.pos_err.max():.3f} um (bound {1e6 * TRACKING_BOUND:g} um), "
            f"max |phi - phi_ref| = {1e6 * r.phi_err.max():.3f} urad (bound {1e6 * self.phi_bound:.4g} urad, "
            f"{1e3 * TRACKING_BOUND:g} mm at r_Q)",
            f"  forces: peak |F| = {peak:.4f} N against f_max = {f_max:g} N (the plan's peak "
            f"{np.abs(r.F_ff[:-1]).max():.4f} N, the feedback's {feedback:.4f} N): the drives need "
            f"{100 * max(peak - f_max, 0.0) / f_max:.2f} % headroom above the plan's limit",
            f"  energy per cycle (the plant's actuator_work): the drives' net work {work.sum():+.6f} J, "
            f"{work[work > 0].sum():.4f} J delivered and {-work[work < 0].sum():.4f} J taken back, peak power "
            f"{np.abs(work / dt).max():.3f} W; booked: {grasps}; audit residual "
            f"{audit[-1] - audit[0]:+.2e} J"]


def track_cycle(cycle, plant_fmu=None, step=LOOP_STEP, f_c=BANDWIDTH, zeta=1.0, build=None, log=None):
    """The planned cycle (planning.plan_cycle's Cycle) through the plant FMU
    (PKM4PUU.fmu, FMI 2.0; found with fmu.find_fmu when not given) in closed
    loop, as the module says, sampled every `step` s (and at each leg's
    end). Returns a Tracking; RuntimeError when the plant FMU refuses a step."""
    from fmpy.fmi1 import FMICallException

    from ..fmu import Fmu, find_fmu
    plant_fmu = plant_fmu or find_fmu("PKM4PUU", 2, build)
    there, back = cycle.segments
    legs = [plan_terms(seg, sample_times(seg.duration, step), cycle, build) for seg in cycle.segments]
    k_release = len(legs[0].t) - 1
    t = np.concatenate([legs[0].t, there.duration + legs[1].t[1:]])

    def joined(name):  # the release's sample: A -> B's reference, the empty machine's inertia
        first, second = getattr(legs[0], name), getattr(legs[1], name)
        return np.concatenate([first[:-1], second] if name == "inertia" else [first, second[1:]])

    pose_d, vel_d, rho_d, drho_d, M_rho = (joined(n) for n in ("pose", "velocity", "rho", "drho", "inertia"))
    F_ff = np.vstack([leg.F_ff for leg in legs])
    payload = np.where(np.arange(len(t)) < k_release, there.payload_mass, back.payload_mass)
    masses = np.linalg.eigvalsh(0.5 * (M_rho + M_rho.transpose(0, 2, 1)))
    gains = Gains(f_c, zeta, (float(masses.min()), float(masses.max())))
    kp, kd = gains.w ** 2, 2 * zeta * gains.w
    start = {**model_parameters(cycle.machine, cycle.params), **interface.RK4, "rk4_step": float(np.diff(t).max()),
             **interface.start_pose(there.pose[0])}
    energy = np.empty((len(t), len(ENERGY)))
    booked = []
    grasps = {0: there.payload_mass, k_release: back.payload_mass}

    def reference(r, k):
        r.pose_d[k], r.dpose_d[k], r.rho_d[k], r.drho_d[k] = pose_d[k], vel_d[k], rho_d[k], drho_d[k]
        return F_ff[min(k, len(F_ff) - 1)]

    def control(r, k, F_ref):
        return F_ref, F_ref + M_rho[k] @ (kp * (r.rho_d[k] - r.rho[k]) + kd * (r.drho_d[k] - r.drho[k]))

    def progress(r, k):
        return f"|p - p_ref| = {1e6 * np.linalg.norm(r.pose[k, :3] - r.pose_d[k, :3]):.3f} um"

    with Fmu(plant_fmu, start=start, instance_name="plant") as plant:
        vr_energy = plant.vrs(ENERGY)
        vr_payload = plant.vrs(["payload_mass"])
        phi_bound = TRACKING_BOUND / float(plant.get(["r_Q"])[0])  # the plant's r_Q, from either dict

        def at_sample(r, k):
            energy[k] = plant.fmu.getReal(vr_energy)
            if k in grasps:
                plant.fmu.setReal(vr_payload, [float(grasps[k])])
                booked.append((float(t[k]), plant.fmu.getReal(vr_energy)[2] - energy[k, 2]))

        try:
            loop = closed_loop(plant, t, reference, control, progress, log, "closed loop", at_sample)
        except FMICallException as e:
            raise RuntimeError(f"the closed loop through {Path(plant_fmu).name} stopped: {e}") from None
    return Tracking(loop, payload, energy, booked, gains, cycle, phi_bound)


@dataclass
class LegTerms:
    """What the loop takes from a planned leg at its sample times t: the
    planned pose, velocity, slider positions and rates, the joint-space
    inertia (each at t) and the feed-forward forces (at the midpoints)."""
    t: np.ndarray
    pose: np.ndarray
    velocity: np.ndarray
    rho: np.ndarray
    drho: np.ndarray
    inertia: np.ndarray
    F_ff: np.ndarray


def plan_terms(seg, t, cycle, build=None):
    """LegTerms of a planned leg at the times t (within [0, seg.duration]):
    the C API's inverse dynamics, payload and machine included, along the
    plan's exact motion (Segment.at)."""
    _, _, _, pose, vel, acc = seg.at(t)
    _, _, _, pose_m, vel_m, acc_m = seg.at(0.5 * (t[:-1] + t[1:]))
    with InverseDynamics(seg.payload_mass, cycle.machine, cycle.params, build) as dyn:
        _, rho, drho = dyn.forces_and_rates(pose, vel, acc)
        return LegTerms(t, pose, vel, rho, drho, slider_inertias(dyn, pose), dyn.forces(pose_m, vel_m, acc_m))
