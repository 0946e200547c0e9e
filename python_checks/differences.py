# SPDX-License-Identifier: BSD-2-Clause
"""Difference quotients the derivative checks share (the reference side of a
comparison: nothing here comes from the code under test)."""
import numpy as np


def richardson(f, h, levels=4):
    """d/ds f(s) at 0 by central differences at h, h/2, ... and Richardson's
    table; also the last correction's size, elementwise (the estimate's own
    error)."""
    T = []
    for k in range(levels):
        hk = h / 2**k
        T.append((f(hk) - f(-hk)) / (2 * hk))
        factor = 4.0
        for j in range(k - 1, -1, -1):
            T[j] = (factor * T[j + 1] - T[j]) / (factor - 1.0)
            factor *= 4.0
    return T[0], np.abs(T[0] - T[1])
