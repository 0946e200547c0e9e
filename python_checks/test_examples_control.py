# SPDX-License-Identifier: BSD-2-Clause
"""examples/closed_loop_control.py: the plant FMU with joint friction and an
off-centre payload in a 1 kHz joint-space PD loop, with the inverse FMU's
computed-force feed-forward given the plant's friction (compensation), not
given it, and without feed-forward at all."""

import numpy as np
import pytest

from pkm4puu.spec import G, TOTAL_WEIGHT, vertical_momentum as spec_momentum
from example_scripts import load_example

clc = load_example("closed_loop_control")

PARAMS = clc.machine()


@pytest.fixture(scope="module")
def runs(plant_fmu, inverse_fmu):
    return clc.compare(plant_fmu, inverse_fmu, plant_machine=PARAMS)


def vertical_momentum(drho, dz):
    """The machine's vertical momentum (kg m/s), the payload's included."""
    return spec_momentum(drho, dz, payload_mass=PARAMS["payload_mass"])


def test_friction_compensation_cuts_the_rms_error(runs, results_dir):
    runs, ratio = runs
    ff, nofric, pd = (runs[m] for m in clc.MODES)
    print("\n" + clc.summary(runs, ratio, PARAMS))
    clc.plot(runs, ratio, PARAMS, results_dir / "test_examples_closed_loop.png")
    for r in runs.values():
        assert np.all(np.isfinite(r.rho)) and np.all(np.isfinite(r.pose))
    # PD alone is stable and tracks roughly: ~1.2 mm while carrying ~2.9 N per actuator at Kp = 2500 N/m.
    assert np.abs(pd.e_rho).max() < 3e-3, "PD only drifted away"
    assert pd.rms > nofric.rms > ff.rms
    assert ratio >= clc.MIN_RATIO, (f"friction compensation cut the RMS error only by {ratio:.2f} "
                                    f"({1e3 * nofric.rms:.6f} mm -> {1e3 * ff.rms:.6f} mm)")


def test_compensation_is_the_spec_friction_along_the_desired_motion(runs):
    """The two feed-forwards differ only by the inverse FMU's friction
    parameters, so their difference is docs/model.md's friction law at the
    desired rates, b drho_d + F_c tanh(drho_d / v_s), to rounding."""
    runs, _ = runs
    ff, nofric = runs["ff"], runs["ff_nofric"]
    diff = (ff.F_ff - nofric.F_ff)[:-1]
    expected = clc.friction(PARAMS, ff.drho_d[:-1])
    print(f"\nfriction compensation: up to {np.abs(expected).max():.4f} N, "
          f"against the spec's law within {np.abs(diff - expected).max():.2e} N")
    assert np.abs(expected).max() > PARAMS["friction_coulomb"]  # it is there
    np.testing.assert_allclose(diff, expected, rtol=0, atol=1e-12)


def test_without_compensation_the_pd_carries_the_friction(runs):
    """All four actuator axes are vertical, so the forces on the sliders
    change the machine's vertical momentum P: dP/dt = sum F - weight -
    sum friction. The feed-forward without friction gives sum F_ff = weight
    + dP_d/dt along the desired motion; so over a window [t0, t1]
        mean(sum F_pd) - mean(sum friction) = [(P - P_d)(t1) - (P - P_d)(t0)] / (t1 - t0),
    at most 2 max|P - P_d| / (t1 - t0): the PD carries the friction that the
    feed-forward left out, to within the momentum by which the loop lags
    (the remaining 1e-4 N is the ~1 ms relaxation of the regularised
    friction after each zero-order-hold step, inside the bound)."""
    runs, _ = runs
    r = runs["ff_nofric"]
    k0, k1 = np.searchsorted(r.t, [0.25, 1.75])  # the move, past the starts and stops of the sliders
    h = r.t[1] - r.t[0]
    fric = clc.friction(PARAMS, r.drho).sum(axis=1)
    carried = r.F_pd[k0:k1].sum(axis=1).mean()
    friction = 0.5 * (fric[k0:k1] + fric[k0 + 1:k1 + 1]).mean()  # over each held step
    lag = vertical_momentum(r.drho, r.dpose[:, 2]) - vertical_momentum(r.drho_d, r.dpose_d[:, 2])
    bound = 2 * np.abs(lag[k0:k1 + 1]).max() / ((k1 - k0) * h)
    print(f"\nwithout compensation the PD carries {carried:.6f} N on average, the friction is "
          f"{friction:.6f} N (bound {bound:.2e} N)")
    assert friction > PARAMS["friction_coulomb"]
    assert abs(carried - friction) <= bound


