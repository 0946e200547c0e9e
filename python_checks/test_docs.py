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


INVERSE_SNIPPET = REPO / "docs" / "snippets" / "fmu_inverse.py"


def test_fmu_inverse_snippet_gives_the_vertical_momentum_balance(inverse_fmu, capsys, monkeypatch):
    """At rest, z = 60 mm, accelerating straight up at 0.5 m/s^2: a vertical
    translation keeps every leg angle (the sliders are vertical), so every
    body accelerates at z'' and the frictionless vertical joints carry all
    of it: sum F = M g (g + z'')/g, with M g = 4 x the spec's holding force
    at P0 (docs/model.md: 2.655616050 N each)."""
    monkeypatch.chdir(inverse_fmu.parent)
    runpy.run_path(str(INVERSE_SNIPPET), run_name="__main__")
    out = capsys.readouterr().out
    m = re.search(r"F \(N\): \[(.*)\]", out)
    assert m, out
    forces = [float(v) for v in m.group(1).split(",")]
    assert len(forces) == 4
    weight = 4 * pkm.STATIC_FORCE_P0
    # the spec gives the holding force to 9 decimals: +-0.5e-9 N each
    tolerance = 4 * 0.5e-9 * (spec.G + 0.5) / spec.G + 1e-12
    assert abs(sum(forces) - weight * (spec.G + 0.5) / spec.G) < tolerance
