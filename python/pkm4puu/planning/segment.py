# SPDX-License-Identifier: BSD-2-Clause
"""One rest-to-rest traversal of a path, time-optimal within the limits:
plan_segment plans it (topp) and samples it; Segment holds the plan, its
samples (pose, rates, forces, slider rates) and which limit is active where.

Friction is not of the form a sdd + b sd^2 + c (it goes with sign(drho) and
drho, not sd^2), so the plan keeps the friction-free forces within the
force limit less a bound on friction, abs(F_fric,i) <= b v_lim + F_c (b
friction_viscous, F_c friction_coulomb, v_lim the speed limit), and the
samples are then checked with friction (the C API's inverse dynamics).
The screw lead and the friction are the model's (the C API's parameters,
given by the FMUs' names in `machine` or `params`). With friction off, the
default, nothing is taken off.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from .. import extras
from .capi_adapter import InverseDynamics, PoseError
from .limits import BadValue, Infeasible, Limits, OutsideWorkspace, PlanningError, SingularPath, check_value

GRID = 2000  # grid intervals per segment (docs/pick_and_place.md: the time's grid error)
DT = 1e-4  # s, the samples' spacing
ACTIVE_TOLERANCE = 1e-6  # a limit within this fraction of its value is active (toppra keeps ~1e-8 from it)
SAMPLE_TOLERANCE = 1e-3  # the samples may pass a limit by this fraction (the grid's interpolation error)


def shown_s(path, s):
    """The s a message gives for this path's s: an Arch's own (A at 0, B at 1)."""
    return float(path.arch_s(s) if hasattr(path, "arch_s") else s)


def where(path, s):
    """'s = ... (x = ... mm, y, z, phi = ... deg)' at this path's s."""
    x, y, z, phi = path(np.array([s]))[0]
    return (f"s = {shown_s(path, s):.4f} (x = {1e3 * x:.2f} mm, y = {1e3 * y:.2f} mm, z = {1e3 * z:.2f} mm, "
            f"phi = {math.degrees(phi):.2f} deg)")


def dynamics(payload_mass, machine, params, build):
    """capi_adapter.InverseDynamics without friction (its screw_lead and
    friction: the model's as given); BadValue naming a parameter the C API
    refuses."""
    try:
        return InverseDynamics(payload_mass, machine, params, build, frictionless=True)
    except ValueError as e:
        raise BadValue(str(e)) from None


def speed_bound(speed_limit, drho_ds):
    """x_max, the slider-speed limit on sd^2 at each grid point:
    speed_limit^2 / max_i (drho_i/ds)^2 (inf where no slider moves)."""
    den = (drho_ds ** 2).max(axis=1)
    with np.errstate(divide="ignore"):
        return np.where(den > 0, speed_limit ** 2 / den, np.inf)


def grid_points(grid):
    """The grid's points s_i, grid + 1 of them over [0, 1]; BadValue unless grid is an integer >= 2."""
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 2:
        raise BadValue(f"grid = {grid!r} must be an integer >= 2")
    return np.linspace(0.0, 1.0, int(grid) + 1)


def check_path(path, s, machine=None, params=None, build=None, name="the path"):
    """OutsideWorkspace or SingularPath at the first pose of path(s) the C
    API's guards refuse, saying where, which leg and why."""
    with dynamics(0.0, machine, params, build) as dyn:
        try:
            dyn.check_poses(path(s))
        except PoseError as e:
            what = {"unreachable": "leaves the workspace", "end stop": "leaves the sliders' travel",
                    "singular": "crosses a singularity"}.get(e.kind, "is refused by the C API")
            leg = f" (leg {e.leg})" if e.leg else ""
            cls = SingularPath if e.kind == "singular" else OutsideWorkspace
            raise cls(f"{name} {what} at {where(path, s[e.index])}{leg}: {e}") from None


