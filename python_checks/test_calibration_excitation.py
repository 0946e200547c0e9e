# SPDX-License-Identifier: BSD-2-Clause
"""`python -m pkm4puu excitation` (pkm4puu.calibration.optimise_excitation):
the optimised trajectory it writes holds the limits it was given at every
sample of its 1 kHz CSV (the optimiser enforces them on coarser grids),
the forces recomputed by the C API's inverse dynamics; its rates are its
positions' derivatives."""
import csv

import numpy as np
import pytest

from pkm4puu import capi
from pkm4puu.calibration.parameters import make_plant
from pkm4puu.cli.excitation import main


@pytest.fixture(scope="module")
def run(tmp_path_factory, pkm_library):
    out = tmp_path_factory.mktemp("excitation") / "traj.csv"
    args = ["--period", "2.0", "--harmonics", "4", "--xy", "0.008", "--z", "0.05", "0.07", "--phi", "0.1",
            "--speed", "0.12", "--force", "20", "--out", str(out)]
    assert main(args) == 0
    with open(out) as f:
        rows = list(csv.reader(f))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    return {h: data[:, k] for k, h in enumerate(header)}


def test_the_trajectory_holds_its_limits_at_every_sample(run, pkm_library):
    assert len(run["t"]) == 2000
    assert np.abs(run["x"]).max() <= 0.008 and np.abs(run["y"]).max() <= 0.008
    assert run["z"].min() >= 0.05 and run["z"].max() <= 0.07
    assert np.abs(run["phi"]).max() <= 0.1
    rho = np.column_stack([run[f"rho[{i}]"] for i in range(1, 5)])
    drho = np.column_stack([run[f"drho[{i}]"] for i in range(1, 5)])
    assert rho.min() >= 0.005 and rho.max() <= 0.145  # the default 5 mm from the stops at 0 and 0.15 m
    assert np.abs(drho).max() <= 0.12
    lib = capi.load(pkm_library)
    with capi.Plant(lib) as p:  # the spec's parameters, the command's default nominal model
        for k in range(0, len(run["t"]), 7):
            pose, vel, acc = ([run[n][k] for n in names] for names in (("x", "y", "z", "phi"),
                                                                        ("dx", "dy", "dz", "dphi"),
                                                                        ("ddx", "ddy", "ddz", "ddphi")))
            F = p.inverse_dynamics(pose, vel, acc).F
            assert np.abs(F).max() <= 20.0, (k, F)


def test_the_trajectory_is_periodic_and_consistent(run):
    """The CSV's rates are the positions' derivatives (central differences,
    error h^2/6 |x'''| well below the tolerance) and the series is periodic."""
    h = run["t"][1] - run["t"][0]
    for a, da in (("x", "dx"), ("phi", "dphi"), ("dz", "ddz"), ("rho[2]", "drho[2]")):
        fd = (run[a][2:] - run[a][:-2]) / (2 * h)
        assert np.abs(fd - run[da][1:-1]).max() <= 1e-3 * np.abs(run[da]).max()
