# SPDX-License-Identifier: BSD-2-Clause
"""Model Exchange through an importer's own integrator (fmpy's CVode), FMI 2.0
and FMI 3.0: the paper's auto-test against the Co-Simulation FMU, and the
singularity guards as event indicators that the importer locates.

The forces are the auto-test's, from the inverse FMU, held over each 1 ms
interval at their midpoint value: a piecewise-constant signal that fmpy and
the Co-Simulation FMU both apply exactly (fmpy's CVode applies inputs only at
its root-function calls and communication points, not in the right-hand
side, so a continuously interpolated input would be integrated as a staircase
of fmpy's choosing; the jumps at the 2,000 interval boundaries are input
events, where fmpy restarts CVode). Both runs then integrate the same ODE,
and their difference is integrator error only.

Not passed to simulate_fmu: `logger=`. fmpy's logging proxy keeps the last
logger it was given in one global, which simulate_fmu frees when it returns;
the next FMU that logs through fmpy's default callbacks then calls freed
memory (a crash in fmpy 0.3.32, not in the FMU). The log is read from fmpy's
default logger, which prints, instead.
"""
import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

from pkm4puu.fmu import Fmu, inverse_forces, run
from pkm4puu.interface import indexed_names, F, POSE
from pkm4puu.motions import pose_at
from pkm4puu.spec import P0, STATIC_FORCE_P0, T_MOVE

H = 1e-3  # s, the interval of the held forces and the communication step
N = round(T_MOVE / H)
START = {"x0": P0[0], "y0": P0[1], "z0": P0[2], "phi0": P0[3]}
WRENCH = ["Fe[1]", "Fe[2]", "Fe[3]", "Me_z"]
TOL = 1e-8  # m and rad: Model Exchange against Co-Simulation
TOL_PATH = 5e-8  # m and rad: either against the prescribed path (test_fmu_autotest)


# --- fmpy with its defaults ------------------------------------------------------
# fmpy's CVode takes its last internal step past stopTime, evaluates the
# derivatives and event indicators there, and interpolates back to its last
# output point: trial evaluations, which the FMU answers (docs/importers.md,
# "stopTime"). Its defaults define stopTime (the DefaultExperiment's), so a
# refusal shows here: an exception, or (inside CVode's right-hand side, where
# ctypes swallows it) an unraisable exception, an error by conftest.py.
ARCHIVES = ["plant_fmu", "plant_fmu3", "inverse_fmu", "inverse_fmu3"]
REPEAT = 5  # the FMU must not depend on what an earlier run in the process left
STILL = 1e-9  # m: the plant at its defaults (static forces at the home pose) holds still


@pytest.mark.parametrize("interface", ["CoSimulation", "ModelExchange"])
@pytest.mark.parametrize("archive", ARCHIVES)
def test_fmpy_defaults_complete(archive, interface, request, capfd):
    path = str(request.getfixturevalue(archive))
    md = read_model_description(path)
    start = {v.name: float(v.start) for v in md.modelVariables if v.name in ("x0", "y0", "z0")}
    for _ in range(REPEAT):
        r = simulate_fmu(path, fmi_type=interface, solver="CVode")
        assert r["time"][-1] == pytest.approx(float(md.defaultExperiment.stopTime), abs=1e-12)
        assert all(np.isfinite(r[n]).all() for n in r.dtype.names)
        if archive.startswith("plant"):
            assert len(start) == 3, "the plant's start pose parameters"
            moved = max(np.abs(r[n] - start[n + "0"]).max() for n in ("x", "y", "z"))
            assert moved < STILL, f"the plant at its defaults moved {moved:.3g} m"
    log = "".join(capfd.readouterr())
    assert "[ERROR]" not in log, log[-2000:]


@pytest.fixture(scope="module")
def midpoint_forces(inverse_fmu):
    """F1..F4 at the midpoint of every 1 ms interval of the auto-test."""
    with Fmu(inverse_fmu) as inv:
        return inverse_forces(inv, (np.arange(N) + 0.5) * H)


def staircase(forces):
    """fmpy's input table for forces held over [k h, (k+1) h): every boundary
    time appears twice (left value, right value), which fmpy treats as an
    input event. The wrench is zero."""
    times = np.repeat(np.arange(N + 1) * H, 2)[1:-1]
    signal = np.zeros(len(times), dtype=[("time", float)] + [(n, float) for n in F + WRENCH])
    signal["time"] = times
    held = np.repeat(forces, 2, axis=0)
    for i, name in enumerate(F):
        signal[name] = held[:, i]
    return signal


