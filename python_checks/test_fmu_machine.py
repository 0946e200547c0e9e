# SPDX-License-Identifier: BSD-2-Clause
"""The machine around the mechanism through the FMUs (docs/model.md "The machine
around the mechanism"): the auto-test chain with every
term on, the plant's energy audit, and a drop onto the end stops.

Every term on: a rotor on each ball screw whose reflected mass J (2 pi/p)^2
equals the slider's, viscous and Coulomb friction, an off-centre payload.
"""
import math

import numpy as np
import pytest

from pkm4puu.fmu import Fmu, inverse_forces
from pkm4puu.interface import indexed_names, F, POSE
from pkm4puu.motions import pose_at
from pkm4puu.spec import G, M_PLATFORM, M_ROD, M_SLIDER, P0, STATIC_FORCE_P0, STOP_STIFFNESS, T_MOVE

SCREW_LEAD = 0.004  # m, the default
MACHINE = {
    "rotor_inertia": M_SLIDER * (SCREW_LEAD / (2 * math.pi)) ** 2,  # reflected mass = the slider's
    "friction_viscous": 0.5,
    "friction_coulomb": 0.005,
    "friction_velocity": 2e-3,
    "payload_mass": 0.2,
    "payload_com[1]": 0.02,
    "payload_com[2]": -0.015,
    "payload_Izz": 1.5e-4,
}
H = 1e-3
N = round(T_MOVE / H)
START = {"x0": P0[0], "y0": P0[1], "z0": P0[2], "phi0": P0[3]}
SOLVERS = {"CVODE": {"solver": 0, "rtol": 1e-10, "atol": 1e-12}, "RK4": {"solver": 1, "rk4_step": 1e-3}}
ENERGY = ["kinetic_energy", "potential_energy", "actuator_work", "dissipated_energy"]


@pytest.fixture(scope="module")
def machine_forces(inverse_fmu):
    """F at the midpoint of every 1 ms step of the auto-test, from the
    inverse FMU with every machine term on."""
    with Fmu(inverse_fmu, start=MACHINE) as inv:
        return inverse_forces(inv, (np.arange(N) + 0.5) * H)


@pytest.fixture(scope="module")
def ideal_forces(inverse_fmu):
    with Fmu(inverse_fmu) as inv:
        return inverse_forces(inv, (np.arange(N) + 0.5) * H)


def drive(plant_fmu, forces, solver, start=MACHINE):
    """The plant with the machine terms, midpoint-held forces: pose and the
    energy outputs after every step."""
    poses, energy = [], []
    with Fmu(plant_fmu, start={**START, **start, **SOLVERS[solver]}) as fmu:
        energy.append(fmu.get(ENERGY))
        for k in range(N):
            fmu.set(F, forces[k])
            fmu.do_step(k * H, H)
            poses.append(fmu.get(POSE))
            energy.append(fmu.get(ENERGY))
    return np.array(poses), np.array(energy)


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_auto_test_chain_with_every_term_on(plant_fmu, machine_forces, ideal_forces, solver):
    """Inverse FMU -> plant FMU with rotor inertia, friction and payload: the
    prescribed path within 5e-8 m and rad (the bound of test_fmu_autotest);
    and the terms matter (the ideal machine's forces miss the path)."""
    pose, _ = drive(plant_fmu, machine_forces, solver)
    ref = np.array([pose_at((k + 1) * H) for k in range(N)])
    err = np.abs(pose - ref).max(axis=0)
    moved_by_terms = np.abs(machine_forces - ideal_forces).max()
    print(f"\n{solver}: every machine term on, error {err[:3].max():.3g} m, {err[3]:.3g} rad; "
          f"the terms change F by up to {moved_by_terms:.3g} N")
    assert moved_by_terms > 1e-3, "the machine terms must change the forces"
    assert err[:3].max() < 5e-8 and err[3] < 5e-8


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_energy_audit_is_constant_with_every_term_on(plant_fmu, machine_forces, solver):
    """kinetic + potential - actuator_work + dissipated stays constant over
    the auto-test (1e-9 J), while every term is nonzero."""
    _, e = drive(plant_fmu, machine_forces, solver)
    audit = e[:, 0] + e[:, 1] - e[:, 2] + e[:, 3]
    drift = np.abs(audit - audit[0]).max()
    print(f"\n{solver}: energy audit drift {drift:.3g} J over 2 s; work {e[-1, 2]:.6f} J, "
          f"dissipated {e[-1, 3]:.3g} J, peak kinetic {e[:, 0].max():.3g} J")
    assert e[-1, 3] > 1e-5 and e[:, 0].max() > 1e-5, "friction must dissipate and the machine move"
    assert drift < 1e-9


# --- the drop onto the lower end stops -------------------------------------------
# F = 0 at the home pose: the machine falls straight down (symmetric, no
# torque about z), every slider reaches rho_min = 0 at once after falling
# h0 = rho(P0) = 0.0443193423 m (docs/model.md golden pose). Bound on the
# penetration: the four stops in parallel (stiffness 4k) must take up the
# weight W's work over h0 + delta; without their damping (which only helps)
# 1/2 (4k) delta^2 = W (h0 + delta), so
#     delta_max <= (W + sqrt(W^2 + 8 k W h0)) / (4 k)           (about 1.56 mm)
# At rest each slider carries a quarter of the weight: delta_static = W / (4 k).
K_STOP, RHO_P0 = STOP_STIFFNESS, 0.0443193423
W = (M_PLATFORM + 4 * M_SLIDER + 4 * M_ROD) * G
DELTA_MAX = (W + math.sqrt(W**2 + 8 * K_STOP * W * RHO_P0)) / (4 * K_STOP)
DELTA_STATIC = W / (4 * K_STOP)
T_DROP, SAMPLE = 0.5, 0.01
RHO = indexed_names("rho", 4)


