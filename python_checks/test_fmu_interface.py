# SPDX-License-Identifier: BSD-2-Clause
"""The spec's "FMU interface contract": every listed variable exists under its
exact name with the listed causality, and the parameter defaults are the
spec's (Tables II and III, leg placement, gravity, solver settings)."""
import math

import pytest
from fmpy import read_model_description

from pkm4puu.interface import ACC, indexed_names, POSE, VEL
from pkm4puu.spec import PARAMETER_DEFAULTS, SOLVER_DEFAULTS

WRENCH = indexed_names("Fe", 3) + ["Me_z"]
GEOMETRY = ["h", "l", "h_prime", "r_b", "r_Q"] + indexed_names("beta", 4) + indexed_names("gamma", 4)
MASSES = ["m_slider", "m_rod"] + indexed_names("I_rod", 3) + ["m_platform", "Izz_platform", "g"]

PLANT = {
    "input": indexed_names("F", 4) + WRENCH,
    "output": POSE + VEL + indexed_names("rho", 4) + indexed_names("drho", 4) + indexed_names("theta1", 4)
    + indexed_names("theta2", 4) + indexed_names("lambda", 12) + ["constraint_residual", "jacobian_condition"],
    "parameter": GEOMETRY + MASSES + ["x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0",
                                      "solver", "rk4_step", "rtol", "atol"],
}
INVERSE = {
    "input": POSE + VEL + ACC + WRENCH,
    "output": indexed_names("F", 4) + indexed_names("rho", 4) + indexed_names("drho", 4)
    + indexed_names("lambda", 12),
    "parameter": GEOMETRY + MASSES,
}

def _variables(path):
    return {v.name: v for v in read_model_description(str(path)).modelVariables}


def _check_contract(path, contract):
    variables = _variables(path)
    wrong = []
    for causality, names in contract.items():
        for name in names:
            v = variables.get(name)
            if v is None:
                wrong.append(f"{name}: missing")
            elif v.causality != causality:
                wrong.append(f"{name}: causality {v.causality}, contract says {causality}")
    assert not wrong, f"{path.name} breaks the interface contract:\n" + "\n".join(wrong)
    if "solver" in contract["parameter"]:
        kind = variables["solver"].type
        assert kind == "Integer", f"{path.name}: 'solver' must be an Integer, is {kind}"


def _check_defaults(path, defaults):
    variables = _variables(path)
    wrong = []
    for name, expected in defaults.items():
        start = variables[name].start
        if start is None or not math.isclose(float(start), expected, rel_tol=1e-12, abs_tol=1e-15):
            wrong.append(f"{name}: start {start}, spec {expected!r}")
    assert not wrong, f"{path.name}: parameter defaults differ from docs/model.md:\n" + "\n".join(wrong)


def test_plant_contract(plant_fmu):
    _check_contract(plant_fmu, PLANT)


def test_inverse_contract(inverse_fmu):
    _check_contract(inverse_fmu, INVERSE)


@pytest.mark.parametrize("which", ["plant_fmu", "inverse_fmu"])
def test_parameter_defaults_are_the_spec(which, request):
    _check_defaults(request.getfixturevalue(which), PARAMETER_DEFAULTS)


def test_plant_solver_defaults(plant_fmu):
    _check_defaults(plant_fmu, SOLVER_DEFAULTS)


@pytest.mark.parametrize("model", ["PKM4PUU", "PKM4PUU_Inverse"])
@pytest.mark.parametrize("fmi", ["fmi2", "fmi3"])
def test_time_is_the_independent_variable_without_start(model, fmi):
    """FMI 2.0 section 2.2.7 (causality "independent"): the independent
    variable "must be defined as Real without a start attribute"; FMI 3.0's
    definition of causality "independent" likewise gives it no start. The FMI Library that
    libcosim uses reports an error for exactly this ("Start attribute is
    required for this causality, variability and initial combination"):
    there the standard wins (docs/importers.md, "Where an importer and the
    standard disagree")."""
    import xml.etree.ElementTree as ET
    from pathlib import Path

    root = ET.parse(Path(__file__).resolve().parents[1] / "src" / "models" / model / fmi / "modelDescription.xml").getroot()
    variables = root.find("ModelVariables")
    if fmi == "fmi2":
        independent = [v for v in variables if v.get("causality") == "independent"]
        assert [v.get("name") for v in independent] == ["time"]
        real = independent[0].find("Real")
        assert real is not None and real.get("start") is None and real.get("unit") == "s"
        assert independent[0].get("variability") == "continuous" and independent[0].get("initial") is None
    else:
        independent = [v for v in variables if v.get("causality") == "independent"]
        assert [v.get("name") for v in independent] == ["time"] and independent[0].tag == "Float64"
        assert independent[0].get("start") is None and independent[0].get("initial") is None
