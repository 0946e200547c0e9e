# SPDX-License-Identifier: BSD-2-Clause
"""The plant FMU's analytic derivatives through fmpy, as an importer that
linearises would ask for them: the capability flags fmpy reads, the Model
Exchange Jacobians A = d der(x)/dx and B = d der(x)/du by
fmi2GetDirectionalDerivative against Richardson-extrapolated central
differences of fmi2GetDerivatives (the same FMU), every machine term on; and
FMI 3.0's adjoint derivative as the transpose of its directional one.
"""
import zipfile
from ctypes import POINTER, c_double
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model

from differences import richardson

MACHINE = {"rotor_inertia": 2e-7, "friction_viscous": 1.5, "friction_coulomb": 0.2, "friction_velocity": 0.05,
           "payload_mass": 0.3, "payload_com[1]": 0.02, "payload_com[2]": -0.012, "payload_Izz": 1.2e-4}
# Off-centre, rotated, moving; the energy integrals at 0.
STATE = np.array([0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.0, 0.0])
INPUTS = {"F[1]": 2.7, "F[2]": 2.5, "F[3]": 2.9, "F[4]": 2.6, "Fe[1]": 0.3, "Fe[2]": -0.2, "Fe[3]": 0.5,
          "Me_z": 0.01, "tau[1]": 1e-3, "tau[2]": -2e-3, "tau[3]": 1.5e-3, "tau[4]": 0.0}
# Difference steps: pose 0.3 mm / 3 mrad, rates 5 mm/s / 50 mrad/s, energies 1 J, forces 1 N,
# Me_z 0.01 N*m, torques 5 mN*m.
STEPS = [3e-4] * 3 + [3e-3] + [5e-3] * 3 + [5e-2] + [1.0] * 2 + [1.0] * 7 + [1e-2] + [5e-3] * 4


def by_name(md):
    return {v.name: v.valueReference for v in md.modelVariables}


@pytest.fixture
def model_exchange(plant_fmu):
    md = read_model_description(plant_fmu)
    fmu = FMU2Model(guid=md.guid, unzipDirectory=extract(plant_fmu),
                    modelIdentifier=md.modelExchange.modelIdentifier, instanceName="derivatives")
    fmu.instantiate()
    vr = by_name(md)
    fmu.setupExperiment(startTime=0.0)
    fmu.setReal([vr[n] for n in MACHINE], list(MACHINE.values()))
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.newDiscreteStates()
    fmu.enterContinuousTimeMode()
    yield md, fmu, vr
    fmu.terminate()
    fmu.freeInstance()


def test_flags_say_derivatives_are_provided(plant_fmu, plant_fmu3):
    md2 = read_model_description(plant_fmu)
    assert md2.modelExchange.providesDirectionalDerivative and md2.coSimulation.providesDirectionalDerivative
    # fmpy 0.3.32 does not read FMI 3.0's flags: the XML itself.
    with zipfile.ZipFile(plant_fmu3) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    for interface in ("ModelExchange", "CoSimulation"):
        element = root.find(interface)
        assert element.get("providesDirectionalDerivatives") == "true", interface
        assert element.get("providesAdjointDerivatives") == "true", interface


def test_model_exchange_a_and_b_match_richardson_differences(model_exchange):
    md, fmu, vr = model_exchange
    n = len(STATE)
    states = [d.variable.derivative.valueReference for d in md.derivatives]
    derivatives = [d.variable.valueReference for d in md.derivatives]
    inputs = [vr[name] for name in INPUTS]
    knowns = states + inputs
    x = STATE.copy()
    px = x.ctypes.data_as(POINTER(c_double))
    dx = np.zeros(n)
    pdx = dx.ctypes.data_as(POINTER(c_double))

    def set_point(state, u):
        x[:] = state
        fmu.setContinuousStates(px, n)
        fmu.setReal(inputs, list(u))

    u0 = np.array(list(INPUTS.values()))
    set_point(STATE, u0)
    J = np.column_stack([fmu.getDirectionalDerivative(derivatives, knowns, list(np.eye(len(knowns))[j]))
                         for j in range(len(knowns))])

    def derivative_at(j, s):
        state, u = STATE.copy(), u0.copy()
        if j < n:
            state[j] += s
        else:
            u[j - n] += s
        set_point(state, u)
        fmu.getDerivatives(pdx, n)
        return dx.copy()

    worst = 0.0
    for j in range(len(knowns)):
        fd, err = richardson(lambda s: derivative_at(j, s), STEPS[j])
        scale = max(np.max(np.abs(J[:, j])), 1e-12)
        unreliable = np.max(err) / scale
        assert unreliable < 1e-8, f"column {j}: the difference quotient is unreliable ({unreliable:.1e})"
        rel = np.max(np.abs(J[:, j] - fd)) / scale
        assert rel < 1e-7, f"column {j} (value reference {knowns[j]}): {rel:.2e} > 1e-7"
        worst = max(worst, rel)
    print(f"A, B through fmpy against Richardson differences: largest relative difference {worst:.2e}")


def test_fmi3_adjoint_is_the_transpose_of_the_directional_derivative(plant_fmu3):
    md = read_model_description(plant_fmu3)
    fmu = FMU3Model(guid=md.guid, unzipDirectory=extract(plant_fmu3),
                    modelIdentifier=md.modelExchange.modelIdentifier, instanceName="adjoint")
    fmu.instantiate()
    try:
        vr = by_name(md)
        fmu.setFloat64([vr[k] for k in MACHINE], list(MACHINE.values()))
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        fmu.updateDiscreteStates()
        fmu.enterContinuousTimeMode()
        x = STATE.copy()
        fmu.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), len(x))
        fmu.setFloat64([vr[k] for k in INPUTS], list(INPUTS.values()))
        unknowns = [d.variable.valueReference for d in md.derivatives]
        knowns = [d.variable.derivative.valueReference for d in md.derivatives] + [vr[k] for k in INPUTS]
        forward = np.column_stack([fmu.getDirectionalDerivative(unknowns, knowns, list(e))
                                   for e in np.eye(len(knowns))])
        # (fmpy's default nSensitivity is the number of unknowns: the adjoint's is the knowns'.)
        adjoint = np.vstack([fmu.getAdjointDerivative(unknowns, knowns, list(e), nSensitivity=len(knowns))
                             for e in np.eye(len(unknowns))])
        assert np.array_equal(forward, adjoint)
        assert np.count_nonzero(forward[4:8, :8]) > 0, "the accelerations depend on the state"
        fmu.terminate()
    finally:
        fmu.freeInstance()
