"""The spec's "FMU interface contract": every listed variable exists under its
exact name with the listed causality, and the parameter defaults are the
spec's (Tables II and III, leg placement, gravity, solver settings)."""
import math

import pytest
from fmpy import read_model_description

from fmu_helpers import ACC, POSE, VEL, arr

WRENCH = arr("Fe", 3) + ["Me_z"]
GEOMETRY = ["h", "l", "h_prime", "r_b", "r_Q"] + arr("beta", 4) + arr("gamma", 4)
MASSES = ["m_slider", "m_rod"] + arr("I_rod", 3) + ["m_platform", "Izz_platform", "g"]

PLANT = {
    "input": arr("F", 4) + WRENCH,
    "output": POSE + VEL + arr("rho", 4) + arr("drho", 4) + arr("theta1", 4) + arr("theta2", 4)
    + arr("lambda", 12) + ["constraint_residual", "jacobian_condition"],
    "parameter": GEOMETRY + MASSES + ["x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0",
                                      "solver", "rk4_step", "rtol", "atol"],
}
INVERSE = {
    "input": POSE + VEL + ACC + WRENCH,
    "output": arr("F", 4) + arr("rho", 4) + arr("drho", 4) + arr("lambda", 12),
    "parameter": GEOMETRY + MASSES,
}

_G = math.radians(65.0)
DEFAULTS = {  # MODEL_SPEC, in SI units
    "h": 0.06634, "l": 0.080, "h_prime": 0.075, "r_b": 0.09273, "r_Q": 0.075,
    "beta[1]": 0.0, "beta[2]": math.pi / 2, "beta[3]": math.pi, "beta[4]": 3 * math.pi / 2,
    "gamma[1]": _G, "gamma[2]": -_G, "gamma[3]": _G, "gamma[4]": -_G,
    "m_slider": 0.09331, "m_rod": 0.06371,
    "I_rod[1]": 3.83e-6, "I_rod[2]": 49.86e-6, "I_rod[3]": 52.64e-6,
    "m_platform": 0.45474, "Izz_platform": 2874.21e-6, "g": 9.81,
}
SOLVER_DEFAULTS = {"solver": 0, "rk4_step": 1e-3, "rtol": 1e-8, "atol": 1e-10}


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
    assert not wrong, f"{path.name}: parameter defaults differ from MODEL_SPEC:\n" + "\n".join(wrong)


def test_plant_contract(plant_fmu):
    _check_contract(plant_fmu, PLANT)


def test_inverse_contract(inverse_fmu):
    _check_contract(inverse_fmu, INVERSE)


@pytest.mark.parametrize("which", ["plant_fmu", "inverse_fmu"])
def test_parameter_defaults_are_the_spec(which, request):
    _check_defaults(request.getfixturevalue(which), DEFAULTS)


def test_plant_solver_defaults(plant_fmu):
    _check_defaults(plant_fmu, SOLVER_DEFAULTS)
