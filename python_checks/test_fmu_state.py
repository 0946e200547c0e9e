# SPDX-License-Identifier: BSD-2-Clause
"""FMU state save/restore is exact: a state taken at t = 1 s and restored
replays 1 s .. 1.5 s bit for bit, in the same instance (get/setFMUstate) and
in a fresh one (serialize / deSerialize), for the FMI 2.0 and the FMI 3.0
Co-Simulation FMU.

An FMU state holds everything the FMU needs, parameters included (FMI 2.0,
section 2.1.8), so the run uses non-default solver settings and the fresh
instance is left at its defaults: the restored state must bring them along."""
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
