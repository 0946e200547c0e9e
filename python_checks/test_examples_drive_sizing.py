# SPDX-License-Identifier: BSD-2-Clause
"""examples/drive_sizing.py: motor torques and speeds from the inverse FMU
along the auto-test with rotor inertia, friction and a payload."""
import math

import numpy as np
import pytest

from pkm4puu.fmu import Fmu
from pkm4puu.interface import START_P0, indexed_names
from pkm4puu.motions import autotest_motion
from pkm4puu.spec import BETA, G, H_PRIME, L, TOTAL_WEIGHT, base_point, platform_point, rz
from example_scripts import load_example

ds = load_example("drive_sizing")

M = ds.MACHINE
P = M["screw_lead"]


@pytest.fixture(scope="module")
def profile(inverse_fmu):
    return ds.drive_profile(inverse_fmu)


def test_torque_is_force_through_the_screw(profile):
    """tau = F p / (2 pi), the lossless screw, to rounding (tau ~ 3e-3 N m)."""
    np.testing.assert_allclose(profile.tau, profile.F * P / (2 * math.pi), rtol=0, atol=1e-17)


def test_at_rest_the_motors_hold_the_weight(profile, plant_fmu):
    """At t = 0 nothing moves, so friction (an odd function of drho) and the
    inertia vanish: each motor holds the plant's holding force F_hold at P0
    through the screw, and the four forces sum to the machine's and the
    payload's weight (all actuator axes are vertical)."""
    with Fmu(plant_fmu, start={**START_P0, **M}) as plant:
        f_hold = plant.get(indexed_names("F_hold", 4))
    np.testing.assert_allclose(profile.tau[0], f_hold * P / (2 * math.pi), rtol=0, atol=1e-14)
    assert profile.F[0].sum() == pytest.approx(TOTAL_WEIGHT + M["payload_mass"] * G, rel=1e-12)


def actuator_rates(pose, vel):
    """drho_i/dt of the spec's closed-form leg inverse kinematics, by hand:
    q~ = Rz(beta)^T (p + Rz(phi) r_Q - B), A = sqrt(q~x^2 + q~y^2 - h'^2),
    rho = q~z - h - l sin(theta2) with l sin(theta2) = -sqrt(l^2 - A^2), so
    drho = dq~z - A dA / sqrt(l^2 - A^2), A dA = q~x dq~x + q~y dq~y."""
    out = np.empty(4)
    for i in range(4):
        rb = rz(BETA[i]).T
        rq = rz(pose[3]) @ platform_point(i)
        q = rb @ (pose[:3] + rq - base_point(i))
        dq = rb @ (vel[:3] + vel[3] * np.array([-rq[1], rq[0], 0.0]))
        a = math.sqrt(q[0] ** 2 + q[1] ** 2 - H_PRIME ** 2)
        out[i] = dq[2] - (q[0] * dq[0] + q[1] * dq[1]) / math.sqrt(L ** 2 - a ** 2)
    return out


def test_speed_is_the_screw_turning_the_actuator_rate(profile):
    """omega = 2 pi drho / p with drho the spec's: the closed-form inverse
    kinematics differentiated along the auto-test's prescribed motion, to
    rounding (64 eps of the largest rate: the closed form's few dozen
    operations, the FMU's solve at a condition number below 26). Also drho
    against a central difference of the FMU's rho: its error is
    h^2/6 max |rho'''|, rho''' estimated by the second difference of drho
    (a factor 2 to spare)."""
    h = profile.t[1] - profile.t[0]
    drho_fd = (profile.rho[2:] - profile.rho[:-2]) / (2 * h)
    rho3 = np.abs(np.diff(profile.drho, 2, axis=0)).max() / h ** 2
    tol = 2 * h ** 2 / 6 * rho3
    assert np.abs(drho_fd - profile.drho[1:-1]).max() <= tol
    drho = np.array([actuator_rates(*autotest_motion(t)[:2]) for t in profile.t])
    gear = 2 * math.pi / P
    worst = np.abs(profile.omega - gear * drho).max()
    print(f"\nomega against 2 pi / p times the spec's drho (up to {gear * np.abs(drho).max():.1f} rad/s): "
          f"within {worst:.2g} rad/s")
    assert worst <= gear * 64 * np.finfo(float).eps * np.abs(drho).max()
    assert profile.max_speed.max() > 0


