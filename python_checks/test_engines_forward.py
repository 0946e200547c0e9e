# SPDX-License-Identifier: BSD-2-Clause
"""Forward dynamics against Pinocchio, the spec's comparison test (docs/model.md
"Comparison test": g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), F2 = F3 = 0,
1.5 s from rest at P0). The runners are in engine_comparison.py.

- The reference: Pinocchio's constrained forward dynamics (KKT system from
  CRBA, RNEA and the point-constraint Jacobians), 32 states integrated by
  DOP853 at rtol 1e-13 with the exact forces. It must itself be decided far
  below the bounds below: fixed-step RK4 at 0.5 ms around Pinocchio's own
  constraintDynamics must agree with it to 1e-12 m / 1e-11 rad, and its
  ||C(q)|| must stay below 1e-12 m.
- The C API with the forces evaluated at the integrator's own times
  (pkm_advance_fn with a callback; CVODE rtol 1e-12, atol 1e-14, and RK4 at
  1 ms): pose and delta rho1 within 1e-10 m and 1e-9 rad, ||C(q)|| <= 1e-12 m.
- The plant FMU at a 1 ms communication step, forces held at each step's
  midpoint value (RK4 1 ms, and CVODE rtol 1e-10): within 1e-8 m and
  3e-7 rad of the exact-force reference (the hold itself costs ~1e-7 rad on
  this sensitive test).
- MuJoCo (RK4, 1 ms, midpoint-held forces, the stiffest connect constraints):
  its agreement and its own constraint violation are reported; it must agree
  at the FMU's level (it sees the same hold) and keep ||C(q)|| within 1e-9 m.
"""
import numpy as np
import pytest

from conftest import command_help, promised_files
from pkm4puu.cli.engine_comparison import (CAPI_SOLVERS, TIMES, TOL_CONSTRAINT, TOL_FMU_PHI, TOL_FMU_POS, TOL_PHI,
                                           TOL_POS, TOL_REF_PHI, TOL_REF_POS, capi_run, deviation, fmu_runs, load_capi,
                                           mujoco_run, pinocchio_reference, pinocchio_rk4)
from pkm4puu.cli.engine_report import write_results


@pytest.fixture(scope="module")
def ref():
    return pinocchio_reference("exact")


@pytest.fixture(scope="module")
def ref_held():
    return pinocchio_reference("midpoint")


@pytest.fixture(scope="module")
def capi(pkm_library):
    lib = load_capi(pkm_library.parent.parent)
    return {name: capi_run(lib, s) for name, s in CAPI_SOLVERS.items()}


@pytest.fixture(scope="module")
def fmu(plant_fmu):
    return fmu_runs(plant_fmu)


@pytest.fixture(scope="module")
def mujoco_result():
    return mujoco_run()


def test_reference_is_converged(ref):
    cross = pinocchio_rk4(5e-4)
    d_pos, d_phi = deviation(cross, ref)
    c = ref["constraint"].max()
    print(f"\nreference: {ref['nfev']} evaluations, max ||C|| {c:.2e} m; vs constraintDynamics + RK4 0.5 ms: "
          f"{d_pos:.2e} m, {d_phi:.2e} rad")
    assert c <= TOL_CONSTRAINT, f"the reference drifts off the constraints: {c:.3e} m"
    assert d_pos <= TOL_REF_POS and d_phi <= TOL_REF_PHI, (d_pos, d_phi)


def test_motion_is_nontrivial(ref):
    assert np.abs(ref["delta_rho1"]).max() > 1e-3
    assert np.abs(ref["phi"]).max() > 0.1


