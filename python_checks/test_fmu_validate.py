# SPDX-License-Identifier: BSD-2-Clause
"""fmpy's validator (schema, names, ModelStructure, start values, causality /
variability, units) finds no problem in either FMU."""
import pytest
from fmpy.validation import validate_fmu


@pytest.mark.parametrize("which", ["plant_fmu", "inverse_fmu"])
def test_validate_fmu(which, request):
    path = request.getfixturevalue(which)
    problems = validate_fmu(str(path))
    for problem in problems:
        print(f"{path.name}: {problem}")
    assert not problems, f"{path.name}: {len(problems)} validation problem(s):\n" + "\n".join(problems)
