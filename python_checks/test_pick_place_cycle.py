# SPDX-License-Identifier: BSD-2-Clause
"""`pkm4puu cycle` (python -m pkm4puu cycle): the standard pick-and-place
cycle's CSV and figure, the cycle closed-loop through the plant FMU (its
CSV, tracking, forces and energy), its table, and bad input answered in one line with
exit status 2 and nothing written: values that are not finite or are
negative, a path that leaves the workspace or crosses a singularity (where
and which leg, checked against the spec's closed-form inverse kinematics),
limits below what holding the payload needs (which actuator and where,
checked against the C API's inverse dynamics)."""
import contextlib
import io
import math
import re
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO, command_help, promised_files
from pkm4puu import capi, spec
from pkm4puu.planning import segment
from pkm4puu.cli import cycle as program

# The columns of cycle.csv as docs/pick_and_place.md (and the issue) list them.
CSV_COLUMNS = ("t x y z phi dx dy dz dphi ddx ddy ddz ddphi F[1] F[2] F[3] F[4] payload_mass").split()
# closed_loop.csv's first columns, as the issue asks for them.
LOOP_COLUMNS = "t x y z phi x_ref y_ref z_ref phi_ref".split()
TRACKING_BOUND = 1e-4  # m: the 0.1 mm


def run(*args):
    """The program's main(ARGS) in this process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = program.main(list(args))
        except SystemExit as e:  # argparse
            status = e.code
    return status, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def standard(tmp_path_factory):
    """python -m pkm4puu cycle --out DIR, as a user runs it."""
    out = tmp_path_factory.mktemp("cycle") / "out"
    r = subprocess.run([sys.executable, "-m", "pkm4puu", "cycle", "--out", str(out)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    return out, r.stdout


def test_standard_cycle_csv(standard, pkm_library):
    """cycle.csv holds the whole cycle at 0.1 ms (1 ms or finer is asked),
    from rest at A to rest at A through B, where the payload (0.25 kg from
    A, none back) is released at rest; the printed cycle time is its last
    time; its forces are the C API's inverse dynamics at its motion."""
    out, stdout = standard
    with open(out / "cycle.csv") as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(out / "cycle.csv", delimiter=",", skiprows=1)
    assert header == CSV_COLUMNS
    col = {name: k for k, name in enumerate(header)}
    t = data[:, col["t"]]
    assert t[0] == 0.0 and np.all(np.diff(t) >= 0) and np.diff(t).max() <= 1e-3 + 1e-15
    cycle_time = float(re.search(r"cycle time: ([0-9.]+) s", stdout).group(1))
    assert t[-1] == pytest.approx(cycle_time, abs=5e-5)
    release = np.flatnonzero(np.diff(t) == 0)
    assert len(release) == 1
    k = release[0]
    mass = data[:, col["payload_mass"]]
    assert np.all(mass[:k + 1] == spec.CYCLE_PAYLOAD) and np.all(mass[k + 1:] == 0.0)
    pose = data[:, 1:5]
    vel = data[:, 5:9]
    A = (-spec.CYCLE_A, 0.0, spec.CYCLE_Z0, -spec.CYCLE_THETA / 2)
    B = (spec.CYCLE_A, 0.0, spec.CYCLE_Z0, spec.CYCLE_THETA / 2)
    np.testing.assert_allclose(pose[[0, -1]], [A, A], atol=1e-12)
    np.testing.assert_allclose(pose[[k, k + 1]], [B, B], atol=1e-12)
    assert np.all(vel[[0, k, k + 1, -1]] == 0.0)
    F = data[:, 13:17]
    rows = np.append(np.arange(0, len(data), 97), [k, k + 1])
    with capi.Plant(capi.load(pkm_library), payload_mass=spec.CYCLE_PAYLOAD) as loaded, \
            capi.Plant(capi.load(pkm_library)) as empty:
        ref = np.array([(loaded if mass[r] else empty).inverse_dynamics(pose[r], vel[r], data[r, 9:13]).F
                        for r in rows])
    np.testing.assert_allclose(F[rows], ref, rtol=0, atol=1e-9)  # the CSV's 12 digits
    assert np.abs(F).max() <= spec.CYCLE_F_MAX * (1 + 1e-5)


