# SPDX-License-Identifier: BSD-2-Clause
"""Time-optimal pick-and-place (planning needs the extra `planning`: toppra,
imported when a plan is made).

    cycle = pkm4puu.plan_cycle()             # the standard cycle
    cycle.duration                           # s
    cycle.segments[0].at(t)                  # the plan A -> B at times t

plan_cycle plans the arch from A to B with the payload and back empty, each
leg the fastest rest-to-rest traversal within the actuator-force and
slider-speed limits (TOPP-RA over the C API's inverse dynamics);
plan_segment plans one path. Every call into the C API is in capi_adapter.
track_cycle runs a planned cycle closed-loop through the plant FMU
(tracking: the planned forces as feed-forward, per-slider PD, the payload
grasped and released through the FMU's tunable parameters).
"""
from .cycle import COLUMNS, Cycle, arch, plan_cycle
from .limits import BadValue, Infeasible, Limits, OutsideWorkspace, PlanningError, SingularPath
from .paths import Arch
from .segment import DT, GRID, Segment, plan_segment
from .tracking import Tracking, track_cycle

__all__ = ["COLUMNS", "Cycle", "arch", "plan_cycle", "BadValue", "Infeasible", "Limits", "OutsideWorkspace",
           "PlanningError", "SingularPath", "Arch", "DT", "GRID", "Segment", "plan_segment", "Tracking", "track_cycle"]
