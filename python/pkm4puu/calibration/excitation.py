# SPDX-License-Identifier: BSD-2-Clause
"""An exciting trajectory for the identification: a finite Fourier series
per platform axis (x, y, z, phi), its coefficients optimised for the
condition number of the stacked base regressor within the workspace, the
end stops and the drives' force and speed limits (docs/calibration.md).

    traj = optimise_excitation(lib, period=2.5, harmonics=5)
    print(traj.condition)
    pose, vel, acc = traj.evaluate(t)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import capi, extras
from .parameters import base_parameters, make_plant

AXES = ("x", "y", "z", "phi")


@dataclass
class Limits:
    """Where and how hard the trajectory may go. xy: bound on ``abs(x)`` and
    ``abs(y)`` of P (m); z: (lowest, highest) z of P (m); phi: bound on
    ``abs(phi)`` (rad); stop_margin: distance kept from each end stop (m);
    speed: bound on ``abs(drho)`` (m/s) and force: on ``abs(F)`` (N) of each
    drive, the force with the nominal parameters."""
    xy: float = 0.010
    z: tuple = (0.045, 0.075)
    phi: float = 0.12
    stop_margin: float = 0.005
    speed: float = 0.15
    force: float = 25.0


@dataclass
class FourierTrajectory:
    """pose_a(t) = center_a + sum_k (a_ak sin(k w t) - b_ak cos(k w t)) / (k w),
    w = 2 pi / period: velocity sum_k a_ak cos + b_ak sin, periodic."""
    period: float
    a: np.ndarray                  # (4, harmonics)
    b: np.ndarray                  # (4, harmonics)
    center: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.06, 0.0]))
    condition: float = float("nan")  # of the stacked base regressor (unit-norm columns)
    start_condition: float = float("nan")  # the same at the optimisation's random start

    @property
    def harmonics(self):
        return self.a.shape[1]

    def evaluate(self, t):
        """pose, velocity, acceleration, each (len(t), 4)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        w = 2 * np.pi / self.period
        k = np.arange(1, self.harmonics + 1)
        kw = k * w
        s, c = np.sin(np.outer(t, kw)), np.cos(np.outer(t, kw))  # (n, K)
        pose = self.center + (s @ (self.a / kw).T - c @ (self.b / kw).T)
        vel = c @ self.a.T + s @ self.b.T
        acc = -s @ (self.a * kw).T + c @ (self.b * kw).T
        return pose, vel, acc

    def vector(self):
        return np.concatenate([self.a.ravel(), self.b.ravel()])

    @classmethod
    def from_vector(cls, x, period, harmonics, center):
        n = 4 * harmonics
        return cls(period, x[:n].reshape(4, harmonics), x[n:].reshape(4, harmonics), np.asarray(center, float))


class _Problem:
    """Objective and constraints of the optimisation, evaluated once per x."""

    def __init__(self, plant, base, pi, limits, period, harmonics, center, samples):
        self.plant, self.base, self.pi, self.limits = plant, base, pi, limits
        self.period, self.harmonics, self.center = period, harmonics, np.asarray(center, float)
        self.t = np.arange(samples) * period / samples
        self.rho_min, self.rho_max = plant.get("rho_min"), plant.get("rho_max")
        self._cache = {}  # x's bytes -> (objective, constraints): SLSQP asks both at the same points

    def trajectory(self, x):
        return FourierTrajectory.from_vector(x, self.period, self.harmonics, self.center)

    def evaluate(self, x):
        key = np.asarray(x, float).tobytes()
        if key in self._cache:
            return self._cache[key]
        pose, vel, acc = self.trajectory(x).evaluate(self.t)
        L = self.limits
        # Every margin at every sample, relative to its own limit (SLSQP sees
        # them alike): >= 0 within the limits.
        box = np.concatenate([1.0 - np.abs(pose[:, :2]).ravel() / L.xy, (pose[:, 2] - L.z[0]) / (L.z[1] - L.z[0]),
                              (L.z[1] - pose[:, 2]) / (L.z[1] - L.z[0]), 1.0 - np.abs(pose[:, 3]) / L.phi])
        try:
            Y, F0, rho, drho = self.plant.regressor_poses(pose, vel, acc)
        except capi.PkmError:
            val = (1e3, np.concatenate([box, -np.ones(16 * len(self.t))]))
        else:
            W = Y[:, :, self.base.independent].reshape(-1, len(self.base.independent))
            norms = np.linalg.norm(W, axis=0)
            if np.any(norms == 0):
                cond = 1e3
            else:
                s = np.linalg.svd(W / norms, compute_uv=False)
                cond = np.log10(s[0] / s[-1])
            F = np.einsum("nij,j->ni", Y, self.pi) + F0
            travel = self.rho_max - self.rho_min
            val = (cond, np.concatenate([box, ((rho - self.rho_min - L.stop_margin) / travel).ravel(),
                                         ((self.rho_max - L.stop_margin - rho) / travel).ravel(),
                                         (1.0 - np.abs(drho) / L.speed).ravel(), (1.0 - np.abs(F) / L.force).ravel()]))
        if len(self._cache) > 4096:
            self._cache.clear()
        self._cache[key] = val
        return val