@pytest.mark.parametrize("solver", list(CAPI_SOLVERS))
def test_capi_matches_pinocchio(capi, ref, solver):
    run = capi[solver]
    d_pos, d_phi = deviation(run, ref)
    c = run["constraint"].max()
    print(f"\nC API {solver} vs Pinocchio: {d_pos:.3e} m, {d_phi:.3e} rad; max ||C|| {c:.2e} m")
    # the forces were evaluated at the integrator's own times, off the 1 ms grid
    t_in = run["input_times"]
    assert np.any(np.abs(t_in / 1e-3 - np.round(t_in / 1e-3)) > 1e-6), "no input evaluation between grid points"
    assert d_pos <= TOL_POS, f"C API {solver}: max |d pose, d delta rho1| = {d_pos:.3e} m > {TOL_POS} m"
    assert d_phi <= TOL_PHI, f"C API {solver}: max |d phi| = {d_phi:.3e} rad > {TOL_PHI} rad"
    assert c <= TOL_CONSTRAINT, f"C API {solver}: max ||C(q)|| = {c:.3e} m"


@pytest.mark.parametrize("solver", ["CVODE", "RK4"])
def test_plant_fmu_matches_pinocchio(fmu, ref, ref_held, solver):
    run = fmu[solver]
    assert len(run["t"]) == len(TIMES) and np.abs(run["t"] - TIMES).max() < 1e-12
    d_pos, d_phi = deviation(run, ref)
    h_pos, h_phi = deviation(run, ref_held)
    c = run["constraint"].max()
    print(f"\nplant FMU {solver} vs Pinocchio: {d_pos:.3e} m, {d_phi:.3e} rad (vs Pinocchio with the same "
          f"held forces: {h_pos:.2e} m, {h_phi:.2e} rad); max ||C|| {c:.2e} m")
    assert d_pos <= TOL_FMU_POS, f"plant FMU {solver}: {d_pos:.3e} m > {TOL_FMU_POS} m"
    assert d_phi <= TOL_FMU_PHI, f"plant FMU {solver}: {d_phi:.3e} rad > {TOL_FMU_PHI} rad"
    assert c <= TOL_CONSTRAINT, f"plant FMU {solver}: max ||C(q)|| = {c:.3e} m"


def test_mujoco_agreement_and_constraint_violation(mujoco_result, ref, ref_held):
    d_pos, d_phi = deviation(mujoco_result, ref)
    h_pos, h_phi = deviation(mujoco_result, ref_held)
    c = mujoco_result["constraint"].max()
    print(f"\nMuJoCo vs Pinocchio: {d_pos:.3e} m, {d_phi:.3e} rad (vs the same held forces: {h_pos:.2e} m, "
          f"{h_phi:.2e} rad); MuJoCo's max ||C(q)|| {c:.2e} m")
    assert d_pos <= TOL_FMU_POS and d_phi <= TOL_FMU_PHI, (d_pos, d_phi)
    assert 0.0 < c <= 1e-9, f"MuJoCo's constraint violation {c:.3e} m"


def test_write_results(ref, ref_held, capi, fmu, mujoco_result, results_dir):
    r = {"ref": ref, "ref_held": ref_held, "capi": capi, "fmu": fmu, "mujoco": mujoco_result}
    paths = write_results(r, results_dir)
    for path in paths:
        assert path.stat().st_size > 0, f"{path} is empty"
    assert {p.name for p in paths} == promised_files(command_help("engines"))
    # What the CSV says, read back: this model (C API, CVODE) against Pinocchio
    # within the bounds above, on the times of the comparison test.
    table = np.genfromtxt(paths[0], delimiter=",", names=True)
    np.testing.assert_allclose(table["t"], TIMES, rtol=0, atol=5e-7)  # written to 1 us
    d_pos = max(np.abs(table[f"capi_cvode_{n}"] - table[f"pinocchio_{n}"]).max()
                for n in ("x", "y", "z", "delta_rho1"))
    d_phi = np.abs(table["capi_cvode_phi"] - table["pinocchio_phi"]).max()
    assert d_pos <= TOL_POS and d_phi <= TOL_PHI, (d_pos, d_phi)
    assert table["capi_cvode_constraint"].max() <= TOL_CONSTRAINT
