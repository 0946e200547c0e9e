"""Independent models of the 4-PUU mechanism for validation and benchmarks,
built from MODEL_SPEC's numbers only (spec.py): Pinocchio (pinocchio_model.py,
the reference) and MuJoCo (mujoco_model.py); and a ctypes binding of this
project's C API (pkm_capi.py)."""