@dataclass
class Segment:
    """A planned traversal. Grid (N + 1 points s, N intervals): x = sd^2,
    u = sdd (constant on each interval), t_grid; a, b, c (F = a sdd + b sd^2
    + c, friction-free), drho_ds and the bound x_max (speed_bound) at the
    grid points. Samples every dt (and at the end): t, pose, velocity,
    acceleration (each (n, 4)), F (friction included), rho, drho. SI units."""
    name: str
    payload_mass: float
    path: object
    force_limit: float
    force_limit_source: str
    speed_limit: float
    speed_limit_source: str
    friction_bound: float
    s: np.ndarray
    x: np.ndarray
    u: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    drho_ds: np.ndarray
    x_max: np.ndarray
    t: np.ndarray = field(default=None, repr=False)
    pose: np.ndarray = field(default=None, repr=False)
    velocity: np.ndarray = field(default=None, repr=False)
    acceleration: np.ndarray = field(default=None, repr=False)
    F: np.ndarray = field(default=None, repr=False)
    rho: np.ndarray = field(default=None, repr=False)
    drho: np.ndarray = field(default=None, repr=False)

    @property
    def sd(self):
        return np.sqrt(self.x)

    @property
    def t_grid(self):
        """The time at each grid point (constant sdd on an interval: its
        duration is 2 ds / (sd_i + sd_{i+1}))."""
        sd = self.sd
        return np.concatenate([[0.0], np.cumsum(2.0 * np.diff(self.s) / (sd[:-1] + sd[1:]))])

    @property
    def duration(self):
        return float(self.t_grid[-1])

    def at(self, t):
        """(s, sd, sdd, pose, velocity, acceleration) at the times t (an
        array within [0, duration]): the exact motion of the plan, sdd
        constant on each grid interval."""
        t = np.asarray(t, dtype=float)
        tg = self.t_grid
        i = np.clip(np.searchsorted(tg, t, side="right") - 1, 0, len(self.u) - 1)
        tau = t - tg[i]
        sd0 = self.sd[i]
        sdd = self.u[i]
        s = np.minimum(self.s[i] + sd0 * tau + 0.5 * sdd * tau ** 2, self.s[-1])
        sd = np.maximum(sd0 + sdd * tau, 0.0)
        d1, d2 = self.path(s, 1), self.path(s, 2)
        return (s, sd, sdd, self.path(s, 0), d1 * sd[:, None],
                d1 * sdd[:, None] + d2 * (sd ** 2)[:, None])

    def grid_forces(self):
        """F (friction-free) at each interval's start and end, with that
        interval's sdd: (N, 4) twice."""
        u = self.u[:, None]
        start = self.a[:-1] * u + self.b[:-1] * self.x[:-1, None] + self.c[:-1]
        end = self.a[1:] * u + self.b[1:] * self.x[1:, None] + self.c[1:]
        return start, end

    def activity(self):
        """Per interval, the largest use of the force limit (abs(F_i) over the
        limit less the friction bound) and of the speed limit (x over x_max)
        at its two ends."""
        start, end = self.grid_forces()
        f = np.maximum(np.abs(start).max(axis=1), np.abs(end).max(axis=1)) / (self.force_limit - self.friction_bound)
        xm = self.x_max
        with np.errstate(invalid="ignore"):
            v = np.nan_to_num(np.maximum(self.x[:-1] / xm[:-1], self.x[1:] / xm[1:]))
        return f, v

    def active(self, tolerance=ACTIVE_TOLERANCE):
        """Per interval, which limit is active: "force", "speed", "force+speed",
        or "" (neither: the interval where sdd switches from its largest to
        its smallest value, which the grid cannot place exactly)."""
        f, v = self.activity()
        fa, va = f >= 1 - tolerance, v >= 1 - tolerance
        return np.where(fa & va, "force+speed", np.where(fa, "force", np.where(va, "speed", "")))

    def active_share(self, tolerance=ACTIVE_TOLERANCE):
        """{"force": ..., "speed": ..., "": ...}: the fraction of the duration
        with each limit active (force+speed counts for both)."""
        dt = np.diff(self.t_grid)
        act = self.active(tolerance)
        T = dt.sum()
        return {"force": dt[np.char.find(act, "force") >= 0].sum() / T,
                "speed": dt[np.char.find(act, "speed") >= 0].sum() / T, "": dt[act == ""].sum() / T}

    def active_summary(self):
        """'force 62 %, speed 36 %': the time share of each active limit."""
        share = self.active_share()
        parts = [f"{k} {100 * share[k]:.0f} %" for k in ("force", "speed") if share[k] >= 0.005]
        return ", ".join(parts) or "none"

    def excess(self):
        """(max abs(F_i) / force limit, max abs(drho_i) / speed limit) over the samples."""
        return (float(np.abs(self.F).max() / self.force_limit), float(np.abs(self.drho).max() / self.speed_limit))


