# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu.planning's time-optimal traversal: optimal (a limit active on every
grid interval but the switches; the time converging with the grid), within
its limits by an independent recomputation (pkm_inverse_dynamics and
pkm_inverse_dynamics at the planned motion), its coefficients against
finite differences of the inverse dynamics, and its time against two
closed forms: a path limited by the slider speed alone, and a vertical
path where the machine is a one-dimensional double integrator."""
import math

import numpy as np
import pytest

from pkm4puu import capi, spec
from pkm4puu.planning import Limits, arch, plan_cycle, plan_segment
from pkm4puu.planning import segment, topp
from pkm4puu.planning.capi_adapter import InverseDynamics

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


@pytest.fixture(scope="module")
def lib(pkm_library):
    return capi.load(pkm_library)


@pytest.fixture(scope="module")
def cycle():
    """The standard cycle on the default grid."""
    return plan_cycle()


def test_a_limit_is_active_on_every_interval_but_the_switches(cycle):
    """Time-optimal means bang-bang or on the speed limit: on every grid
    interval some |F_i| is at its limit or sd^2 at the slider-speed bound, to
    1e-6 of it (toppra steps each x back by 1e-8 in its scaled time, 1e-10 of
    x there), except on the lone intervals where sdd switches from
    accelerating to braking, which the grid cannot place exactly."""
    for seg in cycle.segments:
        active = seg.active(1e-6)
        free = np.flatnonzero(active == "")
        assert 1 <= len(free) <= 3, (seg.name, free)
        for i in free:
            assert 0 < i < len(active) - 1 and active[i - 1] and active[i + 1], (seg.name, i)
            assert seg.u[i - 1] > seg.u[i] > seg.u[i + 1], (seg.name, i, seg.u[i - 1:i + 2])
        # from rest and into rest sd^2 = 0 is far from the speed bound: a force limit acts
        assert "force" in active[0] and "force" in active[-1]
        # the bound the plan kept is the one it records: the fastest slider at v_lim where x = x_max
        assert np.all(seg.x <= seg.x_max)
        np.testing.assert_allclose(np.abs(seg.drho_ds).max(axis=1) * np.sqrt(seg.x_max), seg.speed_limit, rtol=1e-15)


def test_time_converges_first_order_with_the_grid():
    """The grid's constant sdd per interval costs time in proportion to the
    interval: the differences between successive halvings of ds halve too
    (ratio 2 within 15 %), the plan's time falls to its limit from above
    (the force bound is imposed at both ends of each interval), and the
    default grid's time is within 0.1 % of the Richardson extrapolate of
    the two finest."""
    path = arch()
    grids = (500, 1000, 2000, 4000)
    T = np.array([plan_segment(path, spec.CYCLE_PAYLOAD, grid=n, dt=1e-2).duration for n in grids])
    d = -np.diff(T)
    print(f"\nA -> B time on grids {grids}: {', '.join(f'{t:.7f}' for t in T)} s; successive differences "
          f"{', '.join(f'{x:.2e}' for x in d)} s")
    assert np.all(d > 0)
    np.testing.assert_allclose(d[:-1] / d[1:], 2.0, rtol=0.15)
    limit = 2 * T[-1] - T[-2]
    default = T[grids.index(segment.GRID)]
    print(f"extrapolated {limit:.7f} s; the default grid {segment.GRID} is {100 * (default / limit - 1):.3f} % above")
    assert 0 < default / limit - 1 < 1e-3


def test_recomputed_forces_and_speeds_stay_within_the_limits(cycle, lib):
    """Along the plan, sampled every 0.1 ms, the forces from
    pkm_inverse_dynamics and the slider rates from
    pkm_inverse_dynamics (not the planner's pkm_regressor_poses) at the
    planned pose, velocity and acceleration stay within f_max and v_max up
    to the grid's interpolation error, which is second order: at most twice
    the excess of a grid 4 times coarser, divided by 16."""
    coarse = plan_cycle(grid=segment.GRID // 4, dt=1e-3)
    zero = np.zeros(4)
    for seg, rough in zip(cycle.segments, coarse.segments):
        with capi.Plant(lib, payload_mass=seg.payload_mass) as plant:
            F = np.array([plant.inverse_dynamics(p, v, a).F
                          for p, v, a in zip(seg.pose, seg.velocity, seg.acceleration)])
            drho = np.array([plant.inverse_dynamics(p, v, zero).qd[0:12:3] for p, v in zip(seg.pose, seg.velocity)])
        np.testing.assert_allclose(seg.F, F, rtol=0, atol=1e-11)
        np.testing.assert_allclose(seg.drho, drho, rtol=0, atol=1e-13)
        allowed = 2 * max(max(rough.excess()) - 1, 0) / 16
        over_f, over_v = np.abs(F).max() / spec.CYCLE_F_MAX - 1, np.abs(drho).max() / spec.CYCLE_V_MAX - 1
        print(f"\n{seg.name}: max |F| - f_max = {over_f * spec.CYCLE_F_MAX:.2e} N, max |drho| - v_max = "
              f"{over_v * spec.CYCLE_V_MAX:.2e} m/s; allowed {allowed:.1e} of the limit")
        assert over_f <= allowed and over_v <= allowed
        # both limits are used: the plan is not merely feasible
        assert over_f > -1e-3 and over_v > -1e-3


def test_samples_are_one_motion(cycle):
    """The samples' velocity is the pose's rate: a central difference over
    h differs from it by at most h/2 max|acceleration| (the acceleration is
    bounded; it jumps between grid intervals). The plan starts and ends at
    rest at A and B."""
    for seg in cycle.segments:
        h = seg.t[1] - seg.t[0]
        inner = np.flatnonzero(np.abs(np.diff(seg.t) - h) < 1e-12)[:-1]  # uniformly spaced neighbours
        inner = inner[np.abs(seg.t[inner + 2] - seg.t[inner + 1] - h) < 1e-12] + 1
        cd = (seg.pose[inner + 1] - seg.pose[inner - 1]) / (2 * h)
        bound = h / 2 * np.abs(seg.acceleration).max(axis=0) + 1e-12
        assert np.all(np.abs(cd - seg.velocity[inner]) <= bound)
        assert np.all(seg.velocity[[0, -1]] == 0)
    a = arch()
    np.testing.assert_allclose(cycle.segments[0].pose[[0, -1]], a(np.array([0.0, 1.0])), atol=1e-15)
    np.testing.assert_allclose(cycle.segments[1].pose[[0, -1]], a(np.array([1.0, 0.0])), atol=1e-15)


def test_coefficients_match_finite_differences_of_the_inverse_dynamics(lib):
    """F = a sdd + b sd^2 + c along a time law s(t) = s0 + w t + k t^2, with
    the platform's velocity and acceleration from central differences of
    the pose p(s(t)) in time (not from p'(s), p''(s)) and the forces from
    pkm_inverse_dynamics. The differences' error is estimated by
    halving their step (it falls 4-fold): the planner's forces must agree
    within it."""
    path = arch()
    s0, w, k = 0.3, 4.0, 15.0
    times = np.array([0.0, 0.01, 0.02])
    s = s0 + w * times + k * times ** 2
    sd, sdd = w + 2 * k * times, 2 * k
    with InverseDynamics(0.25) as dyn:
        a, b, c, _ = topp.path_coefficients(dyn, path, s)
    planned = a * sdd + b * sd[:, None] ** 2 + c

    def fd(step):
        out = []
        with capi.Plant(lib, payload_mass=0.25) as plant:
            for t in times:
                p = path(s0 + w * (t + np.array([-step, 0.0, step])) + k * (t + np.array([-step, 0.0, step])) ** 2)
                v, acc = (p[2] - p[0]) / (2 * step), (p[2] - 2 * p[1] + p[0]) / step ** 2
                out.append(plant.inverse_dynamics(p[1], v, acc).F)
        return np.array(out)

    coarse, fine = fd(2e-4), fd(1e-4)
    err = np.abs(fine - coarse).max()
    print(f"\n|a sdd + b sd^2 + c - F(finite differences)| = {np.abs(planned - fine).max():.2e} N "
          f"(difference error {err:.1e} N; the dynamic part {np.abs(planned - c).max():.2f} N)")
    assert np.abs(planned - c).max() > 1.0  # the motion is not quasi-static
    assert np.abs(planned - fine).max() <= err


def test_speed_limited_time_is_the_integral_of_the_speed_limit():
    """With the force limit out of the way (1e5 N) the plan rides the
    slider-speed limit: T = integral of max_i |drho_i/ds| ds / v_max, with
    drho/ds from the spec's closed-form inverse kinematics (differences on
    a fine grid), plus what the grid's first and last interval cost at rest
    (2 ds / sd instead of ds / sd, sd = v_max / (pi h) at A and B where only
    z moves): the remainder is second order, below 1e-5 T. (The quadrature
    on 5001 points is second order too: 1.4e-7 T from 100001 points'.)"""
    path = arch()
    s = np.linspace(0.0, 1.0, 5001)
    rho = np.array([spec.leg_inverse_kinematics(p)[:, 0] for p in path(s)])
    integral = np.trapezoid(np.abs(np.gradient(rho, s, axis=0, edge_order=2)).max(axis=1), s) / spec.CYCLE_V_MAX
    seg = plan_segment(path, spec.CYCLE_PAYLOAD, Limits(1e5, spec.CYCLE_V_MAX), dt=1e-2)
    ends = 2 * (1.0 / segment.GRID) * math.pi * spec.CYCLE_H / spec.CYCLE_V_MAX
    print(f"\nspeed-limited: planned {seg.duration:.7f} s, integral {integral:.7f} s + the ends {ends:.2e} s")
    assert seg.active_share()["speed"] > 0.99
    assert abs(seg.duration - (integral + ends)) < 1e-5 * integral


def test_vertical_arch_is_the_one_dimensional_bang_bang():
    """a = theta = 0: P goes up h and back down at x = y = phi = 0, where
    every body translates with z and the four legs share alike:
    F_i = m (z'' + g) / 4, m the spec's moving mass and the payload, and
    drho_i/dt = dz/dt. Up: accelerate at 4 f_max / m - g, brake at
    4 f_max / m + g, coasting at v_max if reached; down the mirror image.
    The grid's error is first order (halving it halves the error) and
    below 1e-4 here."""
    m = spec.M_PLATFORM + spec.CYCLE_PAYLOAD + 4 * (spec.M_SLIDER + spec.M_ROD)
    f, v, h = spec.CYCLE_F_MAX, spec.CYCLE_V_MAX, spec.CYCLE_H
    up, down = 4 * f / m - spec.G, 4 * f / m + spec.G
    peak = math.sqrt(2 * h * up * down / (up + down))
    half = v / (2 * up) + v / (2 * down) + h / v if peak > v else peak / up + peak / down
    err = []
    for n in (segment.GRID // 2, segment.GRID):
        seg = plan_segment(arch(0.0, h, spec.CYCLE_Z0, 0.0), spec.CYCLE_PAYLOAD, grid=n, dt=1e-3)
        err.append(seg.duration / (2 * half) - 1)
        np.testing.assert_allclose(seg.F, seg.F[:, :1].repeat(4, axis=1), rtol=0, atol=1e-12)
    print(f"\nvertical arch: closed form {2 * half:.7f} s, planned {seg.duration:.7f} s; relative errors {err}")
    assert 0 < err[1] < 1e-4
    assert err[0] / err[1] == pytest.approx(2.0, rel=0.1)


def test_friction_is_allowed_for_and_checked():
    """Friction (Coulomb F_c, viscous b) is taken off the force limit as its
    bound b v_max + F_c: the friction-free forces on the grid stay within
    f_max less it; the forces with friction, recomputed along the samples,
    within f_max; the plan takes longer than without friction."""
    machine = {"friction_coulomb": 0.2, "friction_viscous": 1.0}
    bound = 0.2 + 1.0 * spec.CYCLE_V_MAX
    cyc = plan_cycle(machine=machine, grid=1000, dt=1e-3)
    free = plan_cycle(grid=1000, dt=1e-3)
    for seg, ideal in zip(cyc.segments, free.segments):
        assert seg.friction_bound == pytest.approx(bound, rel=1e-15)
        start, end = seg.grid_forces()
        assert np.abs(np.concatenate([start, end])).max() <= (spec.CYCLE_F_MAX - bound) * (1 + 1e-9)
        assert np.abs(seg.F).max() <= spec.CYCLE_F_MAX
        assert seg.duration > ideal.duration


def test_drive_and_friction_parameters_act_through_params_as_through_machine():
    """Every parameter goes by its FMU name through either dict: the screw
    lead (the motor limits through the screw) and friction (its bound taken
    off the force limit) given in params plan what they plan in machine."""
    drive = {"screw_lead": 0.005, "friction_coulomb": 0.5, "friction_viscous": 1.0}
    limits = Limits(100.0, 100.0, torque_max=0.008, motor_speed_max=400.0)
    common = dict(payload_mass=0.1, limits=limits, grid=500, dt=1e-2)
    by_machine = plan_segment(arch(), machine=drive, **common)
    by_params = plan_segment(arch(), params=drive, **common)
    v_lim = 0.005 * 400.0 / (2 * math.pi)  # the motor speed through the screw
    assert by_params.friction_bound == by_machine.friction_bound == pytest.approx(0.5 + 1.0 * v_lim)
    assert by_params.force_limit == by_machine.force_limit == pytest.approx(2 * math.pi * 0.008 / 0.005)
    assert by_params.duration == by_machine.duration
    np.testing.assert_array_equal(by_params.F, by_machine.F)


def test_drive_limits_act_through_the_screw():
    """A motor torque limit tau is the force limit 2 pi tau / p and a motor
    speed limit omega the slider-speed limit p omega / (2 pi): the same plan
    to rounding. Rotor inertia J adds J (2 pi / p)^2 rho_i'' to F_i, i.e.
    J (2 pi / p)^2 drho_i/ds to a_i and nothing to c."""
    p, J = 0.005, 2e-7
    path = arch()
    by_force = plan_segment(path, 0.1, Limits(2 * math.pi * 0.006 / p, p * 400.0 / (2 * math.pi)),
                            machine={"screw_lead": p}, grid=500, dt=1e-2)
    by_motor = plan_segment(path, 0.1, Limits(100.0, 100.0, torque_max=0.006, motor_speed_max=400.0),
                            machine={"screw_lead": p}, grid=500, dt=1e-2)
    assert by_motor.duration == pytest.approx(by_force.duration, rel=1e-12)
    assert "torque_max" in by_motor.force_limit_source and "motor_speed_max" in by_motor.speed_limit_source
    s = np.linspace(0.0, 1.0, 51)
    with InverseDynamics(0.1, {"screw_lead": p}) as bare, InverseDynamics(0.1, {"screw_lead": p, "rotor_inertia": J}) as rotor:
        a0, b0, c0, drho_ds = topp.path_coefficients(bare, path, s)
        a1, b1, c1, _ = topp.path_coefficients(rotor, path, s)
    np.testing.assert_allclose(a1 - a0, J * (2 * math.pi / p) ** 2 * drho_ds, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(c1, c0, rtol=0, atol=1e-12)
