# SPDX-License-Identifier: BSD-2-Clause
"""Identification of the dynamic parameters from a drive log: the sliders'
measured positions rho (n x 4) and the actuator forces F (n x 4) at times t
(docs/calibration.md).

    r = identify(t, rho, F, cutoff=20.0, model={"friction_velocity": 0.005})
    r.table()            # the base parameters with their standard deviations
    r.start_values       # FMU parameter name -> value (PKM4PUU, PKM4PUU_Inverse)

Steps: a zero-phase Butterworth low-pass of rho (cut-off `cutoff`, forward
and backward), central differences for drho and ddrho, the regressor of the
forces in the dynamic parameters through the forward kinematics
(pkm_regressor_joints), the samples within `trim` of either end dropped
(the filter's edges), ordinary least squares for the base parameters, the
legs weighted by the inverse of their residuals' standard deviations and
solved again (weighted least squares), optionally under the parameters'
physical bounds; the start values then from the base parameters and the
model's known values for what the forces cannot separate.

The regressor is computed in blocks of `block` samples, each leg's rows
[W_i | y_i] reduced at once to the triangular factor R_i of their QR
decomposition: every least-squares quantity below follows from the four
R_i (W_i^T W_i = R_i^T R_i), so the memory grows with the log's few
columns, not with the regressor's rows.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numpy as np

from .. import capi, extras
from .parameters import BaseParameters, base_parameters, make_plant

BLOCK = 20000  # samples per block of the regressor (about 9 MB of it)


class IdentificationError(ValueError):
    """Data the identification cannot use; the message says what and where."""


@dataclass
class IdentificationResult:
    base: BaseParameters
    values: np.ndarray          # the base parameters (constrained if asked)
    std: np.ndarray             # their standard deviations (weighted least squares)
    values_ls: np.ndarray       # the unconstrained weighted least-squares solution
    start_values: dict          # FMU parameter name -> start value
    condition: float            # of the stacked base regressor, columns scaled to unit norm
    leg_sigma: np.ndarray       # residual standard deviation of each leg's force, N
    residual_rms: float         # of the weighted fit's force residuals, N
    samples: int                # samples used (after trimming)
    active_bounds: list = field(default_factory=list)  # constraints that bind
    warnings: list = field(default_factory=list)

    @property
    def names(self):
        return self.base.names

    def table(self):
        w = max(len(n) for n in self.names)
        rows = [f"{'base parameter':<{w}}  {'value':>13}  {'std':>10}  {'rel. std':>8}"]
        for n, v, s in zip(self.names, self.values, self.std):
            rel = f"{s / abs(v):8.2%}" if v != 0 else "       -"
            rows.append(f"{n:<{w}}  {v:13.6g}  {s:10.3g}  {rel}")
        return "\n".join(rows)


def _check_data(t, rho, F, min_samples):
    t = np.asarray(t, dtype=float)
    rho = np.asarray(rho, dtype=float)
    F = np.asarray(F, dtype=float)
    if t.ndim != 1:
        raise IdentificationError(f"t must be one-dimensional, got shape {t.shape}")
    for name, a in (("rho", rho), ("F", F)):
        if a.shape != (len(t), 4):
            raise IdentificationError(f"{name} must have shape ({len(t)}, 4) (one column per leg), got {a.shape}")
    for name, a in (("t", t), ("rho", rho), ("F", F)):
        bad = np.argwhere(~np.isfinite(a))
        if len(bad):
            k = bad[0][0]
            where = f"sample {k}" + (f" (t = {t[k]:.6g} s), leg {bad[0][1] + 1}" if a.ndim == 2 else "")
            raise IdentificationError(f"{name} has {len(bad)} non-finite value(s) (NaN or inf), the first at "
                                      f"{where}: remove or interpolate them")
    if len(t) < min_samples:
        raise IdentificationError(f"too short: {len(t)} samples, the identification needs at least {min_samples} "
                                  f"(3 rows per base parameter and more)")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise IdentificationError(f"time is not strictly increasing: t[{k + 1}] = {t[k + 1]:.9g} s after "
                                  f"t[{k}] = {t[k]:.9g} s")
    h = np.median(dt)
    if np.max(np.abs(dt - h)) > 0.05 * h:
        k = int(np.argmax(np.abs(dt - h)))
        raise IdentificationError(f"the samples are not evenly spaced: step {dt[k]:.6g} s at sample {k} against "
                                  f"the median {h:.6g} s; resample the log first")
    return t, rho, F, h


def _scipy(module):
    """scipy.<module>, or extras.MissingExtra saying how to install it."""
    return extras.import_module(f"scipy.{module}", "pkm4puu.identify")


def filtered_derivatives(t, rho, cutoff, order=4):
    """rho low-passed without phase (Butterworth of `order`, forward and
    backward: the magnitude response squared) and its first and second
    central differences."""
    signal = _scipy("signal")

    h = (t[-1] - t[0]) / (len(t) - 1)
    fs = 1.0 / h
    if not 0 < cutoff < 0.5 * fs:
        raise IdentificationError(f"the cut-off {cutoff} Hz must lie between 0 and half the sampling rate "
                                  f"({0.5 * fs:.6g} Hz)")
    sos = signal.butter(order, cutoff, fs=fs, output="sos")
    r = signal.sosfiltfilt(sos, rho, axis=0)
    rd = np.gradient(r, t, axis=0)
    rdd = np.gradient(rd, t, axis=0)
    return r, rd, rdd


def _leg_factors(plant, r, rd, rdd, F, independent, block, guess):
    """The triangular factors R_i ((nb + 1) x (nb + 1)) of each leg's rows
    [W_i | y_i] over the samples, the regressor computed `block` samples at
    a time, each block's forward kinematics starting from the previous
    block's last pose. PkmError's `sample` counts from r's first row."""
    nb = len(independent)
    R = np.zeros((4, nb + 1, nb + 1))
    for start in range(0, len(r), block):
        part = slice(start, start + block)
        try:
            Y, F0, pose = plant.regressor_joints(r[part], rd[part], rdd[part], guess=guess)
        except capi.PkmError as e:
            e.sample = start + getattr(e, "sample", 0)
            raise
        guess = pose[-1]
        rows = np.concatenate([Y[:, :, independent], (F[part] - F0)[:, :, None]], axis=2)  # (n, 4, nb + 1)
        for i in range(4):
            R[i] = np.linalg.qr(np.vstack([R[i], rows[:, i, :]]), mode="r")
    return R


