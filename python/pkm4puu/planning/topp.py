# SPDX-License-Identifier: BSD-2-Clause
"""The time-optimal path parametrisation (TOPP-RA, the toppra package) of a
platform path under the actuator-force and slider-speed limits.

Along a path p(s) the platform's velocity is p' sd and its acceleration
p' sdd + p'' sd^2 (sd = ds/dt, sdd = d^2s/dt^2), so the inverse dynamics
F(p, v, a) = M(p) a + h(p, v) + g(p), with h quadratic in v, becomes

    F(s) = a(s) sdd + b(s) sd^2 + c(s)              (second order in s)
    a = F(p, 0, p') - c,  b = F(p, p', p'') - c,  c = F(p, 0, 0),

three calls of the inverse dynamics per grid point. The slider rates are
drho/dt = (drho/ds) sd, so abs(drho_i/dt) <= v_max is the first-order bound
sd^2 <= v_max^2 / max_i (drho_i/ds)^2. toppra's variables are x = sd^2 and
u = sdd, constant on each grid interval (x_{i+1} = x_i + 2 ds_i u_i); the
force bound is imposed at both ends of every interval (toppra's
interpolation discretisation), so the plan keeps it between the grid
points to second order in the grid step.
"""
import logging

import numpy as np

from toppra import algorithm
from toppra.constraint import DiscretizationType, LinearConstraint, canlinear_colloc_to_interpolate
from toppra.interpolator import AbstractGeometricPath

logging.getLogger("toppra").setLevel(logging.ERROR)  # its failures are reported by the caller

SCALE = 100.0  # the order of toppra's x = sd^2 and u = sdd in its rescaled time


def path_coefficients(dynamics, path, s):
    """(a, b, c, drho_ds), each (len(s), 4): F = a sdd + b sd^2 + c and the
    slider rates per unit of sd, from the inverse dynamics (`dynamics`: a
    capi_adapter.InverseDynamics without friction)."""
    p, d1, d2 = path(s, 0), path(s, 1), path(s, 2)
    zero = np.zeros_like(p)
    c = dynamics.forces(p, zero, zero)
    a = dynamics.forces(p, zero, d1) - c
    F, _, drho_ds = dynamics.forces_and_rates(p, d1, d2)
    return a, F - c, c, drho_ds


class _ForceBound(LinearConstraint):
    """abs(a_i u + b_i x + c_i) <= limit for each actuator i (toppra's canonical
    linear form a u + b x + c = v, F v <= g), at both ends of each interval."""

    def __init__(self, a, b, c, limit):
        super().__init__()
        self.abc, self.limit = (a, b, c), limit
        self.discretization_type = DiscretizationType.Interpolation

    def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
        a, b, c = self.abc
        n = len(gridpoints)
        F = np.broadcast_to(np.vstack([np.eye(4), -np.eye(4)]), (n, 8, 4))
        g = np.full((n, 8), self.limit)
        a_i, b_i, c_i, F_i, g_i, _, _ = canlinear_colloc_to_interpolate(a, b, c, F, g, None, None, gridpoints)
        return a_i, b_i, c_i, F_i, g_i, None, None


class _SpeedBound(LinearConstraint):
    """0 <= x <= x_max (the slider-speed limit on sd^2)."""

    def __init__(self, x_max):
        super().__init__()
        self.x_max = x_max

    def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
        return None, None, None, None, None, None, np.column_stack([np.zeros(len(gridpoints)), self.x_max])


class _Grid(AbstractGeometricPath):
    """toppra's path argument; the constraints hold their own coefficients."""

    def __init__(self, s):
        self._interval = np.array([s[0], s[-1]])

    def __call__(self, path_positions, order=0):
        raise NotImplementedError("the constraints are given on the grid")

    @property
    def dof(self):
        return 4

    @property
    def path_interval(self):
        return self._interval


class NoTraversal(RuntimeError):
    """toppra found no rest-to-rest traversal within the limits."""


def solve(s, a, b, c, force_limit, x_max):
    """The fastest rest-to-rest traversal: x = sd^2 at the grid points (N+1)
    and u = sdd on the intervals (N), with abs(F_i) <= force_limit and
    sd^2 <= x_max (inf where no slider moves, where toppra, which needs a
    finite bound, gets one far above the others). Time is rescaled for
    toppra so that its variables are of order SCALE: its forward pass steps
    each x back by an absolute 1e-8 (to stay within the controllable sets),
    which is then 1e-10 of x."""
    finite = x_max[np.isfinite(x_max)]
    x_max = np.minimum(x_max, 1e6 * finite.max() if finite.size else 1e12)
    with np.errstate(divide="ignore"):
        u_scale = np.median(force_limit / np.abs(a).max(axis=1))
    k2 = min(np.median(x_max), u_scale if np.isfinite(u_scale) else np.inf) / SCALE
    if not (np.isfinite(k2) and k2 > 0):
        k2 = 1.0
    # t' = t sqrt(k2): x' = x / k2, u' = u / k2, F = (a k2) u' + (b k2) x' + c
    problem = algorithm.TOPPRA([_ForceBound(a * k2, b * k2, c, force_limit), _SpeedBound(x_max / k2)], _Grid(s),
                               gridpoints=s, solver_wrapper="seidel")
    _, sd, _ = problem.compute_parameterization(0.0, 0.0)
    if sd is None or not np.all(np.isfinite(sd)):
        raise NoTraversal(str(problem.problem_data.return_code))
    x = np.maximum(k2 * np.asarray(sd, dtype=float) ** 2, 0.0)
    x[0] = x[-1] = 0.0
    u = np.diff(x) / (2.0 * np.diff(s))  # consistent with x by construction
    return x, u
