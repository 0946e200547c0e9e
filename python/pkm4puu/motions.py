# SPDX-License-Identifier: BSD-2-Clause
"""The test motions of docs/model.md: the auto-test's rest-to-rest quintic from
P0 to P1 (paper section 5.1) and the comparison test's actuator forces
(section 5.2)."""
import math

import numpy as np

from .spec import CMP_AMPLITUDE, CMP_DURATION, P0, P1, T_MOVE


def blend(tau):
    """s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 and its first two derivatives,
    held at rest before tau = 0 and after tau = 1 (the motion is rest to rest)."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    ds = 30.0 * tau**2 * (1.0 - tau) ** 2
    dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
    return s, ds, dds


def autotest_motion(t, T=T_MOVE):
    """Prescribed platform pose, velocity and acceleration (each x, y, z, phi)
    at t of the auto-test done in T seconds (the spec's T is 2 s)."""
    s, ds, dds = blend(t / T)
    d = P1 - P0
    return P0 + d * s, d * ds / T, d * dds / T**2


def pose_at(t):
    """The auto-test's prescribed pose (x, y, z, phi) at time t."""
    return autotest_motion(t)[0]


def velocity_at(t):
    """The auto-test's prescribed velocity at time t."""
    return autotest_motion(t)[1]


def acceleration_at(t):
    """The auto-test's prescribed acceleration at time t."""
    return autotest_motion(t)[2]


def motion(t, T=T_MOVE):
    """The auto-test done in T seconds as the inverse FMU's 12 inputs at t:
    pose, velocity, acceleration (interface.POSE + VEL + ACC order)."""
    return [float(v) for part in autotest_motion(t, T) for v in part]


def comparison_forces(t):
    """F1..F4 (N) of the comparison test at time t: F1 = -F4 = 0.02 sin(2 pi t / 1.5), F2 = F3 = 0."""
    f = CMP_AMPLITUDE * math.sin(2.0 * math.pi * t / CMP_DURATION)
    return np.array([f, 0.0, 0.0, -f])