def test_the_readmes_cycle_time_is_this_builds(standard):
    """README.md's headline states the standard cycle's time to two digits:
    the one this build plans."""
    _, stdout = standard
    cycle_time = float(re.search(r"cycle time: ([0-9.]+) s", stdout).group(1))
    readme = (REPO / "README.md").read_text()
    stated = re.search(r"\*\*Pick-and-place\.\*\*.*?takes ([0-9.]+) s", readme, re.S)
    assert stated, "README.md: no cycle time in the pick-and-place headline"
    assert stated.group(1) == f"{cycle_time:.2f}", (stated.group(1), cycle_time)


def test_standard_cycle_figure_and_summary(standard):
    out, stdout = standard
    png = (out / "cycle.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 50_000
    for line in ("A -> B:", "B -> A:", "active: force", "cycle time:"):
        assert line in stdout, stdout


def test_closed_loop_tracks_the_plan_through_the_plant_fmu(standard):
    """closed_loop.csv: the plant FMU driven along the plan every 0.1 ms,
    the reference the plan's pose (cycle.csv's at the same times), tracked
    within 0.1 mm, phi within the turn that moves the platform's joints Q_i
    (at r_Q) by 0.1 mm; the payload grasped at A and released at B. The
    feedback's part of the forces stays an order below the payload's weight
    share m g / 4 (what the feedback would carry, all along A -> B, were the
    plant's payload not set by the grasp: such a run's RMS is about 1 N); the
    printed peak force and energy are the CSV's; the plant's energy audit
    holds over the cycle, the grasp and the release included; the drives'
    net work over the rest-to-rest cycle is the payload's potential energy at
    A less that at B, zero at equal heights up to the tracking error."""
    out, stdout = standard
    with open(out / "closed_loop.csv") as f:
        header = f.readline().strip().split(",")
    assert header[:len(LOOP_COLUMNS)] == LOOP_COLUMNS
    col = {name: k for k, name in enumerate(header)}
    run = np.loadtxt(out / "closed_loop.csv", delimiter=",", skiprows=1)
    plan = np.loadtxt(out / "cycle.csv", delimiter=",", skiprows=1)
    t = run[:, 0]
    assert t[0] == 0.0 and np.all(np.diff(t) > 0) and np.diff(t).max() <= 1e-4 + 1e-12
    assert t[-1] == pytest.approx(plan[-1, 0], abs=1e-9)
    release = np.flatnonzero(np.diff(plan[:, 0]) == 0)[0]
    plan = np.delete(plan, release + 1, axis=0)  # the release instant once, as the loop samples it
    assert len(plan) == len(run) and np.allclose(plan[:, 0], t, rtol=0, atol=1e-9)
    ref = run[:, [col[c] for c in ("x_ref", "y_ref", "z_ref", "phi_ref")]]
    np.testing.assert_allclose(ref, plan[:, 1:5], rtol=0, atol=1e-11)  # the CSVs' 12 digits
    pose = run[:, [col[c] for c in ("x", "y", "z", "phi")]]
    assert np.linalg.norm(pose[:, :3] - ref[:, :3], axis=1).max() <= TRACKING_BOUND
    assert np.abs(pose[:, 3] - ref[:, 3]).max() <= TRACKING_BOUND / spec.R_Q
    mass = run[:, col["payload_mass"]]
    assert np.all(mass[:release] == spec.CYCLE_PAYLOAD) and np.all(mass[release:] == 0.0)
    F = run[:-1, [col[f"F[{i}]"] for i in range(1, 5)]]
    F_ff = run[:-1, [col[f"F_ff[{i}]"] for i in range(1, 5)]]
    feedback = np.sqrt(np.mean((F - F_ff) ** 2))
    assert feedback < 0.1 * spec.CYCLE_PAYLOAD * spec.G / 4, feedback
    peak = float(re.search(r"peak \|F\| = ([0-9.]+) N against f_max", stdout).group(1))
    assert peak == pytest.approx(np.abs(F).max(), abs=1e-4)
    assert np.abs(F_ff).max() <= spec.CYCLE_F_MAX * (1 + 1e-3)  # the plan's, midpoints between its samples
    K, P, W, D = (run[:, col[c]] for c in ("kinetic_energy", "potential_energy", "actuator_work",
                                            "dissipated_energy"))
    audit = K + P - W + D
    assert np.abs(audit - audit[0]).max() < 1e-9
    net = float(re.search(r"the drives' net work ([-+0-9.]+) J", stdout).group(1))
    assert abs(net) <= spec.CYCLE_PAYLOAD * spec.G * TRACKING_BOUND
    png = (out / "closed_loop.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 50_000
    assert {p.name for p in out.iterdir()} == promised_files(command_help("cycle"))


def test_table_lists_every_payload_and_force_limit(monkeypatch):
    """--table: a row per f_max and payload, the cycle time the sum of the
    two legs; a leg whose holding force exceeds f_max somewhere is marked
    infeasible with the actuator and a force beyond f_max. The arch's poses
    are checked once and the empty B -> A planned once per f_max. The sweep
    on a coarse grid (the docs build runs the default)."""
    import pkm4puu.planning
    calls = []

    def counted(name, function):
        def wrapper(*args, **kwargs):
            calls.append((name, kwargs.get("name")))
            return function(*args, **kwargs)
        return wrapper

    monkeypatch.setattr(segment, "check_path", counted("check_path", segment.check_path))
    monkeypatch.setattr(pkm4puu.planning, "plan_segment", counted("plan_segment", segment.plan_segment))
    status, stdout, stderr = run("--table", "--grid", "200", "--dt", "0.01")
    assert status == 0, stderr
    assert [c for c in calls if c[0] == "check_path"] == [("check_path", "the arch")]
    assert calls.count(("plan_segment", "A -> B")) == len(program.TABLE_F_MAX) * len(program.TABLE_PAYLOADS)
    assert calls.count(("plan_segment", "B -> A")) == len(program.TABLE_F_MAX)
    rows = [line for line in stdout.splitlines() if re.match(r"\| [0-9.]+ \| [0-9.]+ \|", line)]
    assert [tuple(float(c) for c in row.strip("|").split("|")[:2]) for row in rows] == \
        [(m, f) for f in program.TABLE_F_MAX for m in program.TABLE_PAYLOADS]
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        for time, active in ((cells[2], cells[3]), (cells[4], cells[5])):
            if time == "—":
                force = float(re.fullmatch(r"infeasible: F\[\d\] = ([-0-9.]+) N to hold at s = [0-9.]+", active)[1])
                assert abs(force) > float(cells[1])
            else:
                assert re.fullmatch(r"(force \d+ %)?(, )?(speed \d+ %)?", active), active
        if cells[6] != "—":
            assert float(cells[6]) == pytest.approx(float(cells[2]) + float(cells[4]), abs=2e-4)
        else:
            assert "—" in (cells[2], cells[4])


def _one_error_line(status, stdout, stderr):
    lines = stderr.strip().splitlines()
    assert status == 2, (status, stderr)
    assert len(lines) == 1 and lines[0].startswith(f"{program.prog()}: error: "), stderr
    assert "Traceback" not in stderr and stdout == ""
    return lines[0]


@pytest.mark.parametrize("args, says", [
    (["--payload", "-0.1"], "payload = -0.1 kg must be >= 0"),
    (["--payload", "inf"], "payload = inf is not finite"),
    (["--f-max", "nan"], "f_max = nan is not finite"),
    (["--f-max", "0"], "f_max = 0 N must be > 0"),
    (["--v-max", "-0.5"], "v_max = -0.5 m/s must be > 0"),
    (["--a", "-0.01"], "a = -0.01 m must be >= 0"),
    (["--h", "nan"], "h = nan is not finite"),
    (["--z0=-inf"], "z0 = -inf is not finite"),
    (["--theta-deg", "inf"], "theta = inf is not finite"),
    (["--grid", "1"], "grid = 1 must be an integer >= 2"),
    (["--dt", "0"], "dt = 0 s must be > 0"),
    (["--a", "0", "--h", "0", "--theta-deg", "0"], "does not move"),
    (["--z0", "0.2"], "leaves the sliders' travel at s = 0.0000"),
])
def test_bad_values_one_line_exit_2_nothing_written(tmp_path, args, says):
    (tmp_path / "keep.txt").write_text("kept")
    new = tmp_path / "new"
    for out in (new, tmp_path):
        line = _one_error_line(*run(*args, "--out", str(out)))
        assert says in line, line
    assert not new.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


def _reach(pose):
    """Per leg: can it reach `pose` elbow-down (docs' closed form: h' <= the
    distance of Q_i from the prismatic axis <= sqrt(l^2 + h'^2))?"""
    out = []
    for i in range(4):
        qt = spec.rz(spec.BETA[i]).T @ (np.asarray(pose[:3]) + spec.rz(pose[3]) @ spec.platform_point(i)
                                        - spec.base_point(i))
        out.append(spec.H_PRIME ** 2 <= qt[0] ** 2 + qt[1] ** 2 <= spec.L ** 2 + spec.H_PRIME ** 2)
    return out


def _arch_pose(a, s):
    th = spec.CYCLE_THETA
    return (-a * math.cos(math.pi * s), 0.0, spec.CYCLE_Z0 + spec.CYCLE_H * math.sin(math.pi * s),
            -th / 2 * math.cos(math.pi * s))


def _reported(line):
    """(s, leg) of an error line."""
    return float(re.search(r"at s = ([0-9.]+)", line).group(1)), int(re.search(r"\(leg (\d)\)", line).group(1))


def test_path_out_of_reach_names_where_and_the_leg():
    """a = 50 mm: x = -50 mm at A, where the spec's geometry leaves some leg
    unable to reach; the message names s = 0 and one of those legs."""
    status, stdout, stderr = run("--a", "0.05")
    line = _one_error_line(status, stdout, stderr)
    s, leg = _reported(line)
    assert "leaves the workspace" in line and s == 0.0
    assert not _reach(_arch_pose(0.05, 0.0))[leg - 1]


def test_path_through_a_singularity_names_where_and_the_leg():
    """The widest arch whose ends the legs still reach (bisected on the
    spec's closed form) ends 0.1 um inside the reach, where a rod stands
    nearly vertical or horizontal: the path enters the C API's leg
    singularity guard, |cos theta2 sin theta2| < 0.01, before it. The
    message names the first grid point past the guard and the leg; the
    spec's inverse kinematics puts that leg's measure below 0.01 there and
    above it one grid step before."""
    lo, hi = spec.CYCLE_A, 0.05
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if all(all(_reach(_arch_pose(mid, s))) for s in (0.0, 1.0)) else (lo, mid)
    a = lo - 1e-7
    line = _one_error_line(*run("--a", repr(a)))
    s, leg = _reported(line)
    assert "crosses a singularity" in line

    def measure(s):
        th2 = spec.leg_inverse_kinematics(_arch_pose(a, s))[leg - 1, 2]
        return abs(math.cos(th2) * math.sin(th2))

    assert measure(s) < 1e-2 <= measure(s - 1.0 / segment.GRID)


def test_limits_below_holding_the_payload_name_the_actuator(pkm_library):
    """f_max = 3 N: the machine and the payload weigh 13.1 N on four vertical
    actuators, so some share exceeds 3 N. The message names the actuator,
    the force and where; the C API's inverse dynamics at rest there gives
    that force."""
    assert (spec.TOTAL_WEIGHT + spec.CYCLE_PAYLOAD * spec.G) / 4 > 3.0
    line = _one_error_line(*run("--f-max", "3"))
    assert "holding the 0.25 kg payload" in line and "beyond f_max = 3 N" in line
    s = float(re.search(r"at s = ([0-9.]+)", line).group(1))
    i, force = re.search(r"needs F\[(\d)\] = ([-0-9.]+) N", line).groups()
    pose = _arch_pose(spec.CYCLE_A, s)
    with capi.Plant(capi.load(pkm_library), payload_mass=spec.CYCLE_PAYLOAD) as plant:
        F = plant.inverse_dynamics(pose, [0.0] * 4, [0.0] * 4).F
    assert abs(F[int(i) - 1]) > 3.0
    assert F[int(i) - 1] == pytest.approx(float(force), abs=1e-3)


def test_library_errors_are_planning_errors():
    """The same checks from Python: PlanningError subclasses (ValueError)."""
    import pkm4puu
    from pkm4puu.planning import BadValue, Infeasible, OutsideWorkspace
    with pytest.raises(BadValue, match="payload = -1 kg"):
        pkm4puu.plan_cycle(payload=-1.0)
    with pytest.raises(OutsideWorkspace, match="leg"):
        pkm4puu.plan_cycle(a=0.05)
    with pytest.raises(Infeasible, match=r"F\[\d\]"):
        pkm4puu.plan_cycle(f_max=3.0, grid=100)