def _squared_residuals(R, x):
    """Each leg's sum of squared residuals |W_i x - y_i|^2 = |R_i (x, -1)|^2."""
    v = np.append(x, -1.0)
    return np.array([np.sum((Ri @ v) ** 2) for Ri in R])


def _stacked(R, weights):
    """(R_W, z) of the legs' rows stacked, leg i's weighted by weights[i]:
    W^T W = R_W^T R_W and W^T y = R_W^T z."""
    Rs = np.linalg.qr(np.vstack([w * Ri for w, Ri in zip(weights, R)]), mode="r")
    return Rs[:-1, :-1], Rs[:-1, -1]


def identify(t, rho, F, *, cutoff=20.0, order=4, trim=None, model=None, physical=True, weighted=True,
             rank_tol=1e-6, lib=None, guess=None, block=BLOCK) -> IdentificationResult:
    """The base parameters from a log of the sliders' positions rho (m) and
    the actuator forces F (N), n x 4 each, at the times t (s, evenly spaced).

    cutoff
        the low-pass's cut-off (Hz), above the motion's bandwidth and below
        the encoder noise's; order: the Butterworth order.
    trim
        samples dropped at either end (default: two periods of the cut-off).
    model
        FMU parameter name -> value for what is known (geometry, g,
        screw_lead, friction_velocity, stops, the mounted payload); the
        spec's values otherwise.
    physical
        constrain the base parameters to their physical bounds (positive
        masses and inertias, friction >= 0, the rod's triangle
        inequalities), so that the start values are a valid parameter set.
    guess
        the platform pose (x, y, z, phi) the forward kinematics starts from
        at the first sample (default the home pose 0, 0, 0.05 m, 0).
    rank_tol
        a base parameter whose column in the stacked regressor (each column
        relative to its size under generic motions) lies within this
        relative distance of the others' span is not identifiable from the
        data: IdentificationError names it.
    block
        samples per block of the regressor (the memory it takes).

    Needs scipy (the extra `calibration`): extras.MissingExtra otherwise.
    """
    linalg = _scipy("linalg")
    if not (isinstance(cutoff, numbers.Real) and math.isfinite(cutoff) and cutoff > 0):
        raise IdentificationError(f"the cut-off {cutoff!r} Hz must be a finite number > 0")
    for name, value, least in (("trim", trim, 0), ("block", block, 1)):
        if value is not None and not (isinstance(value, numbers.Integral) and value >= least):
            raise IdentificationError(f"{name} {value!r} must be a whole number of samples >= {least}")
    lib = lib or capi.load()
    model = dict(model or {})
    try:
        plant = make_plant(lib, model)
    except (capi.PkmError, KeyError) as e:
        raise IdentificationError(f"the model parameters are not valid: {e}") from None
    with plant:
        base = base_parameters(plant)
        nb = len(base.independent)
        t, rho, F, h = _check_data(t, rho, F, min_samples=3 * nb + 30)
        trim_n = int(trim) if trim is not None else int(np.ceil(2.0 / (cutoff * h)))
        if len(t) < 2 * trim_n + 3 * nb + 30:
            raise IdentificationError(f"too short: {len(t)} samples, the identification needs at least "
                                      f"{2 * trim_n + 3 * nb + 30} (the filter's edges, {trim_n} at each end, "
                                      f"and 3 rows per base parameter)")
        rho_min, rho_max = plant.get("rho_min"), plant.get("rho_max")
        outside = np.argwhere((rho < rho_min) | (rho > rho_max))
        if len(outside):
            k, i = outside[0]
            raise IdentificationError(
                f"slider {i + 1} leaves its travel [{rho_min:g}, {rho_max:g}] m at sample {k} (t = {t[k]:.6g} s, "
                f"rho = {rho[k, i]:.6g} m; {len(outside)} such values): the end stops' forces are not "
                f"identified, cut these samples out")
        r, rd, rdd = filtered_derivatives(t, rho, cutoff, order)
        keep = slice(trim_n, len(t) - trim_n)
        try:
            # The dependent columns equal combinations of the kept ones: W pi = W_kept pi_b.
            R_legs = _leg_factors(plant, r[keep], rd[keep], rdd[keep], F[keep], base.independent, block, guess)
        except capi.PkmError as e:
            k = trim_n + getattr(e, "sample", 0)
            raise IdentificationError(
                f"slider positions out of the mechanism's reach at sample {k} (t = {t[k]:.6g} s, rho = "
                f"{np.array2string(rho[k], precision=6)} m): no platform pose joins them ({e})") from None
    samples = keep.stop - keep.start
    n_rows = 4 * samples
    W, y = _stacked(R_legs, np.ones(4))  # W^T W and W^T y of the stacked rows

    # Identifiability: the pivoted QR of the columns, each relative to its
    # size under generic motions (BaseParameters.typical), so that a column
    # the data leave near zero counts as zero (docs/calibration.md).
    Wt = W / (base.typical * np.sqrt(n_rows))
    R, piv = linalg.qr(Wt, mode="r", pivoting=True)
    d = np.abs(np.diag(R))
    weak = [base.names[piv[j]] for j in range(nb) if not d[j] > rank_tol * d[0]]
    if weak:
        raise IdentificationError(
            f"the regressor is rank-deficient ({nb - len(weak)} of {nb}): the data do not separate "
            f"{', '.join(weak)} from the other parameters: not identifiable; use a longer or more "
            f"exciting trajectory (pkm4puu.calibration.excitation)")
    norms = np.linalg.norm(W, axis=0)
    s = np.linalg.svd(W / norms, compute_uv=False)
    condition = float(s[0] / s[-1])

    # Ordinary, then leg-weighted least squares (each leg's noise its own),
    # on the triangular factors: the same normal equations as the rows'.
    x = np.linalg.lstsq(W, y, rcond=None)[0]
    dof = max(samples - nb / 4.0, 1.0)
    leg_sigma = np.sqrt(_squared_residuals(R_legs, x) / dof)
    w = 1.0 / leg_sigma if weighted and np.all(leg_sigma > 0) else np.ones(4)
    Ww, yw = _stacked(R_legs, w)
    x = np.linalg.lstsq(Ww, yw, rcond=None)[0]
    s2 = float(w ** 2 @ _squared_residuals(R_legs, x)) / (n_rows - nb)
    cov = s2 * np.linalg.inv(Ww.T @ Ww)
    std = np.sqrt(np.diag(cov))
    x_ls = x.copy()

    active = []
    if physical:
        x, active = _constrained(Ww, yw, x, std, base)
    start, warnings = start_values(base, x, std, model, lib)
    return IdentificationResult(base=base, values=x, std=std, values_ls=x_ls, start_values=start,
                                condition=condition, leg_sigma=leg_sigma,
                                residual_rms=float(np.sqrt(np.sum(_squared_residuals(R_legs, x)) / n_rows)),
                                samples=samples, active_bounds=active, warnings=warnings)