def plan_segment(path, payload_mass=0.0, limits=None, machine=None, params=None, grid=GRID, dt=DT, name="the path",
                 build=None, check_workspace=True):
    """The fastest rest-to-rest traversal of `path` (p(s), s in [0, 1]; see
    paths.Arch) carrying `payload_mass` kg at P, within `limits` (a
    limits.Limits), for the model's parameters `machine` and `params` (both
    by the FMUs' names, e.g. rotor_inertia, screw_lead, friction_viscous, g;
    `machine` where both give one), on `grid` intervals of s, sampled every
    `dt` s. PlanningError (its subclasses) when it cannot be planned, saying
    why and where; extras.MissingExtra without toppra (the extra
    `planning`)."""
    extras.require("pkm4puu.plan_cycle", "toppra")
    from . import topp  # toppra's classes at its module level
    limits = limits or Limits()
    payload_mass = check_value("payload_mass", payload_mass, unit=" kg")
    s = grid_points(grid)
    dt = check_value("dt", dt, strict=True, unit=" s")
    if not np.any(path(s, 1)):
        raise BadValue(f"{name} does not move: its start and end poses coincide and nothing between differs")
    if check_workspace:
        check_path(path, s, machine, params, build, name)
    with dynamics(payload_mass, machine, params, build) as dyn:
        f_lim, f_src = limits.force(dyn.screw_lead)
        v_lim, v_src = limits.speed(dyn.screw_lead)
        viscous, coulomb = dyn.friction
        friction = viscous * v_lim + coulomb
        f_eff = f_lim - friction
        if f_eff <= 0:
            raise Infeasible(f"{f_src} leaves nothing once friction is allowed for "
                             f"(|F_fric| <= b v_lim + F_c = {friction:.4g} N)", "friction takes the whole force limit")
        a, b, c, drho_ds = topp.path_coefficients(dyn, path, s)
    need = np.abs(c) - f_eff
    k, i = np.unravel_index(np.argmax(need), need.shape)
    if need[k, i] >= 0:
        less = f" less the friction bound {friction:.4g} N" if friction else ""
        raise Infeasible(f"{name}: holding the {payload_mass:g} kg payload at rest at {where(path, s[k])} needs "
                         f"F[{i + 1}] = {c[k, i]:.4g} N, beyond {f_src}{less}",
                         f"F[{i + 1}] = {c[k, i]:.3g} N to hold at s = {shown_s(path, s[k]):.2f}")
    x_max = speed_bound(v_lim, drho_ds)
    try:
        x, u = topp.solve(s, a, b, c, f_eff, x_max)
    except topp.NoTraversal as e:
        raise Infeasible(f"{name}: no rest-to-rest traversal within {f_src} and {v_src} (toppra: {e})",
                         "no traversal found") from None
    seg = Segment(name, payload_mass, path, f_lim, f_src, v_lim, v_src, friction, s, x, u, a, b, c, drho_ds,
                  x_max)
    sample(seg, dt, machine, params, build)
    return seg


def sample_times(T, dt):
    """0, dt, 2 dt, ... up to T, and T itself."""
    n = int(math.floor(T / dt + 1e-9))
    return np.append(np.arange(n + 1) * dt, T) if n * dt < T * (1 - 1e-12) else np.arange(n + 1) * dt


def sample(seg, dt, machine=None, params=None, build=None):
    """Fills seg's samples every dt s (and at its end): the motion, the
    forces with friction and the slider rates from the C API, and checks
    them against the limits."""
    t = sample_times(seg.duration, dt)
    _, _, _, pose, vel, acc = seg.at(t)
    with InverseDynamics(seg.payload_mass, machine, params, build) as dyn:
        F, rho, drho = dyn.forces_and_rates(pose, vel, acc)
    seg.t, seg.pose, seg.velocity, seg.acceleration, seg.F, seg.rho, seg.drho = t, pose, vel, acc, F, rho, drho
    f, v = seg.excess()
    if f > 1 + SAMPLE_TOLERANCE or v > 1 + SAMPLE_TOLERANCE:
        raise PlanningError(f"{seg.name}: the planned motion exceeds its limits between the grid points "
                            f"(max |F| = {f * seg.force_limit:.5g} N against {seg.force_limit:g} N, max |drho| = "
                            f"{v * seg.speed_limit:.5g} m/s against {seg.speed_limit:g} m/s): refine the grid")
