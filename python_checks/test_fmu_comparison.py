# SPDX-License-Identifier: BSD-2-Clause
"""The paper's comparison test (section 5.2, docs/model.md "The paper's two tests")
through the plant FMU: 1.5 s from rest at P0, gravity off, F2 = F3 = 0,
F1(t) = 0.02 N sin(2 pi t / 1.5 s) = -F4(t), midpoint-held at a 1 ms step.
The runner and the result writer are in pkm4puu.cli.comparison (the main job runs
the same code).

Checked facts, each following from the model rather than from a past run:
- the loop-closure constraints hold (the FMU reports ||C(q)||);
- with g = 0 the only vertical forces on the machine are the actuator forces
  (the frictionless vertical prismatic joints push only horizontally), and
  F1 + F4 = 0 exactly, so the vertical momentum stays zero from rest: the
  mass-weighted height of the machine, m_p z + sum(m_s rho_i + m_r z_rod_i)
  with z_rod_i = rho_i + h + (l/2) sin(theta2_i), stays constant;
- the motion is non-trivial and two different integrators (CVODE and fixed
  step RK4) agree.
The bounds are the report's (BOUNDS), which the main job's verdict uses too.
"""
import numpy as np
import pytest

from conftest import command_help, promised_files
from pkm4puu.cli.comparison import (BOUNDS, checks, format_table, max_constraint_residual, max_delta_rho1,
                                    nonfinite_outputs, run_all, solver_difference, vertical_com_drift,
                                    write_results)
from pkm4puu.spec import P0, leg_inverse_kinematics

TOL_POS, TOL_PHI, TOL_CONSTRAINT, MIN_DELTA_RHO1 = BOUNDS


@pytest.fixture(scope="module")
def runs(plant_fmu):
    out = run_all(plant_fmu)
    print("\n" + format_table(out, bounds=BOUNDS))
    return out


def test_outputs_finite(runs):
    for name, r in runs.items():
        bad = nonfinite_outputs(r)
        assert not bad, f"{name}: non-finite outputs {bad}"


def test_constraints_hold(runs):
    for name, r in runs.items():
        worst = max_constraint_residual(r)
        assert worst <= TOL_CONSTRAINT, f"{name}: max ||C(q)|| = {worst:.3e} m > {TOL_CONSTRAINT} m"


def test_motion_is_nontrivial(runs):
    r = runs["CVODE"]
    d_rho1 = max_delta_rho1(r)
    print(f"\ncomparison test: max |delta rho1| = {d_rho1:.4e} m")
    assert d_rho1 > MIN_DELTA_RHO1, f"max |delta rho1| = {d_rho1:.3e} m: the forces barely moved the machine"


def test_vertical_centre_of_mass_stays(runs):
    for name, r in runs.items():
        drift = vertical_com_drift(r)
        print(f"\n{name}: vertical centre-of-mass drift {drift:.3e} m")
        assert drift <= TOL_POS, f"{name}: vertical centre of mass moved {drift:.3e} m with zero net vertical force"


def test_rk4_agrees_with_cvode(runs):
    d_pos, d_phi = solver_difference(runs["CVODE"], runs["RK4"])
    print(f"\nCVODE vs RK4: max |delta position| {d_pos:.3e} m, |delta phi| {d_phi:.3e} rad")
    assert d_pos <= TOL_POS, f"CVODE and RK4 differ by {d_pos:.3e} m > {TOL_POS} m"
    assert d_phi <= TOL_PHI, f"CVODE and RK4 differ by {d_phi:.3e} rad > {TOL_PHI} rad"


def test_verdict_checks_what_the_tests_check(runs):
    """The main job's verdict (checks) holds the runs to BOUNDS on the same
    quantities as the tests above, and the non-trivial motion's check is a
    lower bound: it fails when the bound is above the measured motion."""
    lines = checks(runs)
    assert len(lines) == 2 * len(runs) + 3
    assert all(c.passed for c in lines), [c for c in lines if not c.passed]
    moved = max_delta_rho1(runs["CVODE"])
    assert not all(c.passed for c in checks(runs, BOUNDS._replace(min_delta_rho1=2 * moved)))


def test_write_results(runs, results_dir):
    """The files, each not empty: those `pkm4puu comparison --help` promises
    but the checks (written beside them by the program)."""
    paths = write_results(runs, results_dir)
    for path in paths:
        assert path.stat().st_size > 0, f"{path} is empty"
    assert {p.name for p in paths} | {"comparison_checks.csv"} == promised_files(command_help("comparison"))
    # What the CSV says, read back: every row's rho_i is the spec's closed-form
    # inverse kinematics of its pose, to the 13 digits written (5e-13 of
    # 0.1 m, a few times over through the kinematics), and delta_rho1 is
    # rho1 - rho1(0); the first row is P0.
    table = np.genfromtxt(paths[0], delimiter=",", names=True)
    pose = np.column_stack([table[n] for n in ("x", "y", "z", "phi")])
    rho = np.column_stack([table[f"rho{i}"] for i in range(1, 5)])
    ik = np.array([leg_inverse_kinematics(p)[:, 0] for p in pose])
    written = 5e-13 * 0.1
    assert np.abs(rho - ik).max() <= 10 * written, np.abs(rho - ik).max()
    assert np.abs(table["delta_rho1"] - (rho[:, 0] - rho[0, 0])).max() <= 2 * written
    np.testing.assert_allclose(pose[0], P0, rtol=0, atol=written)
