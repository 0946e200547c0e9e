"""examples/closed_loop_control.py: the plant FMU in a 1 kHz joint-space PD
loop with the inverse FMU's computed-force feed-forward, a payload on the
platform that the feed-forward does not know about."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))

import closed_loop_control as clc  # noqa: E402
from fmu_helpers import G, TOTAL_WEIGHT  # noqa: E402  (MODEL_SPEC's g and the machine's total weight)


@pytest.fixture(scope="module")
def runs(plant_fmu, inverse_fmu):
    return clc.compare(plant_fmu, inverse_fmu)


def test_feed_forward_cuts_the_rms_error(runs, results_dir):
    with_ff, pd_only, ratio = runs
    print("\n" + clc.summary(with_ff, pd_only, ratio, clc.PAYLOAD))
    clc.plot(with_ff, pd_only, ratio, clc.PAYLOAD, results_dir / "test_examples_closed_loop.png")
    for r in (with_ff, pd_only):
        assert np.all(np.isfinite(r.rho)) and np.all(np.isfinite(r.pose))
    # PD alone is stable and tracks roughly: ~1 mm while carrying ~2.9 N per actuator at Kp = 2500 N/m.
    assert np.abs(pd_only.e_rho).max() < 3e-3, "PD only drifted away"
    assert ratio >= clc.MIN_RATIO, (f"feed-forward cut the RMS error only by {ratio:.2f} "
                                    f"({1e3 * pd_only.rms:.4f} mm -> {1e3 * with_ff.rms:.4f} mm)")


def test_settled_errors_carry_exactly_the_unmodelled_weight(runs):
    """At rest after the motion the frictionless vertical joints balance the
    whole weight: sum F_i = total weight. With feed-forward, sum F_ff = the
    nominal weight, so the PD's share sum Kp e_i is the payload's weight
    m_p g; without, it is the whole weight plus the payload."""
    with_ff, pd_only, _ = runs
    m_g = clc.PAYLOAD * G
    for r, expected in ((with_ff, m_g), (pd_only, TOTAL_WEIGHT + m_g)):
        carried = clc.KP * r.e_rho[-1].sum()
        print(f"\nsettled: sum Kp e_i = {carried:.6f} N, expected {expected:.6f} N")
        assert carried == pytest.approx(expected, rel=1e-4)


def test_feed_forward_alone_is_exact_without_payload(plant_fmu, inverse_fmu):
    """No payload: the feed-forward is the plant's own model, so the PD only
    corrects the zero-order hold of F over each 1 ms step (an O(h) force lag):
    measured 4.3e-8 m RMS, against ~0.1 mm with the 100 g payload."""
    r = clc.run_loop(plant_fmu, inverse_fmu, payload=0.0)
    print(f"\nno payload, PD + feed-forward: RMS rho error {r.rms:.3e} m, max {np.abs(r.e_rho).max():.3e} m")
    assert r.rms < 1e-6


def test_command_line(plant_fmu, tmp_path):
    rc = clc.main(["--build", str(plant_fmu.parent), "--out", str(tmp_path), "--t-end", "0.5"])
    assert rc == 0
    for name in ("closed_loop.csv", "closed_loop_tracking.png", "closed_loop_run.csv"):
        assert (tmp_path / name).stat().st_size > 0, name
    assert clc.main(["--build", str(tmp_path / "nowhere"), "--out", str(tmp_path)]) == 1
