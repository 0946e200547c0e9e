# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu.identify and `pkm4puu identify` refuse bad data with a message
that says what and where (docs/calibration.md): too short, non-exciting
(naming what is not identifiable), NaN samples, time going back, slider
positions out of reach or beyond the travel, a CSV without the columns, a
cut-off or trim that is no number of the kind. The regressor goes in
blocks, whatever their size the same estimate as the stacked rows' least
squares. The logs here are made with the C API's regressor, exact forces
F = Y pi + F0 along a random Fourier trajectory (no FMU needed)."""
import csv
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from pkm4puu import capi, locate
from pkm4puu.calibration import IdentificationError, filtered_derivatives, identify, random_trajectory
from pkm4puu.calibration.parameters import make_plant

MODEL = {"friction_velocity": 0.005}
H = 1e-3


@pytest.fixture(scope="module")
def lib(pkm_library):
    return capi.load(pkm_library)


def make_log(lib, pose, vel, acc, params=MODEL):
    with make_plant(lib, params) as p:
        Y, F0, rho, _ = p.regressor_poses(pose, vel, acc)
        F = np.einsum("nij,j->ni", Y, p.regressor_params()) + F0
    return np.arange(len(pose)) * H, rho, F


@pytest.fixture(scope="module")
def good(lib):
    traj = random_trajectory(lib, model=MODEL, period=2.0, harmonics=4, seed=3)
    t = np.arange(3001) * H
    return make_log(lib, *traj.evaluate(t))


def test_a_good_log_identifies_the_parameters(good, lib):
    """The baseline of the refusals below: exact forces give the spec's base
    parameters back (the only error the filter's and the differences'),
    within the reported deviations."""
    r = identify(*good, model=MODEL, lib=lib)
    with make_plant(lib, MODEL) as p:
        truth = r.base.K @ p.regressor_params()
    assert np.all(np.abs(r.values_ls - truth) < 3 * r.std + 1e-12)
    # No payload in the model and none in the data: its first moments are
    # insignificant and the start values have none.
    assert not r.warnings
    assert r.start_values["payload_mass"] == 0.0 and r.start_values["payload_com[1]"] == 0.0


def test_a_model_parameter_that_does_not_exist_is_named(good, lib):
    with pytest.raises(IdentificationError, match="'m_sliders' is no parameter of the model"):
        identify(*good, model={"m_sliders": 0.1}, lib=lib)
    with pytest.raises(IdentificationError, match="screw_lead"):
        identify(*good, model={"screw_lead": -1.0}, lib=lib)


def test_too_short(good, lib):
    t, rho, F = (a[:60] for a in good)
    with pytest.raises(IdentificationError, match="too short: 60 samples"):
        identify(t, rho, F, model=MODEL, lib=lib)


def test_a_motion_without_rotation_leaves_the_rotational_parameters_unidentifiable(lib):
    """A vertical move, no x, y or phi: nothing turns the rods about theta1
    nor the platform, so I_rod[1], I_rod[2], the platform's inertia and the
    payload's first moments have no effect on the forces; the message names
    them (among others: the four legs move alike, and the rest collapses too)."""
    t = np.arange(2001) * H
    w = 2 * np.pi / 2.0
    z = 0.06 + 0.01 * np.sin(w * t)
    zero = np.zeros_like(t)
    pose = np.c_[zero, zero, z, zero]
    vel = np.c_[zero, zero, 0.01 * w * np.cos(w * t), zero]
    acc = np.c_[zero, zero, -0.01 * w * w * np.sin(w * t), zero]
    with pytest.raises(IdentificationError, match="not identifiable") as e:
        identify(*make_log(lib, pose, vel, acc), model=MODEL, lib=lib)
    msg = str(e.value)
    for name in ("I_rod[1]", "I_rod[2]", "Izz_platform + payload_Izz_P", "payload_mx", "payload_my"):
        assert name in msg, msg


def test_a_nan_sample_is_named(good, lib):
    t, rho, F = (a.copy() for a in good)
    F[1234, 2] = np.nan
    with pytest.raises(IdentificationError, match=r"F has 1 non-finite value\(s\).*sample 1234 .*leg 3"):
        identify(t, rho, F, model=MODEL, lib=lib)
    t, rho, F = (a.copy() for a in good)
    rho[10, 0] = np.inf
    with pytest.raises(IdentificationError, match="rho has 1 non-finite.*sample 10 "):
        identify(t, rho, F, model=MODEL, lib=lib)


def test_time_going_back_is_named(good, lib):
    t, rho, F = (a.copy() for a in good)
    t[500], t[501] = t[501], t[500]
    with pytest.raises(IdentificationError, match=r"not strictly increasing: t\[501\]"):
        identify(t, rho, F, model=MODEL, lib=lib)


def test_uneven_sampling_is_refused(good, lib):
    t, rho, F = (a.copy() for a in good)
    t[700:] += 0.5 * H
    with pytest.raises(IdentificationError, match="not evenly spaced.*sample 699"):
        identify(t, rho, F, model=MODEL, lib=lib)


def test_slider_positions_out_of_reach_are_named(good, lib):
    """Slider 1 3 cm above the others' trajectory for 30 samples mid-log:
    within its travel, but no platform pose joins the four (the rod is
    0.08 m long): the forward kinematics fails at the first of them."""
    t, rho, F = (a.copy() for a in good)
    rho[1500:1530, 0] += 0.09
    assert rho[:, 0].max() < 0.15  # within the travel: the reach, not the stops
    with pytest.raises(IdentificationError, match="out of the mechanism's reach at sample 15"):
        identify(t, rho, F, model=MODEL, lib=lib, cutoff=200.0)


def test_slider_positions_beyond_the_travel_are_named(good, lib):
    t, rho, F = (a.copy() for a in good)
    rho[2000, 3] = 0.151
    with pytest.raises(IdentificationError, match=r"slider 4 leaves its travel \[0, 0.15\] m at sample 2000"):
        identify(t, rho, F, model=MODEL, lib=lib)


def test_cutoff_above_nyquist(good, lib):
    with pytest.raises(IdentificationError, match="cut-off 600"):
        identify(*good, model=MODEL, lib=lib, cutoff=600.0)


@pytest.mark.parametrize("kw, message", [({"cutoff": 0.0}, "the cut-off 0.0 Hz"),
                                         ({"cutoff": np.nan}, "the cut-off nan Hz"),
                                         ({"cutoff": "20"}, "the cut-off '20' Hz"),
                                         ({"trim": -5}, "trim -5 must be a whole number of samples >= 0"),
                                         ({"trim": 2.5}, "trim 2.5 must be"), ({"block": 0}, "block 0 must be")],
                         ids=["cutoff 0", "cutoff nan", "cutoff text", "trim -5", "trim 2.5", "block 0"])
def test_a_cutoff_or_trim_of_the_wrong_kind_is_named(good, lib, kw, message):
    with pytest.raises(IdentificationError, match=re.escape(message)):
        identify(*good, model=MODEL, lib=lib, **kw)


def test_the_blocks_give_the_stacked_rows_least_squares(good, lib):
    """The regressor in blocks of 997 samples (the last one short) and in
    one: the same estimate to rounding; and both the weighted least squares
    of the stacked rows computed here directly (the rows [Y_i | F_i - F0_i]
    of every leg, numpy's lstsq, each leg weighted by its OLS residuals'
    standard deviation): values, standard deviations, condition number and
    residual. The values' columns differ in size by 1e9 (masses against
    rotor inertia), so the orders of the sums leave each value a rounding
    error relative to its standard deviation, not to itself: the values are
    compared to 1e-6 of their standard deviations."""
    t, rho, F = (a.copy() for a in good)
    rng = np.random.default_rng(5)
    F += 0.01 * rng.standard_normal(F.shape)  # residuals that differ per leg: the weights matter
    blocked = identify(t, rho, F, model=MODEL, lib=lib, physical=False, block=997)
    whole = identify(t, rho, F, model=MODEL, lib=lib, physical=False, block=len(t))
    assert np.all(np.abs(blocked.values - whole.values) <= 1e-6 * whole.std) and blocked.samples == whole.samples
    trim = round(2 / (20.0 * H))  # the default: two periods of the 20 Hz cut-off
    keep = slice(trim, len(t) - trim)
    assert blocked.samples == keep.stop - keep.start
    r, rd, rdd = filtered_derivatives(t, rho, 20.0)
    with make_plant(lib, MODEL) as p:
        Y, F0, _ = p.regressor_joints(r[keep], rd[keep], rdd[keep])
    W = Y[:, :, blocked.base.independent]  # (n, 4, nb)
    y = F[keep] - F0
    x = np.linalg.lstsq(W.reshape(-1, W.shape[2]), y.reshape(-1), rcond=None)[0]
    sigma = np.sqrt(np.sum((W @ x - y) ** 2, axis=0) / (len(y) - W.shape[2] / 4))
    Ww, yw = (W / sigma[:, None]).reshape(-1, W.shape[2]), (y / sigma).reshape(-1)
    xw = np.linalg.lstsq(Ww, yw, rcond=None)[0]
    s2 = np.sum((Ww @ xw - yw) ** 2) / (len(yw) - len(xw))
    std = np.sqrt(np.diag(s2 * np.linalg.inv(Ww.T @ Ww)))
    Wn = W.reshape(-1, W.shape[2])
    sv = np.linalg.svd(Wn / np.linalg.norm(Wn, axis=0), compute_uv=False)
    for result in (blocked, whole):
        assert np.all(np.abs(result.values - xw) <= 1e-6 * std)
        assert np.allclose(result.leg_sigma, sigma, rtol=1e-8, atol=0)
        assert np.allclose(result.std, std, rtol=1e-6, atol=0)
        assert result.condition == pytest.approx(sv[0] / sv[-1], rel=1e-8)
        assert result.residual_rms == pytest.approx(np.sqrt(np.mean((W @ xw - y) ** 2)), rel=1e-8)


def write_csv(path, t, rho, F, drop=None):
    cols = ["t"] + [f"rho[{i}]" for i in range(1, 5)] + [f"F[{i}]" for i in range(1, 5)]
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([c for c in cols if c != drop])
        for k in range(len(t)):
            row = [t[k], *rho[k], *F[k]]
            w.writerow([v for c, v in zip(cols, row) if c != drop])


def run_cli(*args, cwd):
    env = {**os.environ, locate.BUILD_ENV: str(locate.build_dir())}
    return subprocess.run([sys.executable, "-m", "pkm4puu", "identify", *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=120)


def test_command_line_identifies_a_csv_log(good, tmp_path):
    write_csv(tmp_path / "log.csv", *good)
    p = run_cli("log.csv", "--model", "friction_velocity=0.005", "--out", "start.json", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "m_platform + payload_mass" in p.stdout and "condition number" in p.stdout
    start = json.loads((tmp_path / "start.json").read_text())
    assert start["m_slider"] == pytest.approx(0.09331, rel=1e-3)


def test_command_line_names_what_is_wrong(good, tmp_path):
    write_csv(tmp_path / "no_f3.csv", *good, drop="F[3]")
    p = run_cli("no_f3.csv", cwd=tmp_path)
    assert p.returncode == 1 and "missing column(s) F[3]" in p.stderr, p.stderr
    p = run_cli("absent.csv", cwd=tmp_path)
    assert p.returncode == 2 and "absent.csv: no such file" in p.stderr, p.stderr
    t, rho, F = (a.copy() for a in good)
    F[77, 0] = np.nan
    write_csv(tmp_path / "nan.csv", t, rho, F)
    p = run_cli("nan.csv", cwd=tmp_path)
    assert p.returncode == 1 and "sample 77" in p.stderr, p.stderr
    p = run_cli("nan.csv", "--model", "screw_lead", cwd=tmp_path)
    assert p.returncode == 2 and "NAME=VALUE" in p.stderr, p.stderr
