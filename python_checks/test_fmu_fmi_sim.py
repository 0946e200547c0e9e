# SPDX-License-Identifier: BSD-2-Clause
"""The FMI 3.0 FMUs in a second FMI 3.0 importer besides fmpy: fmi-sim, the
command-line simulator of the Rust `fmi` crates (crates.io/crates/fmi-sim,
version 0.7.0), with its own XML reader, loader and master loops.

Building it takes about 5 minutes on two cores, so it is not part of the test
command: scripts/fmi_sim_check.sh installs it into build/tools/fmi-sim and
runs this file with PKM_REQUIRE_FMI_SIM=1. Without fmi-sim these tests skip
(and fail when PKM_REQUIRE_FMI_SIM=1). fmi-sim is found through $PKM_FMI_SIM,
build/tools/fmi-sim/bin/fmi-sim or the PATH.

Checked:
- Co-Simulation: fmi-sim and fmpy drive the FMI 3.0 plant with the same
  constant inputs for 1 s at 1 ms steps; the outputs after every step agree
  bit for bit (one binary, the same calls: the FMU must not care who calls
  it). fmi-sim 0.7.0 steps at its output interval whatever --step says, so
  both are set to 1 ms; its step k runs from k h to (k+1) h, with the size
  (k+1) h - k h, which fmpy is given too (the result depends on the step
  size's last bit).
- Model Exchange: fmi-sim integrates with forward Euler at its output
  interval. Against the Co-Simulation result (CVODE, rtol 1e-10) its error
  must be first order: halving the step halves the error, and the Richardson
  extrapolation 2 x(h/2) - x(h) removes it down to the second-order rest.
- The inverse FMU: the forces at a pose equal fmpy's.
fmi-sim sets scalar variables only (--init-values name=value): the FMI 3.0
FMUs declare scalars with the FMI 2.0 names (docs/fmus.md, "FMI 3.0: scalars, held inputs").
"""
import csv
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pkm4puu.fmu import Fmu
from pkm4puu.locate import build_dir
from pkm4puu.interface import F, POSE
from pkm4puu.spec import STATIC_FORCE_P0

# The motion of test_fmu_flavours.py: F[1] 4.4 mN above the holding force, a
# small force along x and moment about z, so that all four coordinates move.
INPUTS = {"F[1]": STATIC_FORCE_P0 + 0.0044, "F[2]": STATIC_FORCE_P0, "F[3]": STATIC_FORCE_P0,
          "F[4]": STATIC_FORCE_P0, "Fe[1]": 0.003, "Me_z": 1e-4}
T_END, H = 1.0, 1e-3  # s


def fmi_sim():
    candidates = [os.environ.get("PKM_FMI_SIM"), str(build_dir() / "tools/fmi-sim/bin/fmi-sim"),
                  shutil.which("fmi-sim")]
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return c
    message = "fmi-sim is not installed: scripts/fmi_sim_check.sh installs it and runs these checks"
    if os.environ.get("PKM_REQUIRE_FMI_SIM") == "1":
        pytest.fail(message, pytrace=False)
    pytest.skip(message)


def run_fmi_sim(fmu, mode, values, stop, step, interval, tmp_path):
    out = tmp_path / f"{mode}.csv"
    command = [fmi_sim(), "--model", str(fmu), "-o", str(out), mode, "-f", repr(stop), "--step", repr(step),
               "--output-interval", repr(interval)]
    for name, value in values.items():
        command += ["--init-values", f"{name}={value!r}"]
    done = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ, RUST_BACKTRACE="0"),
                          timeout=300)
    assert done.returncode == 0, f"{' '.join(command)}\n{done.stdout}\n{done.stderr}"
    with open(out, newline="") as f:
        rows = list(csv.DictReader(f))
    return {name: np.array([float(r[name]) for r in rows]) for name in rows[0]}


def test_co_simulation_is_bit_identical_to_fmpy(plant_fmu3, tmp_path):
    sim = run_fmi_sim(plant_fmu3, "co-simulation", INPUTS, T_END, H, H, tmp_path)
    outputs = [n for n in sim if n != "time"]
    n = round(T_END / H)
    with Fmu(plant_fmu3, start=INPUTS) as fmu:
        rows = [fmu.get(outputs)]
        for k in range(n):
            fmu.do_step(k * H, (k + 1) * H - k * H)
            rows.append(fmu.get(outputs))
    ref = np.array(rows)
    got = np.column_stack([sim[name] for name in outputs])
    assert got.shape == ref.shape, f"fmi-sim wrote {got.shape[0]} rows, fmpy {ref.shape[0]}"
    assert np.abs(sim["x"][-1] - sim["x"][0]) > 1e-6, "the test motion must move the platform"
    differ = got != ref
    assert not differ.any(), (f"{differ.sum()} values differ; first: {outputs[np.argwhere(differ)[0][1]]}, "
                              f"max |diff| {np.abs(got - ref).max():.3g}")
    print(f"\nfmi-sim co-simulation: {got.size} output values over {T_END} s, bit-identical to fmpy")


def test_model_exchange_forward_euler_converges_at_first_order(plant_fmu3, tmp_path):
    with Fmu(plant_fmu3, start=dict(INPUTS, rtol=1e-10, atol=1e-12)) as fmu:
        for k in range(round(T_END / H)):
            fmu.do_step(k * H, H)
        exact = fmu.get(POSE)
    end = {}
    for h in (1e-3, 5e-4, 2.5e-4):
        sim = run_fmi_sim(plant_fmu3, "model-exchange", INPUTS, T_END, h, h, tmp_path)
        assert sim["time"][-1] == pytest.approx(T_END, abs=1e-12)
        end[h] = np.array([sim[n][-1] for n in POSE])
    err = {h: np.linalg.norm(x - exact) for h, x in end.items()}
    ratios = [err[1e-3] / err[5e-4], err[5e-4] / err[2.5e-4]]
    richardson = np.linalg.norm(2 * end[2.5e-4] - end[5e-4] - exact)
    print(f"\nfmi-sim forward Euler vs Co-Simulation at t = 1 s: |error| {err[1e-3]:.3g}, {err[5e-4]:.3g}, "
          f"{err[2.5e-4]:.3g} for h = 1, 0.5, 0.25 ms (ratios {ratios[0]:.3f}, {ratios[1]:.3f}); "
          f"Richardson {richardson:.3g}")
    assert err[1e-3] > 1e-8, "Euler at 1 ms must show its error, else the check is trivial"
    for r in ratios:
        assert 1.8 < r < 2.2, f"not first order: error ratios {ratios}"
    assert richardson < err[2.5e-4] / 10, f"Richardson extrapolation {richardson:.3g} vs error {err[2.5e-4]:.3g}"


def test_inverse_forces_match_fmpy(inverse_fmu3, tmp_path):
    pose = {"x": 0.003, "y": -0.002, "z": 0.06, "phi": 0.05, "ddz": 0.3}
    sim = run_fmi_sim(inverse_fmu3, "co-simulation", pose, 0.01, 0.01, 0.01, tmp_path)
    with Fmu(inverse_fmu3, start=pose) as inv:
        ref = inv.get(F)
    got = np.array([sim[n][0] for n in F])
    assert (got == ref).all(), f"fmi-sim {got} vs fmpy {ref}"
    assert np.abs(got - STATIC_FORCE_P0).max() > 1e-3, "a pose away from home must need other forces"