@pytest.fixture(scope="module")
def co_simulation(plant_fmu, midpoint_forces):
    """The Co-Simulation FMU (its CVODE at rtol 1e-10) driven by the same held
    forces: (t, pose) at every communication point."""
    def hold(fmu, k, t):
        fmu.set(F, midpoint_forces[k])

    with Fmu(plant_fmu, start=dict(START, rtol=1e-10, atol=1e-12)) as fmu:
        return run(fmu, 0.0, H, N, hold, POSE)


def model_exchange(path, forces, rtol):
    r = simulate_fmu(str(path), fmi_type="ModelExchange", solver="CVode", relative_tolerance=rtol, stop_time=T_MOVE,
                     output_interval=H, input=staircase(forces), start_values=START, output=POSE,
                     record_events=False)
    return r["time"], np.array([[row[n] for n in POSE] for row in r])


@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
def test_model_exchange_auto_test_converges_to_co_simulation(archive, request, midpoint_forces, co_simulation):
    """fmpy's CVode (absolute tolerance rtol x the declared nominals) restarts
    at each of the 2,000 input events. At rtol 1e-10 it must reproduce the
    Co-Simulation result to 1e-8 m / 1e-8 rad, and the difference
    must shrink at least tenfold when rtol is a hundred times tighter: it is
    the importer's integration error, not a model difference."""
    t_cs, cs = co_simulation
    ref = np.array([pose_at(t) for t in t_cs])
    cs_path = np.abs(cs - ref).max(axis=0)
    assert cs_path[:3].max() < TOL_PATH and cs_path[3] < TOL_PATH
    err = {}
    for rtol in (1e-10, 1e-12):  # two decades: the assertions below compare these two
        t_me, me = model_exchange(request.getfixturevalue(archive), midpoint_forces, rtol)
        assert np.array_equal(t_me, t_cs), "fmpy's output grid must be the communication grid"
        d = np.abs(me - cs).max(axis=0)
        err[rtol] = (d[:3].max(), d[3])
        print(f"\n{archive}: fmpy CVode rtol {rtol:.0e}: |ME - CS| {d[:3].max():.3g} m, {d[3]:.3g} rad")
    assert err[1e-10][0] < TOL and err[1e-10][1] < TOL, f"ME vs CS at rtol 1e-10: {err[1e-10]}"
    for k in (0, 1):
        assert err[1e-12][k] < err[1e-10][k] / 10, f"no convergence with the importer's tolerance: {err}"


# --- the singularity guards as event indicators ---------------------------------
# Each case drives the platform towards a guard that a parameter tightens, so
# that it is reached within a fraction of a second from the home pose (the
# defaults are far outside the workspace the auto-test uses):
#   condition: a moment about z turns the platform until the actuator
#              Jacobian's condition number reaches max_jacobian_condition = 20;
#   leg:       a force along x pushes it until a leg's |cos th2 sin th2|
#              falls to min_leg_measure = 0.48.
HOLD = {name: STATIC_FORCE_P0 for name in F}
GUARDS = {
    "condition": ({"max_jacobian_condition": 20.0}, {"Me_z": 0.05}),
    "leg": ({"min_leg_measure": 0.48}, {"Fe[1]": 1.0}),
}
INDICATORS = ["guard_condition_margin"] + indexed_names("guard_leg_margin", 4)
THETA2 = indexed_names("theta2", 4)


def guard_measure(case, row):
    """The guarded quantity from the FMU's ordinary outputs (not from its
    indicators): the condition number, or the smallest |cos th2 sin th2|."""
    if case == "condition":
        return row["jacobian_condition"]
    return min(abs(np.cos(row[n]) * np.sin(row[n])) for n in THETA2)


