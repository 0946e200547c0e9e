# SPDX-License-Identifier: BSD-2-Clause
"""pkm4puu: the 4-PUU Schönflies robot's FMUs from Python.

    import pkm4puu as pkm
    with pkm.Fmu.open("PKM4PUU", start=pkm.START_P0) as plant:
        r = plant.simulate(1.0, pkm.STEP, inputs={"F[1]": 2.7}, outputs=pkm.POSE)

The library: spec (docs/model.md's numbers and geometry), motions (the test
motions), interface (variable names), locate (the build directory and the
paths in it), fmu (the wrapper), capi (the C API's binding, cffi reading
pkm.h), linearization (the plant's Jacobians through Model Exchange),
closed_loop (the sampled loop the control examples share), calibration
(identification of the dynamic parameters from a drive log,
pkm4puu.identify; it needs scipy). The rest needs numpy and fmpy only.

The reports (the paper's tests through the FMUs, the engine comparison
against the independent Pinocchio and MuJoCo models, figures) are in
pkm4puu.validation and run as `python -m pkm4puu COMMAND`.
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
           "STATIC_FORCE_P0", "STEP", "T_MOVE", "identify"]