def test_rotor_torque_is_inertia_times_angular_acceleration(profile, inverse_fmu):
    """Rotor inertia adds J (2 pi/p)^2 rho'' to F, i.e. J omega' to tau
    exactly (the path is prescribed); omega' from a central difference of
    omega, error h^2/6 max |omega'''| (estimated by differences, x2)."""
    bare = ds.drive_profile(inverse_fmu, {**M, "rotor_inertia": 0.0})
    h = profile.t[1] - profile.t[0]
    w = profile.omega
    dw = (w[2:] - w[:-2]) / (2 * h)
    w3 = np.abs(np.diff(w, 3, axis=0)).max() / h ** 3
    tol = M["rotor_inertia"] * 2 * h ** 2 / 6 * w3 + 1e-15
    rotor = (profile.tau - bare.tau)[1:-1]
    print(f"\nrotor torque up to {np.abs(rotor).max():.3e} N m, J omega' within {np.abs(rotor - M['rotor_inertia'] * dw).max():.2e} (tol {tol:.2e})")
    assert np.abs(rotor).max() > 100 * tol  # it is there
    assert np.abs(rotor - M["rotor_inertia"] * dw).max() <= tol


def test_rms_and_envelope(profile):
    """The RMS lies between the smallest and the largest |tau|; a constant
    torque has itself as RMS; the envelope is continuous at the corner speed
    and zero past the maximum speed."""
    assert np.all(np.abs(profile.tau).min(axis=0) <= profile.rms) and np.all(profile.rms <= profile.peak)
    flat = ds.DriveProfile(1.0, profile.t, profile.F, np.full_like(profile.tau, 2e-3), profile.rho, profile.drho, P)
    np.testing.assert_allclose(flat.rms, 2e-3, rtol=1e-12)
    m = ds.MOTOR
    assert m.torque_limit(m.corner_speed * (1 + 1e-12)) == pytest.approx(m.peak_torque, rel=1e-9)
    assert m.torque_limit(-0.5 * m.corner_speed) == m.peak_torque
    assert m.torque_limit(1.01 * m.max_speed) == 0.0


def test_command_line(inverse_fmu, tmp_path):
    rc = ds.main(["--build", str(inverse_fmu.parent), "--out", str(tmp_path), "--durations", "2", "0.5"])
    assert rc == 0
    for name in ("drive_sizing.csv", "drive_sizing.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    # Each move starts and ends at rest: the written torques at its start hold
    # the machine's and the payload's weight through the screw, the speeds
    # at both ends are 0 (written to 10 digits).
    table = np.genfromtxt(tmp_path / "drive_sizing.csv", delimiter=",", names=True)
    assert sorted(set(table["T_s"])) == [0.5, 2.0]
    for T in (0.5, 2.0):
        move = table[table["T_s"] == T]
        tau = np.column_stack([move[f"tau{i}_Nm"] for i in range(1, 5)])
        omega = np.column_stack([move[f"omega{i}_rad_s"] for i in range(1, 5)])
        hold = (TOTAL_WEIGHT + M["payload_mass"] * G) * P / (2 * math.pi)
        assert tau[0].sum() == pytest.approx(hold, rel=1e-9), (T, tau[0].sum(), hold)
        assert np.abs(omega[[0, -1]]).max() <= 1e-9, (T, omega[[0, -1]])
    assert ds.main(["--build", str(tmp_path / "nowhere"), "--out", str(tmp_path)]) == 1
    assert ds.main(["--build", str(inverse_fmu.parent), "--out", str(tmp_path), "--durations", "0"]) == 2