def drop(plant_fmu, solver, h):
    """Drop with communication step h: the pose every 10 ms, the deepest rho."""
    every = round(SAMPLE / h)
    samples, deepest = [], 0.0
    with Fmu(plant_fmu, start={**START, **SOLVERS[solver]}) as fmu:
        fmu.set(F, [0.0] * 4)
        for k in range(round(T_DROP / h)):
            fmu.do_step(k * h, h)  # a Discard raises
            deepest = min(deepest, fmu.get(RHO).min())
            if (k + 1) % every == 0:
                samples.append(fmu.get(POSE + ["dz"] + RHO + indexed_names("stop_force", 4) + ENERGY))
    return np.array(samples), deepest


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_drop_onto_the_stops_comes_to_rest_and_is_located(plant_fmu, solver):
    runs = {h: drop(plant_fmu, solver, h) for h in (1e-4, 1e-3, 1e-2)}
    for h, (s, deepest) in runs.items():
        end = s[-1]
        assert abs(end[4]) < 1e-9, f"h = {h}: not at rest at {T_DROP} s (dz = {end[4]:.3g})"
        assert np.allclose(end[5:9], -DELTA_STATIC, atol=1e-9, rtol=0), f"h = {h}: rho at rest {end[5:9]}"
        assert np.allclose(end[9:13], W / 4, rtol=1e-9), f"h = {h}: stop forces at rest {end[9:13]}"
        assert -deepest <= DELTA_MAX, f"h = {h}: penetration {-deepest:.4g} m beyond the bound {DELTA_MAX:.4g} m"
        assert np.abs(s[:, [0, 1, 3]]).max() < 1e-12, "the fall is vertical"
        # The audit: with F = 0 nothing works on the machine, so the stops'
        # damping dissipates the potential energy lost (0.47 J). Bound: 1e-6
        # J, two millionths of what is exchanged (an integrator that left the
        # integrals out of its error control was off by 1e-2 J here).
        audit = s[:, 13] + s[:, 14] - s[:, 15] + s[:, 16]
        assert abs(s[-1, 15]) == 0.0, "nothing works on the machine"
        assert s[-1, 16] > 0.4, f"h = {h}: the stops must dissipate the fall's energy ({s[-1, 16]:.4g} J)"
        assert np.abs(audit - audit[0]).max() < 1e-6, f"h = {h}: energy audit drifts {np.abs(audit - audit[0]).max():.3g} J"
    spread = max(np.abs(runs[h][0][:, :4] - runs[1e-4][0][:, :4]).max() for h in (1e-3, 1e-2))
    drift = max(np.abs(r[0][:, 13] + r[0][:, 14] + r[0][:, 16] - r[0][0, 13] - r[0][0, 14] - r[0][0, 16]).max()
                for r in runs.values())
    print(f"\n{solver}: energy audit of the drop within {drift:.3g} J; deepest {-runs[1e-4][1]:.4g} m (bound {DELTA_MAX:.4g}, static {DELTA_STATIC:.3g}); "
          f"pose every 10 ms agrees within {spread:.3g} m across steps of 0.1, 1, 10 ms")
    assert spread < 1e-6, "the contact must be located, not stepped over"


@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
def test_model_exchange_drop_locates_the_stops_as_events(archive, request, capfd):
    """Model Exchange through fmpy's CVode: the stop indicators change sign
    where the sliders reach rho_min (an event, logged; the run goes on), and
    the machine comes to rest on the stops as in Co-Simulation."""
    from fmpy import simulate_fmu
    lower = indexed_names("stop_margin_lower", 4)
    r = simulate_fmu(str(request.getfixturevalue(archive)), fmi_type="ModelExchange", solver="CVode",
                     relative_tolerance=1e-10, stop_time=T_DROP,
                     output_interval=1e-3, debug_logging=True,
                     start_values={**START, **{n: 0.0 for n in F}}, output=lower + RHO + ["dz"])
    log = capfd.readouterr().out
    assert r["time"][-1] == pytest.approx(T_DROP), "the run must not stop at the contact"
    z = np.array([[row[n] for n in lower] for row in r])
    first = np.argmax((z < 0).all(axis=1))
    t_contact = r["time"][first]
    # Free fall from rest over h0: t = sqrt(2 h0 / g), when every indicator crosses zero.
    assert t_contact == pytest.approx(math.sqrt(2 * RHO_P0 / G), abs=2e-3)
    assert (z[:first] >= 0).all()
    assert np.allclose(z[-1], -DELTA_STATIC, atol=1e-8, rtol=0), z[-1]
    for i in range(1, 5):
        assert f"slider {i} passes its lower end stop" in log, log[-3000:]
    print(f"\n{archive}: contact at t = {t_contact:.4f} s (free fall: {math.sqrt(2 * RHO_P0 / G):.4f} s), "
          f"{log.count('passes its lower end stop')} contact and {log.count('leaves its lower')} release events logged")
