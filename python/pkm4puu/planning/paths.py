# SPDX-License-Identifier: BSD-2-Clause
"""Geometric paths of the platform: the pose p(s) = (x, y, z, phi) for s in
[0, 1] with its derivatives p'(s) and p''(s), evaluated on arrays of s."""
import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Arch:
    """The pick-and-place arch from A (s = 0) to B (s = 1):
    x = -a cos(pi s), y = 0, z = z0 + h sin(pi s), phi = -(theta/2) cos(pi s)
    (m, rad). reverse=True runs it from B to A (s -> 1 - s)."""
    a: float
    h: float
    z0: float
    theta: float
    reverse: bool = False

    def reversed(self):
        return Arch(self.a, self.h, self.z0, self.theta, not self.reverse)

    def arch_s(self, s):
        """The arch's own parameter (A at 0, B at 1) at this path's s."""
        return 1.0 - np.asarray(s, dtype=float) if self.reverse else np.asarray(s, dtype=float)

    def __call__(self, s, order=0):
        """p(s) (order 0), p'(s) (1) or p''(s) (2), each (n, 4) for s of shape (n,)."""
        sa = self.arch_s(np.atleast_1d(s))
        sign = -1.0 if self.reverse and order == 1 else 1.0  # d/ds of s -> 1 - s
        c, sn, zero = np.cos(math.pi * sa), np.sin(math.pi * sa), np.zeros_like(sa)
        half = 0.5 * self.theta
        if order == 0:
            return np.stack([-self.a * c, zero, self.z0 + self.h * sn, -half * c], axis=1)
        k = math.pi ** order
        if order == 1:
            return sign * k * np.stack([self.a * sn, zero, self.h * c, half * sn], axis=1)
        if order == 2:
            return k * np.stack([self.a * c, zero, -self.h * sn, half * c], axis=1)
        raise ValueError(f"order must be 0, 1 or 2, not {order}")

    def describe(self):
        return (f"arch a = {1e3 * self.a:g} mm, h = {1e3 * self.h:g} mm, z0 = {1e3 * self.z0:g} mm, "
                f"theta = {math.degrees(self.theta):g} deg")
