# SPDX-License-Identifier: BSD-2-Clause
"""The payload changed during a run from Python: capi.Plant.set keeps the
run (the C API's tunable parameters), and the fmpy wrapper sets it between
Co-Simulation steps of the FMI 2.0 and 3.0 plant. At the home pose held by
the empty machine's forces, a payload m at P sinks the platform at
-m g / (M + m), M the moving mass (the spec's total weight over g): the
derivation is tests/fmi/payload.cpp's (a vertical motion there moves every
body straight up, decoupled from x, y and phi by the legs' symmetry)."""
import numpy as np
import pytest

from pkm4puu import Fmu, capi, spec

MASS = 0.25  # kg
ACC = -MASS * spec.G / (spec.TOTAL_WEIGHT / spec.G + MASS)  # m/s^2


def test_capi_plant_set_keeps_the_run(pkm_library):
    """Plant.set(payload_mass=...) at rest: the state kept, the acceleration
    the spec's; a fixed parameter ends the run."""
    F = [spec.STATIC_FORCE_P0] * 4
    with capi.Plant(capi.load(pkm_library)) as m:
        m.init_pose(0.0, spec.P0)
        m.advance(0.01, F)
        before = m.outputs(F)
        m.set(payload_mass=MASS)
        after = m.outputs(F)
        assert np.array_equal(after.pose, before.pose) and np.array_equal(after.velocity, before.velocity)
        assert after.acceleration[2] == pytest.approx(ACC, rel=1e-9)
        assert after.actuator_work - before.actuator_work == pytest.approx(MASS * spec.G * spec.P0[2], rel=1e-12)
        m.advance(0.02, F)  # the run goes on
        m.set(g=9.0)
        with pytest.raises(capi.PkmError, match="a parameter of the machine changed"):
            m.advance(0.03, F)


@pytest.mark.parametrize("fmi", [2, 3])
def test_fmu_wrapper_sets_the_payload_between_steps(fmi, plant_fmu, plant_fmu3):
    """Fmu.set between do_step calls (FMI 3.0: the get after a step, as FMI
    3.0.2 section 4.2.1 asks): the plant sinks by ACC t^2 / 2 (CVODE at its
    default tolerances)."""
    h, n = 1e-3, 20
    with Fmu(plant_fmu if fmi == 2 else plant_fmu3) as plant:
        plant.do_step(0.0, h)
        plant.set(["payload_mass"], [MASS])
        for k in range(1, n + 1):
            plant.do_step(k * h, h)
        z, dz = plant.get(["z", "dz"])
    t = n * h
    assert z - spec.P0[2] == pytest.approx(0.5 * ACC * t * t, rel=1e-6)
    assert dz == pytest.approx(ACC * t, rel=1e-6)
