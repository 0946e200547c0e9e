# SPDX-License-Identifier: BSD-2-Clause
"""examples/pick_and_place.py: the standard cycle planned for the spec's
limits and for drive_sizing.py's drives; the drives' plan within the motor's
envelope and, friction included, within its torque limit through the screw."""
import math

import numpy as np
import pytest

from example_scripts import load_example
from pkm4puu.spec import CYCLE_F_MAX, CYCLE_V_MAX

pp = load_example("pick_and_place")


@pytest.fixture(scope="module")
def plans():
    machine, motor = pp.drives()
    return pp.plan_with_drives(0.25), machine, motor


def test_drives_plan_keeps_the_motor_within_its_envelope(plans):
    """The torque limit acts as 2 pi tau_peak / p on each force and the corner
    speed as p omega_corner / (2 pi) on each slider; the forces recomputed
    with friction along the plan stay within the former, so every operating
    point (tau = F p / 2 pi, omega = 2 pi drho / p) is within the motor's
    torque-speed envelope."""
    cycle, machine, motor = plans
    p = machine["screw_lead"]
    for seg in cycle.segments:
        assert seg.force_limit == pytest.approx(2 * math.pi * motor.peak_torque / p, rel=1e-15)
        assert seg.speed_limit == pytest.approx(p * motor.corner_speed / (2 * math.pi), rel=1e-15)
        assert seg.friction_bound == pytest.approx(machine["friction_viscous"] * seg.speed_limit
                                                   + machine["friction_coulomb"], rel=1e-15)
        assert np.abs(seg.F).max() <= seg.force_limit
    for _, _, use in pp.motor_use(cycle, motor):
        assert use <= 1 + 1e-5  # the slider-speed excess between grid points, second order


def test_command_line(tmp_path):
    assert pp.main(["--out", str(tmp_path)]) == 0
    for name in ("pick_and_place.csv", "pick_and_place.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    with open(tmp_path / "pick_and_place.csv") as f:
        header = f.readline().strip().split(",")
        cycles = {line.split(",", 1)[0] for line in f}
    assert header[:2] == ["cycle", "t_s"] and cycles == {"spec", "drives"}
    # The cycle planned for the spec's limits keeps them at every written
    # point, |F_i| = 2 pi |tau_i| / p <= 10 N and |drho_i| = p |omega_i| / 2 pi
    # <= 0.5 m/s, up to the excess between the planner's grid points (second
    # order in their spacing, test_pick_place_topp.py; 1e-5 as in
    # test_pick_place_cycle.py).
    rows = np.genfromtxt(tmp_path / "pick_and_place.csv", delimiter=",", names=True, dtype=None, encoding=None)
    spec_rows = rows[rows["cycle"] == "spec"]
    lead = pp.drives()[0]["screw_lead"]
    force = np.abs([spec_rows[f"tau{i}_Nm"] for i in range(1, 5)]) * 2 * math.pi / lead
    speed = np.abs([spec_rows[f"omega{i}_rad_s"] for i in range(1, 5)]) * lead / (2 * math.pi)
    assert force.max() <= CYCLE_F_MAX * (1 + 1e-5) and speed.max() <= CYCLE_V_MAX * (1 + 1e-5)
    assert force.max() >= 0.9 * CYCLE_F_MAX or speed.max() >= 0.9 * CYCLE_V_MAX  # time-optimal: a limit is reached
    assert pp.main(["--out", str(tmp_path), "--payload", "-1"]) == 2
