# SPDX-License-Identifier: BSD-2-Clause
"""CVODE continued across communication points, and FMU states.

With CVODE the plant FMU keeps the integrator's history from one doStep to
the next when the inputs continue (held constant, or given with their
derivatives); it restarts where they jump and after setFMUState (SUNDIALS
cannot set CVODE's multistep history, so a saved state does not hold it).
Taking a state is an observation (FMI 2.0 section 2.1.8, FMI 3.0 section
2.2.6: getFMUState copies the state): the original run does not restart
there. Checked here:

- saving the state before every step changes nothing: the run is the one
  without, bit for bit (a ramp of values and slopes, FMI 2.0, and held
  inputs, FMI 3.0, which has no input derivatives);
- a state saved where the history continues restores into a run that
  restarts CVODE there: within one restart's error of the original (one
  step's error weight, ONE_STEP), not bit for bit; saved where the inputs
  jump (the original restarts there too) it restores bit for bit;
- the continuation happens: the same run restarted at every step (a
  setFMUState of the state just taken) is not bit-identical to it; the
  continued run stays within one step's error weight (ONE_STEP) of a
  reference integrated at rtol 1e-12, the restarted one within what rtol
  1e-8 allows over N steps (BOUND).
"""
import numpy as np
import pytest

from pkm4puu.fmu import Fmu
from pkm4puu.interface import F, POSE, VEL
from pkm4puu.spec import SOLVER_DEFAULTS, STATIC_FORCE_P0

H = 1e-3
N = 600
OUT = POSE + VEL
RTOL, ATOL = SOLVER_DEFAULTS["rtol"], SOLVER_DEFAULTS["atol"]  # the FMU's defaults
# rtol on positions of ~0.05 m, accumulated over N steps: a deviation of
# N x rtol x 0.05 m = 3e-7 m would be the solver's whole error budget; every
# run must stay within it of the reference, and so of each other.
BOUND = N * RTOL * 0.05
# CVODE's error test keeps each internal step's local error within its weight
# rtol |y| + atol: 6e-10 m on z ~ 0.05 m. A run that continues its history is
# one integration of a smooth, slow motion, which adds no error of its own at
# a communication point: it stays within one step's weight. A restart starts
# again at order 1 with a first step sized for an error near that weight
# (CVODE's initial step estimate), so N restarts add N such errors and lose
# the bound (measured: 1.2e-8 m restarted at every step, 20 times it).
ONE_STEP = RTOL * 0.05 + ATOL

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
    else:  # held: piecewise constant, jumping every 100 steps
        fmu.set(F, force(H * 100 * (k // 100))[0])
    fmu.do_step(t, H, no_set_prior=False)
    return fmu.get(OUT)


def run(fmu, k0, k1, ramp, between=None):
    """Steps k0 .. k1-1; `between(fmu)` before each."""
    rows = []
    for k in range(k0, k1):
        if between:
            between(fmu)
        rows.append(step(fmu, k, ramp))
    return np.array(rows)


def save_and_serialize(fmu):
    state = fmu.get_state()
    try:
        assert len(fmu.serialize(state)) > 0
    finally:
        fmu.free_state(state)


def restart_here(fmu):
    state = fmu.get_state()
    try:
        fmu.set_state(state)
    finally:
        fmu.free_state(state)


CASES = [("plant_fmu", True), ("plant_fmu3", False)]


@pytest.mark.parametrize("archive,ramp", CASES)
def test_saving_the_state_changes_nothing(archive, ramp, request):
    path = request.getfixturevalue(archive)
    with Fmu(path, start={"solver": 0}) as fmu:
        plain = run(fmu, 0, N, ramp)
    with Fmu(path, start={"solver": 0}, instance_name="saving") as fmu:
        saving = run(fmu, 0, N, ramp, between=save_and_serialize)
    same = plain == saving
    assert same.all(), (f"{(~same).sum()} values differ with getFMUState before every step; largest difference "
                        f"{np.abs(plain - saving).max():.3e}")


@pytest.mark.parametrize("archive,ramp,k_save,exact", [
    ("plant_fmu", True, 300, False),    # a ramp continues: CVODE's history continues at the save
    ("plant_fmu3", False, 250, False),  # held inputs, between two jumps
    ("plant_fmu3", False, 300, True),   # the inputs jump at the save: the original restarts there too
])
def test_restored_run_restarts_cvode(archive, ramp, k_save, exact, request):
    with Fmu(request.getfixturevalue(archive), start={"solver": 0}) as fmu:
        run(fmu, 0, k_save, ramp)
        state = fmu.get_state()
        try:
            first = run(fmu, k_save, N, ramp)
            fmu.set_state(state)
            replay = run(fmu, k_save, N, ramp)
        finally:
            fmu.free_state(state)
    moved = np.abs(first[-1, :3] - first[0, :3]).max()
    assert moved > 1e-5, f"the platform barely moved ({moved:.2e} m): the check would be trivial"
    dev = np.abs(replay[:, :3] - first[:, :3]).max()
    print(f"\n{archive}, saved after step {k_save}: max |replay - original| = {dev:.3e} m "
          f"(bound {ONE_STEP:.1e} m)")
    if exact:
        same = first == replay
        assert same.all(), f"{(~same).sum()} values differ after the restore; largest difference {dev:.3e}"
    assert dev <= ONE_STEP, (f"the restored run, which restarts once, is {dev:.3e} m from the original, beyond "
                             f"one step's error weight {ONE_STEP:.1e} m")


def test_continuation_happens_and_keeps_accuracy(plant_fmu):
    with Fmu(plant_fmu, start={"solver": 0}) as fmu:
        continued = run(fmu, 0, N, True)
    with Fmu(plant_fmu, start={"solver": 0}, instance_name="restarted") as fmu:
        restarted = run(fmu, 0, N, True, between=restart_here)
    with Fmu(plant_fmu, start={"solver": 0, "rtol": 1e-12, "atol": 1e-14}, instance_name="reference") as fmu:
        reference = run(fmu, 0, N, True, between=restart_here)
    assert not (continued == restarted).all(), "no difference: CVODE restarted at every step anyway"
    for name, rows, bound in (("continued", continued, ONE_STEP), ("restarted", restarted, BOUND)):
        dev = np.abs(rows[:, :3] - reference[:, :3]).max()
        print(f"\n{name}: max |x, y, z - reference| = {dev:.3e} m (bound {bound:.1e} m)")
        assert dev <= bound, f"{name}: {dev:.3e} m from the rtol 1e-12 reference, bound {bound:.1e} m"
