# SPDX-License-Identifier: BSD-2-Clause
"""The dynamic parameters of the regressor (pkm.h's pkm_regressor) and the
base parameters: the combinations of them that the actuator forces
determine (docs/calibration.md).

    lib = capi.load()
    plant = make_plant(lib, {"friction_velocity": 0.005})
    base = base_parameters(plant)       # numerically, from a pivoted QR
    base.names  -> ["m_slider", ..., "m_platform + payload_mass", ...]
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from .. import capi, extras

# Lower bounds of pi's entries that make a parameter set the FMUs accept
# (the parameter table, src/pkm4puu/model/parameter_table.hpp): masses >= 1 mg, the rod's and the
# platform's inertias >= 1e-12 kg m^2, the payload, rotor and friction >= 0;
# the payload's first moments are signed.
LOWER = {"m_slider": 1e-6, "m_rod": 1e-6, "I_rod[1]": 1e-12, "I_rod[2]": 1e-12, "I_rod[3]": 1e-12,
         "m_platform": 1e-6, "Izz_platform": 1e-12, "payload_mass": 0.0, "payload_mx": -np.inf,
         "payload_my": -np.inf, "payload_Izz_P": 0.0, "rotor_inertia": 0.0, "friction_viscous": 0.0,
         "friction_coulomb": 0.0}

def make_plant(lib, values=None):
    """A capi.Plant of the spec's parameters with `values` (the FMUs'
    parameter names: "m_rod", "I_rod[2]", "payload_com[1]", "screw_lead", ...)
    set over them. Raises KeyError naming a name that is no parameter (or an
    index out of its vector's 1..n), capi.PkmError naming an invalid value."""
    values = dict(values or {})
    for name in values:
        if name not in lib.parameters:
            raise KeyError(f"{name!r} is no parameter of the model" + _what_it_is(lib, name))
    return capi.Plant(lib, **{name: float(v) for name, v in values.items()})


def _what_it_is(lib, name):
    """": beta is a vector, beta[1] to beta[4]" where `name` misses a
    parameter by its index (or has one where the parameter has none)."""
    base = name.split("[", 1)[0]
    indices = sorted(int(m.group(1)) for m in (re.fullmatch(re.escape(base) + r"\[(\d+)\]", n)
                                                 for n in lib.parameters) if m)
    if indices:
        return f": {base} is a vector, {base}[{indices[0]}] to {base}[{indices[-1]}]"
    if base != name and base in lib.parameters:
        return f": {base} is a number, without an index"
    return ""


@dataclass
class BaseParameters:
    """The identifiable combinations pi_b = K pi of the full parameter vector:
    pi_b[j] = pi[independent[j]] + sum_d beta[j, d] pi[dependent[d]]."""
    full_names: list
    units: list
    independent: list   # indices into pi of the base parameters' leading terms
    dependent: list     # indices into pi of the parameters folded into them
    K: np.ndarray       # (n_base, n_pi)
    typical: np.ndarray  # RMS of each base parameter's regressor entries over the random motions

    @property
    def names(self):
        return [self.formula(j) for j in range(len(self.independent))]

    @property
    def lower(self):
        """Lower bound of each base parameter implied by its terms' (LOWER):
        a positive combination of bounded terms is bounded; -inf otherwise."""
        out = []
        for row in self.K:
            terms = [(c, LOWER[self.full_names[i]]) for i, c in enumerate(row) if c != 0.0]
            out.append(sum(c * lb for c, lb in terms) if all(c > 0 and np.isfinite(lb) for c, lb in terms)
                       else -np.inf)
        return np.array(out)

    def formula(self, j):
        parts = []
        for i, c in enumerate(self.K[j]):
            if c == 0.0:
                continue
            name = self.full_names[i]
            if not parts:
                parts.append(name if c == 1.0 else f"{c:.6g} {name}")
            else:
                parts.append(f"+ {name}" if c == 1.0 else f"{'-' if c < 0 else '+'} {abs(c):.6g} {name}")
        return " ".join(parts)

    def index(self, name):
        return self.names.index(name)


def random_motions(n, seed=0, center=(0.0, 0.0, 0.06, 0.0)):
    """n random platform motions (pose, velocity, acceleration) near the
    workspace's centre, for the structural rank."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, size=(3, n, 4))
    pose = np.asarray(center) + u[0] * [0.008, 0.008, 0.012, 0.08]
    return pose, u[1] * [0.2, 0.2, 0.2, 1.5], u[2] * [2.0, 2.0, 2.0, 20.0]


def base_parameters(plant, samples=120, seed=0, tol=1e-9):
    """The base parameters of `plant`'s geometry, numerically: the regressors
    of random motions stacked, their columns scaled to unit norm; the
    numerical rank from a column-pivoted QR; then, in pi's order, each column
    that raises the rank of those kept is kept (so the formulas fold the
    payload into the platform, not the reverse), and the others are written
    as combinations of the kept ones by least squares."""
    qr = extras.import_module("scipy.linalg", "pkm4puu.calibration").qr

    names = [n for n, _ in capi.regressor_params(plant.lib)]
    units = [u for _, u in capi.regressor_params(plant.lib)]
    Y, _, _, _ = plant.regressor_poses(*random_motions(samples, seed))
    W = Y.reshape(-1, Y.shape[2])
    norms = np.linalg.norm(W, axis=0)
    if np.any(norms == 0.0):
        raise RuntimeError(f"regressor columns identically zero: {[names[i] for i in np.where(norms == 0)[0]]}")
    Ws = W / norms
    R = qr(Ws, mode="r", pivoting=True)[0]
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tol * d[0]))
    kept = []
    for j in range(W.shape[1]):
        trial = kept + [j]
        s = np.linalg.svd(Ws[:, trial], compute_uv=False)
        if s[-1] > tol * s[0] * np.sqrt(len(trial)) and len(kept) < rank:
            kept = trial
    dependent = [j for j in range(W.shape[1]) if j not in kept]
    K = np.zeros((len(kept), W.shape[1]))
    K[np.arange(len(kept)), kept] = 1.0
    if dependent:
        beta = np.linalg.lstsq(W[:, kept], W[:, dependent], rcond=None)[0]
        beta[np.abs(beta) < 1e-9] = 0.0
        near_int = np.abs(beta - np.round(beta)) < 1e-9
        beta[near_int] = np.round(beta[near_int])
        K[:, dependent] = beta
    typical = norms[kept] / np.sqrt(W.shape[0])
    return BaseParameters(names, units, kept, dependent, K, typical)
