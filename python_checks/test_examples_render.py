# SPDX-License-Identifier: BSD-2-Clause
"""examples/render_robot.py: the mechanism drawn from a run's CSV. A short
run is rendered; the frames must change as the platform moves, a static pose
must render identically twice, and the drawn legs must meet the drawn
platform (the DH chain from the FMU's joint outputs against the pose)."""

import numpy as np
import pytest

from pkm4puu.cli.autotest import BOUNDS
from pkm4puu.drawing import read_run_csv, RUN_COLUMNS, write_run_csv
from pkm4puu.interface import POSE
from pkm4puu.spec import P0, P1, T_MOVE, constraint_residual
from example_scripts import load_example

rr = load_example("render_robot")

T_SHORT = 0.6  # s: the auto-test's motion done in 0.6 s, a short run
N_FRAMES = 4
SIZE = 160  # px
# A frame pair "differs" when more than this many pixels change. The platform
# rises ~6 mm between these frames, several pixels at this size, and the
# sliders and rods move with it.
MIN_CHANGED = 50


@pytest.fixture(scope="module")
def short_run(plant_fmu, inverse_fmu):
    t, Y = rr.autotest_run(plant_fmu, inverse_fmu, T=T_SHORT)
    return t, rr.rows_from_array(Y)


def changed_pixels(a, b):
    return int(np.count_nonzero(np.any(a != b, axis=-1)))


def test_drawing_closes_the_loop(short_run):
    """Q_i from the legs' joint values (DH chain of Table I) and p + Rz(phi) r_Qi
    from the pose are the same points: the drawing's formulas agree with the
    FMU's kinematics (whose ||C(q)|| is ~1e-16 m)."""
    _, rows = short_run
    gap = rr.closure_error(rows)
    print(f"\nmax gap between legs and platform in the drawing: {gap:.2e} m")
    assert gap < 1e-9


def test_frames_change_as_the_platform_moves(short_run, results_dir):
    t, rows = short_run
    idx = rr.pick(t, N_FRAMES)
    frames = [rr.frame_image(rows[k], size_px=SIZE) for k in idx]
    assert all(f.shape == (SIZE, SIZE, 4) for f in frames)
    changes = [changed_pixels(a, b) for a, b in zip(frames, frames[1:])]
    times = ", ".join(f"{t[k]:.2f}" for k in idx)
    heights = ", ".join(f"{1e3 * rows[k]['z']:.1f}" for k in idx)
    print(f"\nframes at t = {times} s (z = {heights} mm): "
          f"changed pixels between consecutive frames {changes}")
    assert all(c > MIN_CHANGED for c in changes), changes
    # a static pose renders the same image every time
    again = rr.frame_image(rows[idx[0]], size_px=SIZE)
    assert np.array_equal(again, frames[0])
    # and the GIF writer makes a playable file with one image per frame
    gif = rr.write_gif(t, rows, results_dir / "test_examples_robot.gif", n_frames=N_FRAMES, size_px=SIZE, hold=0)
    from PIL import Image
    with Image.open(gif) as im:
        assert im.n_frames == N_FRAMES
    rr.write_still(t, rows, results_dir / "test_examples_robot_frames.png", n_frames=N_FRAMES)


def test_run_csv_round_trip(short_run, tmp_path):
    t, rows = short_run
    Y = np.array([[r[c] for c in RUN_COLUMNS] for r in rows])
    t2, rows2 = read_run_csv(write_run_csv(tmp_path / "run.csv", t, Y))
    Y2 = np.array([[r[c] for c in RUN_COLUMNS] for r in rows2])
    assert np.allclose(t2, t, atol=1e-9) and np.allclose(Y2, Y, rtol=1e-11, atol=1e-15)


def test_command_line(plant_fmu, tmp_path):
    assert rr.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--frames", "3",
                    "--size", "120"]) == 0
    for name in ("robot_run.csv", "robot_motion.gif", "robot_frames.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    # The written run is the midpoint-held auto-test: from P0 to P1 within
    # the auto-test's bounds, and every row's joints close the spec's loops
    # (Eq. 15) to the 13 digits written.
    t, rows = read_run_csv(tmp_path / "robot_run.csv")
    pose = np.array([[r[c] for c in POSE] for r in rows])
    assert t[-1] == pytest.approx(T_MOVE) and np.array_equal(pose[0], P0)
    assert np.linalg.norm(pose[-1, :3] - P1[:3]) <= BOUNDS.position and abs(pose[-1, 3] - P1[3]) <= BOUNDS.phi
    q = [[r[f"{n}[{i}]"] for i in range(1, 5) for n in ("rho", "theta1", "theta2")] + [r[c] for c in POSE]
         for r in rows]
    assert max(np.abs(constraint_residual(qk)).max() for qk in q) <= 1e-12
    # rendering a given CSV
    out2 = tmp_path / "again"
    assert rr.main(["--csv", str(tmp_path / "robot_run.csv"), "--out", str(out2), "--frames", "2",
                    "--size", "100"]) == 0
    assert (out2 / "robot_motion.gif").is_file()
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,x\n0,0\n")
    assert rr.main(["--csv", str(bad), "--out", str(out2)]) == 1
