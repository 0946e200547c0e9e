# SPDX-License-Identifier: BSD-2-Clause
"""Every FMI flavour of the plant through fmpy: FMI 2.0 and 3.0, Model
Exchange and Co-Simulation, from the one binary and the generated model
descriptions.

The motion: 0.5 s from rest at the home pose, with forces that do not hold
the machine (F[1] 4.4 mN above the holding force, Fe and Me_z nonzero), so
that all four coordinates move. Co-Simulation integrates with the FMU's CVODE
at rtol 1e-10; Model Exchange with fmpy's CVode at rtol 1e-10: the two
integrators are independent, so their agreement bounds both errors.
"""
import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

HOLD = 2.655616050  # docs/model.md "Bodies"
START = {"F[1]": HOLD + 0.0044, "F[2]": HOLD, "F[3]": HOLD, "F[4]": HOLD, "Fe[1]": 0.003, "Me_z": 1e-4}
OUTPUTS = ["x", "y", "z", "phi", "dx", "dphi"]


def simulate(path, fmi_type, **kw):
    start = dict(START)
    if fmi_type == "CoSimulation":
        start.update(rtol=1e-10, atol=1e-12)
    return simulate_fmu(str(path), fmi_type=fmi_type, stop_time=0.5, output_interval=1e-2, start_values=start,
                        output=OUTPUTS, **kw)


def as_array(r):
    return np.array([[row[n] for n in OUTPUTS] for row in r])


@pytest.mark.parametrize("fmu", ["plant_fmu", "inverse_fmu", "plant_fmu3", "inverse_fmu3"])
def test_every_archive_validates_and_offers_both_interfaces(fmu, request):
    path = request.getfixturevalue(fmu)
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.modelExchange is not None and md.coSimulation is not None
    assert md.fmiVersion == ("3.0" if "fmu3" in fmu else "2.0")


def test_model_exchange_reproduces_co_simulation(plant_fmu, plant_fmu3):
    cs = as_array(simulate(plant_fmu, "CoSimulation"))
    me = as_array(simulate(plant_fmu, "ModelExchange", solver="CVode", relative_tolerance=1e-10))
    moved = np.abs(cs[-1] - cs[0])
    assert moved[0] > 1e-6 and moved[3] > 1e-5, "the test motion must move the platform"
    err = np.max(np.abs(me - cs), axis=0)
    assert err[:3].max() < 1e-8, f"ME vs CS position error {err[:3].max():.3g} m (bound 1e-8)"
    assert err[3] < 1e-8, f"ME vs CS phi error {err[3]:.3g} rad (bound 1e-8)"
    me3 = as_array(simulate(plant_fmu3, "ModelExchange", solver="CVode", relative_tolerance=1e-10))
    assert np.max(np.abs(me3 - cs)) < 1e-8


def test_fmi3_co_simulation_is_bit_identical_to_fmi2(plant_fmu, plant_fmu3):
    a = as_array(simulate(plant_fmu, "CoSimulation"))
    b = as_array(simulate(plant_fmu3, "CoSimulation"))
    assert np.array_equal(a, b)