@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
@pytest.mark.parametrize("case", list(GUARDS))
def test_guard_crossing_is_an_event_the_importer_locates(case, archive, request, capfd):
    parameters, push = GUARDS[case]
    limit = next(iter(parameters.values()))
    r = simulate_fmu(str(request.getfixturevalue(archive)), fmi_type="ModelExchange", solver="CVode",
                     relative_tolerance=1e-10, stop_time=2.0,
                     output_interval=H, start_values={**parameters, **HOLD, **push}, debug_logging=True,
                     output=INDICATORS + THETA2 + ["jacobian_condition"])
    log = capfd.readouterr().out
    t_event = r["time"][-1]
    assert t_event < 1.0, f"the {case} guard was not reached: the run ended at t = {t_event}"
    z = np.array([[row[n] for n in INDICATORS] for row in r])
    crossed = int(np.argmin(np.abs(z[-1])))
    # Before the event every indicator is positive; at it, the crossed one is
    # zero to the root finder's accuracy, and the guarded quantity is at its limit.
    assert (z[:-1] > 0).all(), f"an indicator was not positive before the event:\n{z[:-1].min(axis=0)}"
    assert abs(z[-1, crossed]) < 1e-9, f"{INDICATORS[crossed]} = {z[-1, crossed]:.3g} at the event"
    assert (crossed == 0) == (case == "condition"), f"{INDICATORS[crossed]} crossed in the {case} case"
    assert guard_measure(case, r[-1]) == pytest.approx(limit, rel=1e-8), "event not at the guard's limit"
    assert "terminateSimulation = true" in log, log[-2000:]

    # Co-Simulation with the same inputs fails the step that contains the event.
    with Fmu(request.getfixturevalue(archive), start=parameters) as fmu:
        fmu.set(list(HOLD) + list(push), list(HOLD.values()) + list(push.values()))
        k = 0
        with pytest.raises(FMICallException) as failure:
            for k in range(round(2.0 / H)):
                fmu.do_step(k * H, H)
        assert failure.value.status == 2, "a guard crossing is a Discard"
        assert k * H <= t_event < (k + 1) * H, f"Co-Simulation stopped in [{k * H}, {(k + 1) * H}], ME at {t_event}"
    print(f"\n{archive}, {case} guard: event at t = {t_event:.9f} s, "
          f"{INDICATORS[crossed]} = {z[-1, crossed]:.2g}; Co-Simulation discards the step [{k * H:.3f}, {(k + 1) * H:.3f}]")


# --- a drop onto the lower end stops: bounces located by the importer -----------
# The platform starts at the home pose moving down at 1 m/s, each slider
# pushed down by its actuator with 5 N: it hits the lower stops (rho_min) at
# about 1.9 m/s and bounces on their springs and dampers (stop_stiffness
# 1e5 N/m, stop_damping 100 N s/m: damping ratio about 0.3 against a quarter
# of the moving mass) until it rests on them. x, y and phi stay 0: the four
# legs move alike and the mechanism translates along z (sliders, rods and
# platform rigidly, dz = drho_i), so its motion is that of one mass
# M = m_platform + 4 (m_slider + m_rod) on four stops. The expected switches
# come from that one-mass model, solved here independently of the FMU:
# flight; contact (spring and damper k delta + d delta_dot); clamped (that
# force would pull: none) until it pushes again or the depth
# delta = rho_min - rho returns to 0.
# The actuators push down (rather than letting the platform fall under
# gravity alone) to keep the flights short: an error du in a rebound speed
# moves the next impact by 2 du / a, a the net deceleration; at a = g the
# importer's own CVode error at rtol 1e-10 (1e-11 s on the first impact,
# growing through each contact) reaches 2.3e-9 s by the fourth impact
# (measured against rtol 1e-13), beyond what a comparison to 1e-9 s can
# tell from the Co-Simulation's; at a = 28 m/s^2 it stays below 7e-10 s.
DROP_F = -5.0  # N per slider
DROP = {**{name: DROP_F for name in F}, "dz0": -1.0}
DROP_STOP = 0.3  # s: the model's last switch is at 0.133 s, sustained contact after
STOPS_LOWER = indexed_names("stop_margin_lower", 4)
EVENT_TOL = 1e-9  # s: ME against CS event times
DROP_TOL = 1e-7  # m: ME against CS trajectory


def one_mass_switches(depth0, p):
    """(time, 'passes' | 'leaves') of the one-mass model from depth `depth0`
    (< 0: above the stops) at the speed -dz0 into them, to DROP_STOP, with
    the plant's parameters p; and whether it ends at rest on the stops."""
    from scipy.integrate import solve_ivp
    m = (p["m_platform"] + 4 * (p["m_slider"] + p["m_rod"])) / 4  # per stop
    w = m * p["g"] - DROP_F  # net force into the stop, per slider
    k, d = p["stop_stiffness"], p["stop_damping"]
    push = lambda t, y: k * y[0] + d * y[1]
    depth = lambda t, y: y[0]
    laws = {"flight": lambda t, y: [y[1], w / m], "contact": lambda t, y: [y[1], (w - push(t, y)) / m]}
    laws["clamped"] = laws["flight"]
    # phase: (its law, [(indicator, direction, next phase)])
    phases = {"flight": [(depth, 1, "contact")], "contact": [(push, -1, "clamped")],
              "clamped": [(push, 1, "contact"), (depth, -1, "flight")]}
    t, y, phase, out = 0.0, [depth0, -DROP["dz0"]], "flight", []
    while True:
        events = []
        for g, direction, _ in phases[phase]:
            e = lambda t, y, g=g: g(t, y)
            e.terminal, e.direction = True, direction
            events.append(e)
        s = solve_ivp(laws[phase], (t, DROP_STOP), y, events=events, rtol=1e-13, atol=1e-16, method="DOP853")
        hits = [j for j in range(len(events)) if s.t_events[j].size]
        if not hits:
            return out, phase != "flight"
        j = min(hits, key=lambda j: s.t_events[j][0])
        t, y = s.t_events[j][0], list(s.y_events[j][0])
        nxt = phases[phase][j][2]
        if phase == "flight" or nxt == "flight":
            out.append((t, "passes" if phase == "flight" else "leaves"))
        phase = nxt


