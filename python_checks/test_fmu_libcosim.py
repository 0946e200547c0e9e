# SPDX-License-Identifier: BSD-2-Clause
"""A co-simulation master other than fmpy: libcosim (Open Simulation Platform,
through libcosimpy) loads the plant FMU, runs 1 s with constant actuator
forces at a 1 ms step, and ends where fmpy's run of the same case ends."""
import numpy as np
import pytest

from pkm4puu.fmu import Fmu, run
from pkm4puu.interface import F, POSE

H_NS = 1_000_000  # 1 ms, libcosim counts time in nanoseconds
DURATION_NS = 1_000_000_000  # 1 s
FORCES = [2.7, 2.6, 2.65, 2.66]  # N, near the static 2.6556 N: a bounded, non-trivial motion
TOL = 1e-9


@pytest.fixture(scope="module")
def cosim():
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
        from libcosimpy.CosimSlave import CosimLocalSlave
    except Exception as e:  # not a skip: this check is part of the suite
        pytest.fail(f"libcosimpy cannot be imported ({e!r}); install the pinned requirements: "
                    ".venv/bin/pip install -r python_checks/requirements.txt", pytrace=False)
    log_output_level(CosimLogLevel.WARNING)
    return CosimExecution, CosimObserver, CosimLocalSlave


def run_libcosim(cosim, fmu_path):
    CosimExecution, CosimObserver, CosimLocalSlave = cosim
    execution = CosimExecution.from_step_size(step_size=H_NS)
    slave = CosimLocalSlave(fmu_path=str(fmu_path), instance_name="plant")
    index = execution.add_local_slave(local_slave=slave)
    assert index >= 0, f"libcosim could not add {fmu_path.name}"
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer=observer)

    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    missing = [n for n in F + POSE + ["solver"] if n not in refs]
    assert not missing, f"libcosim does not see the variables {missing}"
    assert execution.integer_initial_value(index, refs["solver"], 0)
    for name, value in zip(F, FORCES):
        assert execution.real_initial_value(index, refs[name], value), f"could not set {name}"

    assert execution.simulate_until(target_time=DURATION_NS), f"libcosim run failed: {execution.status()}"
    status = execution.status()
    assert status.current_time == DURATION_NS, f"libcosim stopped at {status.current_time} ns"
    return np.array(observer.last_real_values(index, [refs[n] for n in POSE]))


def run_fmpy(fmu_path):
    """The same case through fmpy: forces set once, as initial values."""
    with Fmu(fmu_path, start={"solver": 0, **dict(zip(F, FORCES))}) as fmu:
        _, Y = run(fmu, 0.0, H_NS * 1e-9, DURATION_NS // H_NS, lambda f, k, t: None, POSE)
    return Y


def test_libcosim_agrees_with_fmpy(cosim, plant_fmu):
    by_libcosim = run_libcosim(cosim, plant_fmu)
    fmpy_run = run_fmpy(plant_fmu)
    by_fmpy = fmpy_run[-1]
    diff = np.abs(by_libcosim - by_fmpy)
    print(f"\nlibcosim vs fmpy at t = 1 s: (x, y, z, phi) = {by_libcosim}, max |diff| = {diff.max():.3e}")
    assert np.all(np.isfinite(by_libcosim)), f"libcosim outputs {by_libcosim}"
    moved = np.abs(by_fmpy - fmpy_run[0]).max()
    assert moved > 1e-6, f"the platform barely moved ({moved:.2e}): the comparison would be trivial"
    assert diff.max() <= TOL, f"libcosim {by_libcosim} vs fmpy {by_fmpy}: max |diff| {diff.max():.3e} > {TOL}"