def _feasible_start(prob, limits, period, harmonics, seed):
    """Seeded random coefficients within the limits: amplitudes a fraction
    of the workspace's, shrunk until every constraint holds."""
    rng = np.random.default_rng(seed)
    k = np.arange(1, harmonics + 1) * (2 * np.pi / period)
    amp = np.array([limits.xy, limits.xy, 0.5 * (limits.z[1] - limits.z[0]), limits.phi])
    for attempt in range(20):
        shrink = 0.4 * 0.8 ** attempt
        a = rng.uniform(-1, 1, (4, harmonics)) * (shrink * amp)[:, None] * k / np.sqrt(harmonics)
        b = rng.uniform(-1, 1, (4, harmonics)) * (shrink * amp)[:, None] * k / np.sqrt(harmonics)
        x0 = np.concatenate([a.ravel(), b.ravel()])
        if np.all(prob.evaluate(x0)[1] >= 0):
            return x0
    raise RuntimeError("no starting trajectory within the limits: widen them")


def random_trajectory(lib=None, *, period=3.0, harmonics=4, limits=None, model=None, samples=100, seed=1,
                      center=(0.0, 0.0, 0.06, 0.0)) -> FourierTrajectory:
    """A Fourier trajectory with seeded random coefficients within `limits`
    (not optimised): a validation trajectory unlike the excitation."""
    lib = lib or capi.load()
    limits = limits or Limits()
    with make_plant(lib, model) as plant:
        base = base_parameters(plant)
        prob = _Problem(plant, base, plant.regressor_params(), limits, period, harmonics, center, samples)
        x = _feasible_start(prob, limits, period, harmonics, seed)
        traj = prob.trajectory(x)
        traj.condition = float(10 ** prob.evaluate(x)[0])
    return traj


def optimise_excitation(lib=None, *, period=2.5, harmonics=5, limits=None, model=None, samples=100, seed=0,
                        maxiter=60, center=(0.0, 0.0, 0.06, 0.0)) -> FourierTrajectory:
    """The Fourier coefficients (a, b per axis and harmonic) that minimise the
    condition number of the stacked base regressor at `samples` points of
    one period, its columns scaled to unit norm, subject to `limits`
    (Limits) with the nominal parameters `model` (FMU names over the spec's).
    SLSQP from a seeded random start inside the limits; the result holds
    them also on a grid ten times finer. Raises RuntimeError if no
    trajectory within the limits was found."""
    minimize = extras.import_module("scipy.optimize", "pkm4puu.calibration").minimize

    lib = lib or capi.load()
    limits = limits or Limits()
    with make_plant(lib, model) as plant:
        base = base_parameters(plant)
        pi = plant.regressor_params()
        prob = _Problem(plant, base, pi, limits, period, harmonics, center, samples)
        best = _feasible_start(prob, limits, period, harmonics, seed)
        res = minimize(lambda x: prob.evaluate(x)[0], best, method="SLSQP",
                       constraints=[{"type": "ineq", "fun": lambda x: prob.evaluate(x)[1]}],
                       options={"maxiter": maxiter, "ftol": 1e-6})
        # The last iterate may end slightly outside the limits, or between
        # the samples: back off towards the start until it is inside on a
        # grid ten times finer.
        fine = _Problem(plant, base, pi, limits, period, harmonics, center, 10 * samples)
        x = best
        for alpha in np.append(0.5 ** np.arange(0, 12), 0.0):
            trial = best + alpha * (res.x - best)
            if np.all(prob.evaluate(trial)[1] >= 0.0) and np.all(fine.evaluate(trial)[1] >= 0.0):
                x = trial
                break
        else:
            raise RuntimeError("the excitation's random start leaves the limits between its samples: "
                               "use more samples")
        cond, _ = prob.evaluate(x)
        traj = prob.trajectory(x)
        traj.condition = float(10 ** cond)
        traj.start_condition = float(10 ** prob.evaluate(best)[0])
    return traj