def _physical_rows(base):
    """Rows A with A x >= b for the base parameters x: the bounds of
    BaseParameters.lower and the rod's triangle inequalities (validate())."""
    A, b, what = [], [], []
    for j, lb in enumerate(base.lower):
        if np.isfinite(lb):
            row = np.zeros(len(base.independent))
            row[j] = 1.0
            A.append(row), b.append(lb), what.append(f"{base.names[j]} >= {lb:g}")
    try:
        ix, iy, iz = (base.index(n) for n in ("I_rod[1]", "I_rod[2]", "I_rod[3]"))
    except ValueError:
        ix = None
    if ix is not None:
        for a, c, e in ((ix, iy, iz), (ix, iz, iy), (iy, iz, ix)):
            row = np.zeros(len(base.independent))
            row[a], row[c], row[e] = 1.0, 1.0, -1.0
            A.append(row), b.append(0.0), what.append(f"{base.names[a]} + {base.names[c]} >= {base.names[e]}")
    return np.array(A), np.array(b), what


def _constrained(Ww, yw, x, std, base):
    """The weighted least squares min |Ww x - yw| under the physical rows
    (SLSQP on the parameters scaled by their standard deviations); x itself
    when it satisfies them. Ww and yw may be any pair with the same normal
    equations (the rows' triangular factor)."""
    minimize = _scipy("optimize").minimize

    A, b, what = _physical_rows(base)
    if len(A) == 0 or np.all(A @ x >= b):
        return x, []
    scale = np.where(std > 0, std, 1.0)
    H = (Ww * scale).T @ (Ww * scale)
    g = (Ww * scale).T @ yw
    As = A * scale
    z0 = x / scale
    res = minimize(lambda z: 0.5 * z @ H @ z - g @ z, z0, jac=lambda z: H @ z - g, method="SLSQP",
                   constraints=[{"type": "ineq", "fun": lambda z: As @ z - b, "jac": lambda z: As}],
                   options={"maxiter": 500, "ftol": 1e-14})
    z = res.x
    # The solver's last iterate may sit a rounding below a bound: lift it.
    xs = z * scale
    for j, lb in enumerate(base.lower):
        if np.isfinite(lb):
            xs[j] = max(xs[j], lb)
    active = [w for w, row, bb in zip(what, A, b) if row @ xs - bb <= 1e-9 * max(1.0, abs(bb)) + 1e-12]
    return xs, active