def test_settled_pd_force_carries_exactly_what_the_feed_forward_left_out(runs):
    """At rest after the motion the feed-forward with the payload supplies
    the weight, so its PD carries only the friction; PD only carries the
    machine's weight and the payload's as well. Exactly, over the last held
    step [t_k, t_k+1] (vertical momentum P, docs/model.md "Bodies"):
        sum F_pd = expected weight + mean friction + (P(t_k+1) - P(t_k)) / h,
    the friction's mean over the step within |f(t_k+1) - f(t_k)| of its
    value at t_k (it changes monotonically as the loop settles)."""
    runs, _ = runs
    w = TOTAL_WEIGHT + PARAMS["payload_mass"] * G
    for mode, expected_weight in (("ff", 0.0), ("ff_nofric", 0.0), ("pd", w)):
        r = runs[mode]
        k = len(r.t) - 2  # the last step's force
        h = r.t[k + 1] - r.t[k]
        carried = r.F_pd[k].sum()
        fric = clc.friction(PARAMS, r.drho[k:k + 2]).sum(axis=1)
        momentum = vertical_momentum(r.drho[k:k + 2], r.dpose[k:k + 2, 2])
        expected = expected_weight + fric[0] + (momentum[1] - momentum[0]) / h
        bound = abs(fric[1] - fric[0]) + 1e-12 * w
        print(f"\n{mode}: settled sum F_pd = {carried:.9f} N, expected {expected:.9f} N (bound {bound:.1e} N)")
        assert abs(carried - expected) <= bound


def test_compensated_error_is_the_zero_order_hold(runs):
    """With the plant's own machine in the feed-forward, what is left is the
    zero-order hold: F_ff is held over each step while the needed force moves
    on by up to the largest per-step change of F_ff; the PD answers a force
    error dF with dF / Kp, so max |e| <= max |dF_ff per step| / Kp (the mean
    lag is half a step: a factor 2 to spare)."""
    runs, _ = runs
    r = runs["ff"]
    dF = np.abs(np.diff(r.F_ff[:-1], axis=0)).max()
    e = np.abs(r.e_rho).max()
    print(f"\ncompensated: max |e| = {e:.3e} m, max |dF_ff| / Kp = {dF / clc.KP:.3e} m")
    assert e <= dF / clc.KP


def test_command_line(plant_fmu, tmp_path):
    rc = clc.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--t-end", "0.5"])
    assert rc == 0
    for name in ("closed_loop.csv", "closed_loop_tracking.png", "closed_loop_run.csv"):
        assert (tmp_path / name).stat().st_size > 0, name
    # At t = 0 the desired motion is at rest at P0 (no friction at rest): the
    # written feed-forward carries the machine's and the payload's weight.
    table = np.genfromtxt(tmp_path / "closed_loop.csv", delimiter=",", names=True)
    first = sum(table[f"F_ff{i}_N"][0] for i in range(1, 5))
    assert abs(first - (TOTAL_WEIGHT + PARAMS["payload_mass"] * G)) <= 4 * 5e-10, first  # written to 1e-9 N
    assert clc.main(["--build", str(tmp_path / "nowhere"), "--out", str(tmp_path)]) == 1
    assert clc.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--coulomb", "-1"]) == 2
