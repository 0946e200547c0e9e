# SPDX-License-Identifier: BSD-2-Clause
"""examples/ssp_cosim.py: the auto-test as an SSP system (inverse.F ->
plant.F) loaded and run by libcosim (libcosimpy)."""
import csv
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from pkm4puu.cli.autotest import BOUNDS
from pkm4puu.fmu import Fmu, inverse_forces, run
from pkm4puu.interface import F, POSE
from pkm4puu.motions import pose_at
from example_scripts import load_example

ssp_cosim = load_example("ssp_cosim")

H = ssp_cosim.H
N = ssp_cosim.N_STEPS
SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"


@pytest.fixture(scope="module")
def ssp_file(plant_fmu, inverse_fmu, tmp_path_factory):
    try:
        import libcosimpy  # noqa: F401
    except Exception as e:  # not a skip: this check is part of the suite
        pytest.fail(f"libcosimpy cannot be imported ({e!r}); install the pinned requirements", pytrace=False)
    return ssp_cosim.write_ssp(plant_fmu, inverse_fmu, tmp_path_factory.mktemp("ssp") / "PKM4PUU_autotest.ssp")


@pytest.fixture(scope="module")
def compensated(ssp_file):
    return ssp_cosim.run_ssp(ssp_file)


def fmpy_midpoint_run(plant_fmu, inverse_fmu):
    """The midpoint-held auto-test through fmpy (pkm4puu.cli.autotest's
    'midpoint' case, CVODE): the plant holds F(t_k + h/2) over [t_k, t_k + h]."""
    with Fmu(inverse_fmu) as inv:
        Fm = inverse_forces(inv, (np.arange(N) + 0.5) * H)
    with Fmu(plant_fmu, start={**ssp_cosim.START_P0, "solver": 0}) as fmu:
        _, Y = run(fmu, 0.0, H, N, lambda f, k, t: f.set(F, Fm[k]), POSE)
    return Y


def test_ssp_archive_structure(ssp_file):
    with zipfile.ZipFile(ssp_file) as z:
        names = set(z.namelist())
        assert {"SystemStructure.ssd", "resources/PKM4PUU.fmu", "resources/PKM4PUU_Inverse.fmu"} <= names
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    comps = {c.get("name"): c.get("source") for c in root.iter(f"{SSD}Component")}
    assert comps == {"inverse": "resources/PKM4PUU_Inverse.fmu", "plant": "resources/PKM4PUU.fmu"}
    conns = sorted((c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
                   for c in root.iter(f"{SSD}Connection"))
    assert conns == [("inverse", f, "plant", f) for f in F]


def test_libcosim_reproduces_the_autotest(compensated, plant_fmu, inverse_fmu):
    """With the inverse FMU's inputs leading by 3h/2 the plant holds
    F(t_k + h/2) over every step: the midpoint-held auto-test, whose bound
    pkm4puu.cli.autotest sets at 5e-8 m / 5e-8 rad (measured 1.1e-8 m,
    1.4e-8 rad with CVODE). It is the same computation as fmpy's, so the two
    runs agree to rounding: 6e-14 m measured, from the step times, which
    libcosim counts in integer nanoseconds, differing from fmpy's k * 1e-3 in
    their last bits (CVODE's steps depend on them; with RK4 the runs agree to
    1.5e-16 m)."""
    r = compensated
    print(f"\nlibcosim SSP auto-test: max position error {r.pos_err.max():.3e} m, "
          f"max phi error {r.phi_err.max():.3e} rad")
    assert np.all(np.isfinite(r.pose))
    assert r.pos_err.max() <= BOUNDS.position
    assert r.phi_err.max() <= BOUNDS.phi
    by_fmpy = fmpy_midpoint_run(plant_fmu, inverse_fmu)
    diff = np.abs(r.pose - by_fmpy).max()
    print(f"libcosim vs fmpy (midpoint hold): max |diff| = {diff:.3e}")
    assert diff <= 1e-12


def test_without_lead_the_connection_delay_shows(plant_fmu, inverse_fmu, tmp_path, compensated):
    """No lead: the plant holds F(t_k - h) over [t_k, t_k + h], a 3h/2 lag,
    an O(h) error (~3e-5 m) instead of the O(h^2) one: the compensation is what
    makes the SSP reproduce the auto-test."""
    path = ssp_cosim.write_ssp(plant_fmu, inverse_fmu, tmp_path / "nolead.ssp", lead=0.0)
    lagged = ssp_cosim.run_ssp(path, lead=0.0)
    print(f"\nno lead: max position error {lagged.pos_err.max():.3e} m (compensated "
          f"{compensated.pos_err.max():.3e} m)")
    assert lagged.pos_err.max() > 100 * compensated.pos_err.max()


def test_command_line(plant_fmu, tmp_path):
    assert ssp_cosim.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--solver", "rk4"]) == 0
    for name in ("PKM4PUU_autotest.ssp", "ssp_autotest.csv", "ssp_autotest_errors.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    # The compensated run's written pose against the spec's prescribed motion:
    # within the midpoint-held auto-test's bounds.
    with open(tmp_path / "ssp_autotest.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    run = next(k for k in rows[0] if k.endswith("_x_m"))[:-len("_x_m")]  # the first run written
    assert "compensated" in run, run
    t = np.array([float(r["t_s"]) for r in rows])
    pose = np.array([[float(r[f"{run}_{q}"]) for q in ("x_m", "y_m", "z_m", "phi_rad")] for r in rows])
    prescribed = np.array([pose_at(tk) for tk in t])
    assert t[-1] == pytest.approx(N * H)
    assert np.linalg.norm(pose[:, :3] - prescribed[:, :3], axis=1).max() <= BOUNDS.position
    assert np.abs(pose[:, 3] - prescribed[:, 3]).max() <= BOUNDS.phi
