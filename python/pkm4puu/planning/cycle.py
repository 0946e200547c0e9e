# SPDX-License-Identifier: BSD-2-Clause
"""The pick-and-place cycle: the arch from A to B carrying the payload, then
back from B to A empty, each leg rest to rest and time-optimal, no dwell
(docs/pick_and_place.md; the standard cycle's numbers are spec.CYCLE_*)."""
from dataclasses import dataclass
from typing import List, Optional

import numpy as np

from .. import interface, spec
from .limits import Limits, check_value
from .paths import Arch
from .segment import DT, GRID, Segment, check_path, grid_points, plan_segment

# The columns of cycle.csv, in order (SI units).
COLUMNS = ["t"] + interface.POSE + interface.VEL + interface.ACC + interface.F + ["payload_mass"]


@dataclass
class Cycle:
    """The planned cycle: segments[0] is A -> B with the payload,
    segments[1] B -> A without; each segment's time starts at 0. machine
    and params: the machine it was planned for (plan_cycle's)."""
    arch: Arch
    limits: Limits
    segments: List[Segment]
    machine: Optional[dict] = None
    params: Optional[dict] = None

    @property
    def duration(self):
        """The cycle time (s): the sum of the two traversals."""
        return sum(seg.duration for seg in self.segments)

    def samples(self):
        """The whole cycle as one (n, len(COLUMNS)) array in COLUMNS' order,
        the segments one after the other on one time axis. The instant the
        payload is released at B appears twice: as the last sample of A -> B
        (with the payload) and the first of B -> A (without), at rest both
        times but with different forces."""
        rows, t0 = [], 0.0
        for seg in self.segments:
            rows.append(np.column_stack([t0 + seg.t, seg.pose, seg.velocity, seg.acceleration, seg.F,
                                         np.full(len(seg.t), seg.payload_mass)]))
            t0 += seg.duration
        return np.vstack(rows)

    def summary(self):
        """The lines a user reads: the cycle, the limits, each segment's time,
        active limits and peaks."""
        lines = [f"pick-and-place cycle: {self.arch.describe()}; payload {self.segments[0].payload_mass:g} kg "
                 f"A -> B, empty B -> A",
                 f"limits: |F_i| <= {self.segments[0].force_limit_source}, "
                 f"|drho_i/dt| <= {self.segments[0].speed_limit_source}"]
        for seg in self.segments:
            f, v = seg.excess()
            lines.append(f"  {seg.name}: {seg.duration:.4f} s (payload {seg.payload_mass:g} kg), active: "
                         f"{seg.active_summary()}; peak |F| {f * seg.force_limit:.3f} N, "
                         f"peak |drho/dt| {v * seg.speed_limit:.4f} m/s")
        lines.append(f"cycle time: {self.duration:.4f} s")
        return lines


def plan_cycle(payload=spec.CYCLE_PAYLOAD, f_max=spec.CYCLE_F_MAX, v_max=spec.CYCLE_V_MAX, a=spec.CYCLE_A,
               h=spec.CYCLE_H, z0=spec.CYCLE_Z0, theta=spec.CYCLE_THETA, *, torque_max=None, motor_speed_max=None,
               machine=None, params=None, grid=GRID, dt=DT, build=None):
    """The time-optimal pick-and-place cycle on the arch
    x = -a cos(pi s), y = 0, z = z0 + h sin(pi s), phi = -(theta/2) cos(pi s)
    (m, rad): `payload` kg carried from A (s = 0) to B (s = 1), back empty;
    abs(F_i) <= f_max (N), abs(drho_i/dt) <= v_max (m/s), optionally the motors'
    torque_max (N m) and motor_speed_max (rad/s) through the screw. The
    defaults are the standard cycle. machine and params: the model's
    parameters by the FMUs' names, either dict taking any of them (machine's
    where both give one), e.g. machine={"screw_lead": ..., "rotor_inertia":
    ..., "friction_viscous": ..., "friction_coulomb": ...}, params={"g": 0.0}.
    Returns a Cycle; PlanningError (its subclasses) says why and where when
    there is none."""
    payload = check_value("payload", payload, unit=" kg")
    path = arch(a, h, z0, theta)
    limits = Limits(f_max, v_max, torque_max, motor_speed_max)
    # the poses do not depend on the payload or the direction: checked once
    check_path(path, grid_points(grid), machine, params, build, "the arch")
    common = dict(limits=limits, machine=machine, params=params, grid=grid, dt=dt, build=build, check_workspace=False)
    there = plan_segment(path, payload, name="A -> B", **common)
    back = plan_segment(path.reversed(), 0.0, name="B -> A", **common)
    return Cycle(path, limits, [there, back], machine, params)


def arch(a=spec.CYCLE_A, h=spec.CYCLE_H, z0=spec.CYCLE_Z0, theta=spec.CYCLE_THETA):
    """The Arch from A to B; BadValue when a, h or theta is negative or any is not finite."""
    return Arch(check_value("a", a, unit=" m"), check_value("h", h, unit=" m"),
                check_value("z0", z0, minimum=None, unit=" m"), check_value("theta", theta, unit=" rad"))
