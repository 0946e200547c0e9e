# SPDX-License-Identifier: BSD-2-Clause
"""examples/linearize_lqr.py: the plant FMU linearised at home through fmpy's
directional derivatives, its modes against the potential's Hessian, an LQR
designed on A and B, and that LQR against closed_loop_control.py's PD on the
Co-Simulation FMU from a 1 mm offset."""
import math

import numpy as np
import pytest

from pkm4puu import spec
from example_scripts import load_example

ll = load_example("linearize_lqr")


@pytest.fixture(scope="module")
def study(plant_fmu, inverse_fmu):
    return ll.Study(plant_fmu, inverse_fmu).run()


def test_at_rest_the_linearisation_is_a_stiffness(study):
    """At the held equilibrium the rate terms vanish (the velocity forces are
    quadratic in the rates; no friction in the ideal machine) and nothing
    depends on z: A = [[0, I], [-M^-1 K, 0]] with a zero z column."""
    A = study.A
    scale = np.abs(A[4:, :4]).max()
    assert np.abs(study.ydot0).max() <= 1e-9, "the spec's forces do not hold P0"
    assert np.array_equal(A[:4], np.hstack([np.zeros((4, 4)), np.eye(4)]))
    assert np.abs(A[4:, 4:]).max() <= 1e-12 * scale
    assert np.abs(A[4:, 2]).max() <= 1e-12 * scale


def test_hessian_is_the_spec_working_mode(study):
    """docs/model.md "Working mode": elbow-down, the potential's Hessian at home
    has eigenvalues +307, +95, +1.3 and 0 along z (the spec's rounding), and
    the spec's holding forces make P0 an equilibrium (the gradient vanishes
    to the 1e-9 N of the spec's 10 digits)."""
    ev = np.linalg.eigvalsh(study.K_hess)
    print(f"\npotential Hessian eigenvalues: {ev}")
    assert abs(ev[0]) <= 1e-6 * ev[-1]
    assert round(ev[1], 1) == 1.3 and round(ev[2]) == 95 and round(ev[3]) == 307
    h = np.array([1e-6, 1e-6, 1e-6, 1e-5])
    grad = [(ll.potential(spec.P0 + e * hk) - ll.potential(spec.P0 - e * hk)) / (2 * hk) for e, hk in zip(np.eye(4), h)]
    assert np.abs(grad).max() <= 1e-8


def test_eigenfrequencies_are_those_of_the_hessian(study):
    """eig(A) = +-i sqrt(eig(M^-1 K)), K the Hessian of the spec's potential
    (differences over the spec's closed-form inverse kinematics), M from
    Pinocchio: both independent of the FMU. Tolerance 1e-6 relative, the
    issue's bound for the derivatives (the Richardson-extrapolated Hessian
    is good to ~1e-9)."""
    omega, omega_h = study.omega, study.omega_hess
    print(f"\nlinearisation: {omega} rad/s; Hessian: {omega_h} rad/s; "
          f"{omega / (2 * math.pi)} Hz")
    assert len(omega) == 3 and len(omega_h) == 3, "three oscillating modes (x, y, phi) and z neutral"
    np.testing.assert_allclose(omega, omega_h, rtol=1e-6, atol=0)
    assert np.abs(study.eig_open.real).max() <= 1e-9 * omega.max(), "undamped"
    zero = np.sort(np.abs(study.eig_open))[:2]
    assert zero.max() <= 1e-6 * omega.max(), "z: a double zero"


def test_linearisation_predicts_the_nonlinear_plant(study):
    """expm(A t) dy0 against the Co-Simulation FMU over 0.5 s: the error is
    the second-order remainder, so halving dy0 halves the relative error
    (ratio 2; 1 for a wrong A) and it is of the order |dp| / l (27 um / 80 mm
    = 3.4e-4), here required below 1e-3."""
    e1, e2 = study.pred_err
    print(f"\nprediction: relative error {e1:.3e} at dy0, {e2:.3e} at dy0 / 2, ratio {e1 / e2:.3f}")
    assert e1 <= 1e-3
    assert 1.8 <= e1 / e2 <= 2.2


def test_lqr_is_stable_and_faster_than_the_pd(study):
    """The LQR's closed loop on A, B is stable, also sampled at 1 kHz; the
    joint PD, put on the same linearisation, has a slow, lightly damped
    pair (its gains act through the ill-conditioned actuator Jacobian)."""
    print("\n" + ll.summary(study))
    assert study.eig_lqr.real.max() < 0 and study.radius_lqr < 1
    assert study.eig_pd.real.max() < 0 and study.radius_pd < 1
    assert -study.eig_lqr.real.max() > 5 * -study.eig_pd.real.max()


def test_lqr_tracks_better_than_the_pd_from_an_offset(study, results_dir):
    """From the same 1 mm offset, with the same feed-forward, on the plant
    with friction and payload: both loops stay finite and converge; after
    0.5 s (over 9 time constants of the LQR's slowest pole, under one of the
    PD's) the LQR's position error is the smaller, and over the run too."""
    ll.plot(study, results_dir / "test_examples_lqr.png")
    a, b = study.lqr_run, study.pd_run
    assert a.pos_err[0] == pytest.approx(ll.OFFSET, rel=1e-9) and b.pos_err[0] == pytest.approx(ll.OFFSET, rel=1e-9)
    for r in (a, b):
        assert np.all(np.isfinite(r.pose)) and r.pos_err[-1] < 1e-2 * ll.OFFSET
    assert ll.settle_time(study.t_end) == 0.5
    k = ll.after(a, 0.5)
    lqr_max, pd_max = a.pos_err[k:].max(), b.pos_err[k:].max()
    print(f"\nmax |p - p_d| after 0.5 s: LQR {1e3 * lqr_max:.6f} mm, PD {1e3 * pd_max:.6f} mm; "
          f"RMS: LQR {1e3 * ll.rms(a.pos_err):.6f} mm, PD {1e3 * ll.rms(b.pos_err):.6f} mm")
    assert lqr_max < pd_max
    assert ll.rms(a.pos_err) < ll.rms(b.pos_err)


def test_command_line(plant_fmu, tmp_path):
    rc = ll.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--t-end", "0.3"])
    assert rc == 0
    for name in ("linearize_lqr.csv", "linearize_lqr.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    # Both loops start OFFSET off the path along (1, 1, 1)/sqrt 3, phi on it
    # (written to 7 digits).
    table = np.genfromtxt(tmp_path / "linearize_lqr.csv", delimiter=",", names=True)
    for loop in ("lqr", "pd"):
        assert table[f"{loop}_pos_err_m"][0] == pytest.approx(ll.OFFSET, rel=1e-6), loop
        assert table[f"{loop}_phi_err_rad"][0] == 0.0, loop
    assert ll.main(["--build", str(tmp_path / "nowhere"), "--out", str(tmp_path)]) == 1
    assert ll.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--offset", "-1"]) == 2
