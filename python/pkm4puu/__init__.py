"""pkm4puu: the 4-PUU Schönflies robot's FMUs from Python.

    import pkm4puu as pkm
    with pkm.Fmu.open("PKM4PUU", start=pkm.START_P0) as plant:
        r = plant.simulate(1.0, pkm.STEP, inputs={"F[1]": 2.7}, outputs=pkm.POSE)

Modules: spec (MODEL_SPEC's numbers and geometry), motions (the test
motions), interface (variable names), fmu (the wrapper), autotest and
comparison (the paper's tests through the FMUs; also `python -m`), plots,
drawing, cli, closed_loop (the sampled loop the control examples share);
references.pinocchio_model and references.mujoco_model (the independent
models, imported on demand: they need pinocchio and mujoco);
capi (a ctypes binding of the C API, pkm.h).
"""
from .fmu import Fmu, Result, build_dir, find_fmu, inverse_forces, run
from .interface import ACC, DRHO, F, POSE, RHO, RK4, START_P0, THETA1, THETA2, VEL, WRENCH, arr, start_pose
from .motions import autotest_motion, blend, comparison_forces, motion, p, pd, pdd
from .spec import P0, P1, STATIC_FORCE_P0, STEP, T_MOVE

__all__ = ["Fmu", "Result", "build_dir", "find_fmu", "inverse_forces", "run", "ACC", "DRHO", "F", "POSE", "RHO",
           "RK4", "START_P0", "THETA1", "THETA2", "VEL", "WRENCH", "arr", "start_pose", "autotest_motion", "blend",
           "comparison_forces", "motion", "p", "pd", "pdd", "P0", "P1", "STATIC_FORCE_P0", "STEP", "T_MOVE"]
