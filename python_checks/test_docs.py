# SPDX-License-Identifier: BSD-2-Clause
"""The documentation's FMU snippet (docs/snippets/first_fmu.py, included by
docs/getting_started.md) runs as written with fmpy in the folder of the FMU,
and what it prints is the spec's check: the static forces of docs/model.md
hold the plant at home, P0 = (0, 0, 0.05 m, 0), with rho_i(P0) from the
spec's closed-form inverse kinematics (pkm4puu.spec, independent of the C++)."""
import re
import runpy

import numpy as np

import pkm4puu as pkm
from conftest import REPO
from pkm4puu import spec

SNIPPET = REPO / "docs" / "snippets" / "first_fmu.py"


def test_fmu_snippet_holds_the_plant_at_home(plant_fmu, capsys, monkeypatch):
    monkeypatch.chdir(plant_fmu.parent)
    runpy.run_path(str(SNIPPET), run_name="__main__")
    out = capsys.readouterr().out
    pose = re.search(r"final pose x, y, z, phi: \[(.*)\]", out)
    rho = re.search(r"rho\[1\] \(m\): (\S+)", out)
    assert pose and rho, out
    assert np.abs(np.array([float(v) for v in pose.group(1).split(",")]) - pkm.P0).max() < 1e-9
    assert abs(float(rho.group(1)) - spec.leg_inverse_kinematics(pkm.P0)[0, 0]) < 1e-9
