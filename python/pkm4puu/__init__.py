# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu: the 4-PUU Schönflies robot's FMUs from Python.

    import pkm4puu as pkm
    with pkm.Fmu.open("PKM4PUU", start=pkm.START_P0) as plant:
        r = plant.simulate(1.0, pkm.STEP, inputs={"F[1]": 2.7}, outputs=pkm.POSE)

The library: spec (docs/model.md's numbers and geometry), motions (the test
motions), interface (variable names), locate (the build directory and the
paths in it), fmu (the wrapper), capi (the C API's binding, cffi reading
pkm.h), linearization (the plant's Jacobians through Model Exchange), closed_loop
(the sampled loop the control examples share), drawing (the mechanism's
points, a run's CSV), plots (figures; matplotlib, the extra `plots`),
program (what command-line programs over the FMUs share), extras (the
optional dependencies), calibration (identification of the dynamic
parameters from a drive log, pkm4puu.identify; scipy, the extra
`calibration`), references (independent Pinocchio and MuJoCo models of
the mechanism; the extra `references`) and planning (the time-optimal
pick-and-place cycle, pkm4puu.plan_cycle; toppra, the extra `planning`).
The rest needs numpy and fmpy only.

The programs (the paper's tests through the FMUs, the engine comparison,
the identification, figures) are in pkm4puu.cli, behind the command
`pkm4puu COMMAND` (or `python -m pkm4puu COMMAND`).
"""
from ._version import __version__
from .fmu import Fmu, Result, find_fmu, inverse_forces, run
from .interface import (ACC, DRHO, F, POSE, RHO, RK4, START_P0, THETA1, THETA2, VEL, WRENCH, indexed_names,
                        start_pose)
from .locate import build_dir
from .motions import acceleration_at, autotest_motion, blend, comparison_forces, motion, pose_at, velocity_at
from .spec import P0, P1, STATIC_FORCE_P0, STEP, T_MOVE

__all__ = ["__version__", "Fmu", "Result", "build_dir", "find_fmu", "inverse_forces", "run", "ACC", "DRHO", "F", "POSE", "RHO",
           "RK4", "START_P0", "THETA1", "THETA2", "VEL", "WRENCH", "indexed_names", "start_pose", "autotest_motion",
           "blend", "comparison_forces", "motion", "pose_at", "velocity_at", "acceleration_at", "P0", "P1",
           "STATIC_FORCE_P0", "STEP", "T_MOVE", "identify", "plan_cycle"]


def __getattr__(name):
    """pkm4puu.identify, the calibration's identification
    (calibration.identify), and pkm4puu.plan_cycle, the pick-and-place
    planner (planning.plan_cycle), imported on first use: they load the C
    API's binding, and scipy or toppra when called."""
    if name == "identify":
        from .calibration import identify
        return identify
    if name == "plan_cycle":
        from .planning import plan_cycle
        return plan_cycle
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