@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
def test_drop_onto_the_end_stops_bounces_located_as_in_co_simulation(archive, request, capfd):
    """fmpy's CVode at rtol 1e-10 through Model Exchange: no solver failure,
    every switch of the stops a state event (the FMU logs each one in Event
    Mode), as many as the one-mass model predicts; the event times within
    1e-9 s and z within 1e-7 m of the Co-Simulation FMU's CVODE at rtol 1e-10."""
    import re
    path = request.getfixturevalue(archive)
    names = ["m_platform", "m_slider", "m_rod", "g", "stop_stiffness", "stop_damping", "rho_min", "rho[1]"]
    with Fmu(path, start=DROP) as fmu:
        p = dict(zip(names, fmu.get(names)))
    expected, resting = one_mass_switches(p["rho_min"] - p["rho[1]"], p)
    assert resting and len(expected) >= 6, f"the drop should bounce several times and come to rest: {expected}"
    assert expected[-1][0] < DROP_STOP - 0.1

    r = simulate_fmu(str(path), fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
                     stop_time=DROP_STOP,
                     output_interval=H, start_values=DROP, output=["z"] + STOPS_LOWER,
                     record_events=False, debug_logging=True)
    log = capfd.readouterr().out
    assert r["time"][-1] == pytest.approx(DROP_STOP), "the importer's integration stopped early"
    # The FMU's Event Mode log: "event at t = ...: slider i passes|leaves its lower end stop".
    found = re.findall(r"event at t = ([-+0-9.eE]+): slider (\d) (passes|leaves) its (\w+) end stop", log)
    assert all(side == "lower" for *_, side in found)
    per_leg = {i: [(float(t), what) for t, leg, what, _ in found if int(leg) == i] for i in range(1, 5)}
    for i in range(1, 5):
        assert [w for _, w in per_leg[i]] == [w for _, w in expected], f"slider {i}: {per_leg[i]} vs {expected}"
    me_times = np.array([t for t, _ in per_leg[1]])
    model_dt = max(np.abs(np.array([t for t, _ in per_leg[i]]) - np.array([t for t, _ in expected])).max()
                   for i in range(1, 5))
    legs_dt = max(np.abs(np.array([t for t, _ in per_leg[i]]) - me_times).max() for i in range(2, 5))
    # The legs are alike: they switch together, to the resolution at which
    # the event times are compared here (a leg whose stop acted otherwise
    # would switch milliseconds apart).
    assert legs_dt <= EVENT_TOL, f"the legs switch {legs_dt:.3g} s apart: {per_leg}"

    # Co-Simulation: communication points on the grid and 1e-9 s either side
    # of each event fmpy located; the stops' mode (the sign of their
    # indicators: negative while held) must switch between the two.
    grid = np.arange(round(DROP_STOP / H) + 1) * H
    probes = np.concatenate([me_times - EVENT_TOL, me_times + EVENT_TOL])
    times = np.unique(np.concatenate([grid, probes]))
    cs = {}
    with Fmu(path, start=dict(DROP, rtol=1e-10, atol=1e-12)) as fmu:
        for t0, t1 in zip(times[:-1], times[1:]):
            fmu.do_step(t0, t1 - t0)
            cs[t1] = fmu.get(["z"] + STOPS_LOWER)
    for k, (t, what) in enumerate(per_leg[1]):
        held_before = [z < 0 for z in cs[t - EVENT_TOL][1:]]
        held_after = [z < 0 for z in cs[t + EVENT_TOL][1:]]
        assert held_before == [what == "leaves"] * 4 and held_after == [what == "passes"] * 4, \
            f"event {k} ({what}) at t = {t:.12f}: CS held {held_before} before, {held_after} after"
    assert np.array_equal(r["time"], grid)
    dz = np.abs(np.array([row["z"] for row in r])[1:] - np.array([cs[t][0] for t in grid[1:]])).max()
    print(f"\n{archive}: {len(expected)} switches per slider as the one-mass model's (within {model_dt:.2g} s), "
          f"the legs' within {legs_dt:.2g} s of each other; CS switches within {EVENT_TOL:g} s of each; "
          f"|z_ME - z_CS| {dz:.3g} m")
    assert dz < DROP_TOL
    assert model_dt < 1e-7, "the mechanism's drop is the one-mass model's"
