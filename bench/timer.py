# SPDX-License-Identifier: BSD-2-Clause
"""The Python benchmarks' timer (timer.h's counterpart): the wall times of repeated calls."""
import time


def timed(fn, repeat, setup=None):
    """The wall time of each of `repeat` calls of fn() (setup() called untimed before each), and fn's last result."""
    times, out = [], None
    for _ in range(repeat):
        if setup:
            setup()
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out