def start_values(base, x, std, model, lib):
    """FMU parameter name -> start value from the base parameters x: each base
    parameter's leading term takes it minus the model's known values of the
    terms folded into it (the mounted payload: the forces carry only the sum
    of platform and payload)."""
    names = base.full_names
    known = make_plant(lib, model)
    with known:
        pi_known = known.regressor_params()
        payload_Izz_known = known.get("payload_Izz")
        v_s = known.get("friction_velocity")
    pi = pi_known.copy()
    warnings = []
    for j, lead in enumerate(base.independent):
        pi[lead] = x[j]
    # The mounted payload's mass is known (the forces carry only the sum with
    # the platform's); its first moments are identified, its centre of mass
    # follows, and its inertia about P with the known own inertia.
    ip, mx, my, iz = (names.index(n) for n in ("payload_mass", "payload_mx", "payload_my", "payload_Izz_P"))
    payload_mass = pi[ip]
    if payload_mass <= 0.0:
        for k in (mx, my):
            if k in base.independent:
                j = base.independent.index(k)
                if abs(x[j]) > 3 * std[j]:
                    warnings.append(f"{names[k]} = {x[j]:.3g} +- {std[j]:.2g} kg m is significant but the model "
                                    f"has no payload mass to carry it: give payload_mass in `model`")
            pi[k] = 0.0
    com = (pi[mx] / payload_mass, pi[my] / payload_mass) if payload_mass > 0 else (0.0, 0.0)
    if iz in base.dependent:
        pi[iz] = payload_Izz_known + payload_mass * (com[0] ** 2 + com[1] ** 2)
    for j, lead in enumerate(base.independent):
        if lead in (mx, my) and payload_mass <= 0.0:
            continue
        pi[lead] = x[j] - sum(base.K[j, d] * pi[d] for d in base.dependent)
    # The FMU takes the payload's centre of mass and its own inertia.
    out = {}
    for i, n in enumerate(names):
        if n == "payload_mx":
            out["payload_com[1]"] = float(com[0])
        elif n == "payload_my":
            out["payload_com[2]"] = float(com[1])
        elif n == "payload_Izz_P":
            out["payload_Izz"] = float(payload_Izz_known)
        else:
            out[n] = float(pi[i])
    out["friction_velocity"] = float(v_s)
    try:
        with make_plant(lib, {**model, **out}):
            pass
    except capi.PkmError as e:
        warnings.append(f"the identified values are no valid parameter set (identify with physical=True): {e}")
    return out, warnings
