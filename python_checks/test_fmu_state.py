# SPDX-License-Identifier: BSD-2-Clause
"""FMU state save/restore is exact: a state taken at t = 1 s and restored
replays 1 s .. 1.5 s bit for bit, in the same instance (get/setFMUstate) and
in a fresh one (serialize / deSerialize), for the FMI 2.0 and the FMI 3.0
Co-Simulation FMU. So does a ROS2 run restored where its step ladder after
a switch of the contact mode is pending: after initialisation and right
after an impact on the end stops.

An FMU state holds everything the FMU needs, parameters included (FMI 2.0,
section 2.1.8; FMI 3.0, section 2.2.6), so the runs use non-default solver
settings and the fresh instance is left at its defaults: the restored state
must bring them along."""
import math

import numpy as np
import pytest

from pkm4puu.fmu import Fmu
from pkm4puu.interface import DRHO, F, POSE, RHO, THETA1, THETA2, VEL, indexed_names
from pkm4puu.spec import STATIC_FORCE_P0

H = 1e-3
T_SAVE, T_END = 1.0, 1.5
OUT = (POSE + VEL + RHO + DRHO + THETA1 + THETA2
       + indexed_names("lambda", 12) + ["constraint_residual", "jacobian_condition"])
SOLVERS = {"CVODE": {"solver": 0, "rtol": 1e-9}, "RK4": {"solver": 1, "rk4_step": 5e-4},
           "Rosenbrock": {"solver": 2, "rk4_step": 5e-4}}


def forces(t):
    """The static forces plus a different, time-varying part on each leg, so
    the platform moves in all four coordinates."""
    return [STATIC_FORCE_P0 + 0.01 * math.sin(2 * math.pi * t * (1 + 0.3 * i) + i) for i in range(4)]


def advance(fmu, k0, k1):
    """Steps k0 .. k1-1 (t = k h), inputs midpoint-held; outputs after each."""
    rows = []
    for k in range(k0, k1):
        fmu.set(F, forces((k + 0.5) * H))
        fmu.do_step(k * H, H, no_set_prior=False)
        rows.append(fmu.get(OUT))
    return np.array(rows)


def _assert_identical(a, b, what):
    same = a == b  # exact float equality, not a tolerance
    if not same.all():
        i, j = np.argwhere(~same)[0]
        raise AssertionError(f"{what}: {(~same).sum()} values differ; first at step {i}, {OUT[j]}: "
                             f"{a[i, j]!r} vs {b[i, j]!r} (diff {a[i, j] - b[i, j]:.3e})")


@pytest.mark.parametrize("solver", list(SOLVERS))
@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
def test_state_restore_is_exact(archive, solver, request):
    plant_fmu = request.getfixturevalue(archive)
    k_save, k_end = round(T_SAVE / H), round(T_END / H)
    with Fmu(plant_fmu, start=SOLVERS[solver]) as fmu:
        advance(fmu, 0, k_save)
        at_save = fmu.get(OUT)
        state = fmu.get_state()
        try:
            first = advance(fmu, k_save, k_end)
            moved = np.abs(first[-1, :4] - at_save[:4]).max()
            assert moved > 1e-6, f"the platform barely moved ({moved:.2e}): the check would be trivial"

            fmu.set_state(state)
            _assert_identical(fmu.get(OUT)[None], at_save[None], f"{solver}: outputs right after setFMUstate")
            _assert_identical(advance(fmu, k_save, k_end), first, f"{solver}: replay after setFMUstate")

            blob = fmu.serialize(state)
        finally:
            fmu.free_state(state)

    with Fmu(plant_fmu, instance_name="fresh") as fresh:  # default parameters
        restored = fresh.deserialize(blob)
        try:
            fresh.set_state(restored)
        finally:
            fresh.free_state(restored)
        _assert_identical(fresh.get(OUT)[None], at_save[None], f"{solver}: outputs after deSerializeFMUstate")
        _assert_identical(advance(fresh, k_save, k_end), first, f"{solver}: replay in a fresh instance")
    print(f"\n{archive}, {solver}: state at t = {T_SAVE} s, {len(blob)} bytes serialized, replay bit-identical")


DROP = ["z", "dz", "stop_force[1]", "der(dissipated_energy)", "dissipated_energy"]


def drop_steps(fmu, k0, k1):
    """Steps k0 .. k1-1 of a drop (inputs as started); outputs after each."""
    rows = []
    for k in range(k0, k1):
        fmu.do_step(k * H, H)
        rows.append(fmu.get(DROP))
    return np.array(rows)


@pytest.mark.parametrize("saved", ["after initialisation", "after the impact"])
@pytest.mark.parametrize("archive", ["plant_fmu", "plant_fmu3"])
def test_rosenbrock_restore_is_exact_where_its_steps_grow(archive, saved, request):
    """ROS2 (solver = 2) starts with short steps after initialisation and
    after every switch of the contact mode and lengthens them as the
    transient decays: a drop onto the end stops (F = 0), with strong viscous
    friction when saved after initialisation, restored there replays bit
    for bit (the state carries the ladder)."""
    start = {"solver": 2, **{name: 0.0 for name in F}}
    if saved == "after initialisation":
        start["friction_viscous"] = 1000.0
    with Fmu(request.getfixturevalue(archive), start=start) as fmu:
        k = 0
        if saved == "after the impact":
            while fmu.get(["stop_force[1]"])[0] == 0.0:
                assert k < 200, "no impact within 0.2 s"
                drop_steps(fmu, k, k + 1)
                k += 1
        state = fmu.get_state()
        try:
            first = drop_steps(fmu, k, k + 40)
            fmu.set_state(state)
            _assert_identical_rows(drop_steps(fmu, k, k + 40), first, f"ROS2, restored {saved}")
            blob = fmu.serialize(state)
        finally:
            fmu.free_state(state)
    with Fmu(request.getfixturevalue(archive), instance_name="fresh") as fresh:
        restored = fresh.deserialize(blob)
        try:
            fresh.set_state(restored)
        finally:
            fresh.free_state(restored)
        _assert_identical_rows(drop_steps(fresh, k, k + 40), first, f"ROS2, restored {saved} in a fresh instance")


def _assert_identical_rows(a, b, what):
    same = a == b
    if not same.all():
        i, j = np.argwhere(~same)[0]
        raise AssertionError(f"{what}: {(~same).sum()} values differ; first at step {i}, {DROP[j]}: "
                             f"{a[i, j]!r} vs {b[i, j]!r} (diff {a[i, j] - b[i, j]:.3e})")
