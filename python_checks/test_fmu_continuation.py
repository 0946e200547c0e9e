# SPDX-License-Identifier: BSD-2-Clause
"""CVODE continued across communication points.

With CVODE the plant FMU keeps the integrator's history from one fmi2DoStep
to the next when the inputs continue (held constant, or given with their
derivatives); it restarts where they jump, after fmi2SetFMUstate, and after
fmi2GetFMUstate (the saved state does not hold the history, so the original
run restarts there as the restored one does). Checked here:

- a run that continues restores bit for bit: a state saved in the middle of
  a force ramp (values and slopes each step, FMI 2.0) or of held inputs (FMI 3.0,
  which has no input derivatives) replays the rest exactly;
- the continuation happens: the same run with a GetFMUstate after every step
  (a restart at every step) is not bit-identical to it, and both agree with
  a reference integrated at rtol 1e-12 to within what rtol 1e-8 allows.
"""
import numpy as np
import pytest

from pkm4puu.fmu import Fmu
from pkm4puu.interface import F, POSE, VEL
from pkm4puu.spec import STATIC_FORCE_P0

H = 1e-3
N, K_SAVE = 600, 300
OUT = POSE + VEL


SLOPES = [0.4, -0.3, 0.2, -0.1]  # N/s


def force(t):
    """Value and slope of a force ramp on each leg (the platform moves in all
    four coordinates)."""
    return [STATIC_FORCE_P0 + s * t for s in SLOPES], SLOPES


def step(fmu, k, ramp):
    t = k * H
    if ramp:
        u, du = force(t)
        fmu.set(F, u)
        fmu.set_derivatives(F, du)
    else:  # held: piecewise constant, changing every 100 steps
        fmu.set(F, force(H * 100 * (k // 100))[0])
    fmu.do_step(t, H, no_set_prior=False)
    return fmu.get(OUT)


def run(fmu, k0, k1, ramp, save_every_step=False):
    rows = []
    for k in range(k0, k1):
        rows.append(step(fmu, k, ramp))
        if save_every_step:
            fmu.free_state(fmu.get_state())
    return np.array(rows)


@pytest.mark.parametrize("archive,ramp", [("plant_fmu", True), ("plant_fmu3", False)])
def test_continued_run_restores_bit_for_bit(archive, ramp, request):
    with Fmu(request.getfixturevalue(archive), start={"solver": 0}) as fmu:
        run(fmu, 0, K_SAVE, ramp)
        state = fmu.get_state()
        try:
            first = run(fmu, K_SAVE, N, ramp)
            fmu.set_state(state)
            replay = run(fmu, K_SAVE, N, ramp)
        finally:
            fmu.free_state(state)
    moved = np.abs(first[-1, :3] - first[0, :3]).max()
    assert moved > 1e-5, f"the platform barely moved ({moved:.2e} m): the check would be trivial"
    same = first == replay
    assert same.all(), (f"{(~same).sum()} values differ after the restore; largest difference "
                        f"{np.abs(first - replay).max():.3e}")


def test_continuation_happens_and_keeps_accuracy(plant_fmu):
    with Fmu(plant_fmu, start={"solver": 0}) as fmu:
        continued = run(fmu, 0, N, True)
    with Fmu(plant_fmu, start={"solver": 0}, instance_name="restarted") as fmu:
        restarted = run(fmu, 0, N, True, save_every_step=True)
    with Fmu(plant_fmu, start={"solver": 0, "rtol": 1e-12, "atol": 1e-14}, instance_name="reference") as fmu:
        reference = run(fmu, 0, N, True, save_every_step=True)
    assert not (continued == restarted).all(), "no difference: CVODE restarted at every step anyway"
    # rtol 1e-8 on positions of ~0.05 m, accumulated over 600 steps: a
    # deviation of 600 x 1e-8 x 0.05 m = 3e-7 m would be the solver's whole
    # error budget; both runs must stay within it.
    bound = N * 1e-8 * 0.05
    for name, rows in (("continued", continued), ("restarted", restarted)):
        dev = np.abs(rows[:, :3] - reference[:, :3]).max()
        print(f"\n{name}: max |x, y, z - reference| = {dev:.3e} m (bound {bound:.1e} m)")
        assert dev <= bound, f"{name}: {dev:.3e} m from the rtol 1e-12 reference, bound {bound:.1e} m"
