# SPDX-License-Identifier: BSD-2-Clause
"""The drives' limits a plan keeps, and the errors a plan answers bad input with."""
import math
from dataclasses import dataclass
from typing import Optional


class PlanningError(ValueError):
    """A traversal that cannot be planned; the message says why and where."""


class BadValue(PlanningError):
    """A non-finite, negative or otherwise invalid argument."""


class OutsideWorkspace(PlanningError):
    """The path leaves the workspace: a leg cannot reach, or a slider leaves its travel."""


class SingularPath(PlanningError):
    """The path crosses a leg or parallel singularity (the C API's guards)."""


class Infeasible(PlanningError):
    """No traversal within the limits (holding the payload already needs
    more, say); `short` says it in a few words (for a table)."""

    def __init__(self, message, short=None):
        super().__init__(message)
        self.short = short or message


def check_value(name, value, minimum=0.0, strict=False, unit=""):
    """float(value), or BadValue naming it when it is not finite or below
    `minimum` (at or below it when `strict`)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise BadValue(f"{name} = {value!r} is not a number") from None
    if not math.isfinite(v):
        raise BadValue(f"{name} = {v} is not finite")
    if minimum is not None and (v <= minimum if strict else v < minimum):
        raise BadValue(f"{name} = {v:g}{unit} must be {'>' if strict else '>='} {minimum:g}{unit}")
    return v


@dataclass(frozen=True)
class Limits:
    """abs(F_i) <= f_max (N) and abs(drho_i/dt) <= v_max (m/s) for each actuator;
    optionally the motors' torque abs(tau_i) <= torque_max (N m) and speed
    abs(omega_i) <= motor_speed_max (rad/s), which the lossless ball screw of
    lead p turns into abs(F_i) <= 2 pi torque_max / p and
    abs(drho_i/dt) <= p motor_speed_max / (2 pi)."""
    f_max: float = 10.0
    v_max: float = 0.5
    torque_max: Optional[float] = None
    motor_speed_max: Optional[float] = None

    def __post_init__(self):
        check_value("f_max", self.f_max, strict=True, unit=" N")
        check_value("v_max", self.v_max, strict=True, unit=" m/s")
        if self.torque_max is not None:
            check_value("torque_max", self.torque_max, strict=True, unit=" N m")
        if self.motor_speed_max is not None:
            check_value("motor_speed_max", self.motor_speed_max, strict=True, unit=" rad/s")

    def force(self, screw_lead):
        """(the force limit on each F_i in N, what sets it)."""
        f, what = float(self.f_max), f"f_max = {self.f_max:g} N"
        if self.torque_max is not None and 2 * math.pi * self.torque_max / screw_lead < f:
            f = 2 * math.pi * self.torque_max / screw_lead
            what = f"torque_max = {self.torque_max:g} N m through the screw ({f:.4g} N)"
        return f, what

    def speed(self, screw_lead):
        """(the speed limit on each drho_i/dt in m/s, what sets it)."""
        v, what = float(self.v_max), f"v_max = {self.v_max:g} m/s"
        if self.motor_speed_max is not None and screw_lead * self.motor_speed_max / (2 * math.pi) < v:
            v = screw_lead * self.motor_speed_max / (2 * math.pi)
            what = f"motor_speed_max = {self.motor_speed_max:g} rad/s through the screw ({v:.4g} m/s)"
        return v, what
