# SPDX-License-Identifier: BSD-2-Clause
"""Opening and driving the project's FMUs from Python: a thin, always
cleaning-up wrapper around fmpy's FMU2Slave and FMU3Slave that speaks the
interface's names::

    from pkm4puu import Fmu
    with Fmu.open("PKM4PUU", start={"solver": 1}) as plant:
        result = plant.simulate(0.5, 1e-3, inputs={"F[1]": 2.7}, outputs=["x", "z"])
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from .interface import ACC, F, POSE, VEL
from .locate import BUILD_ENV, PathLike, fmu_path
from .motions import autotest_motion

MODELS = ("PKM4PUU", "PKM4PUU_Inverse")


def find_fmu(model: str = "PKM4PUU", fmi: int = 2, build: PathLike = None) -> Path:
    """The archive of `model` (PKM4PUU, the plant, or PKM4PUU_Inverse) for FMI
    version `fmi` (2 or 3): in the build directory `build` or
    $PKM_BUILD_DIR when given, else the installed package's own (a
    wheel's), else in ./build (locate.fmu_path); FileNotFoundError saying how
    to build it when it is not there."""
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}: one of {', '.join(MODELS)}")
    if fmi not in (2, 3):
        raise ValueError(f"fmi must be 2 or 3, not {fmi!r}")
    path = fmu_path(model, fmi, build)
    if not path.is_file():
        raise FileNotFoundError(f"{path} does not exist: build the FMUs first (./scripts/build.sh builds them "
                                f"into build/), and pass the directory that holds them (--build DIR) or set "
                                f"{BUILD_ENV} to it")
    return path


class Result:
    """A run's outputs at the communication points: `t` and one column per
    output name (`result["x"]`, or `result.values` as an n x m array)."""

    def __init__(self, t: np.ndarray, names: Sequence[str], values: np.ndarray):
        self.t, self.names, self.values = t, list(names), values

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[:, self.names.index(name)]


class Fmu:
    """One Co-Simulation instance, FMI 2.0 or 3.0 (from the archive's model
    description), initialised and ready to step.

    with Fmu(path, start={"solver": 1, "g": 0.0}) as fmu:
        fmu.set(F, [1, 2, 3, 4]); fmu.do_step(0.0, 1e-3); fmu.get(["x"])

    `start` values are set by name (type from the model description) between
    instantiate and enterInitializationMode. On leaving the block the instance
    is terminated and freed and its extracted directory removed, also when
    something failed. `unzipdir` lets several instances share one extraction
    (and so one loaded shared library); the caller then owns that directory.
    The methods below hide the two versions' different names (setReal /
    setFloat64, getFMUstate / getFMUState, ...); `fmu.fmu` is fmpy's object.
    """

    def __init__(self, path, start: Mapping[str, float] | None = None, instance_name: str = "instance",
                 unzipdir: str | None = None, start_time: float = 0.0):
        self.path = str(path)
        self.start = dict(start or {})
        self.instance_name = instance_name
        self.start_time = start_time
        self.md = read_model_description(self.path)
        self._vars = {v.name: v for v in self.md.modelVariables}
        self.fmi3 = self.md.fmiVersion.startswith("3.")
        self._own_dir = unzipdir is None
        self.unzipdir = unzipdir
        self.fmu = None
        self._instantiated = False
        self._initialized = False

    @classmethod
    def open(cls, model: str = "PKM4PUU", fmi: int = 2, build=None, **kwargs) -> "Fmu":
        """An instance of `model` (see find_fmu), for use in a with block."""
        return cls(find_fmu(model, fmi, build), **kwargs)

    # -- life cycle ---------------------------------------------------------
    def __enter__(self):
        try:
            if self.unzipdir is None:
                self.unzipdir = extract(self.path)
            slave = FMU3Slave if self.fmi3 else FMU2Slave
            self.fmu = slave(
                guid=self.md.guid,
                unzipDirectory=self.unzipdir,
                modelIdentifier=self.md.coSimulation.modelIdentifier,
                instanceName=self.instance_name,
            )
            self.fmu.instantiate()
            self._instantiated = True
            self.initialize()
        except BaseException:
            self.close()
            raise
        return self

    def initialize(self):
        """setupExperiment (FMI 2.0), start values, enter/exit initialization mode."""
        if not self.fmi3:
            self.fmu.setupExperiment(startTime=self.start_time)
        for name, value in self.start.items():
            self.set_any(name, value)
        if self.fmi3:
            self.fmu.enterInitializationMode(startTime=self.start_time)
        else:
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self._initialized = True

    def close(self):
        if self.fmu is not None and self._instantiated:
            try:
                if self._initialized:
                    self.fmu.terminate()
            finally:
                self._instantiated = False
                self.fmu.freeInstance()
        if self._own_dir and self.unzipdir is not None:
            shutil.rmtree(self.unzipdir, ignore_errors=True)
            self.unzipdir = None

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.close()
        else:  # do not let a cleanup error hide the original one
            try:
                self.close()
            except Exception:
                pass
        return False

    # -- variables ----------------------------------------------------------
    def var(self, name):
        try:
            return self._vars[name]
        except KeyError:
            raise KeyError(f"{self.md.modelName}: no variable named {name!r}") from None

    def vrs(self, names):
        return [self.var(n).valueReference for n in names]

    def set_any(self, name, value):
        v = self.var(name)
        vr = [v.valueReference]
        if v.type in ("Real", "Float64"):
            self._set_real(vr, [float(value)])
        elif v.type in ("Integer", "Enumeration") and not self.fmi3:
            self.fmu.setInteger(vr, [int(value)])
        elif v.type in ("Int32", "Enumeration"):
            self.fmu.setInt32(vr, [int(value)])
        elif v.type == "Boolean":
            self.fmu.setBoolean(vr, [bool(value)])
        else:
            self.fmu.setString(vr, [str(value)])

    def _set_real(self, vrs, values):
        (self.fmu.setFloat64 if self.fmi3 else self.fmu.setReal)(vrs, values)

    def set(self, names, values):
        """setReal / setFloat64 by names."""
        self._set_real(self.vrs(names), [float(v) for v in values])

    def get(self, names):
        """getReal / getFloat64 by names, as a numpy array."""
        vrs = self.vrs(names)
        return np.array(self.fmu.getFloat64(vrs) if self.fmi3 else self.fmu.getReal(vrs))

    def set_derivatives(self, names, values, order=1):
        """setRealInputDerivatives by names (FMI 2.0 only: the FMI 3.0 FMUs
        hold their inputs over a step)."""
        if self.fmi3:
            raise NotImplementedError("the FMI 3.0 FMUs take no input derivatives")
        self.fmu.setRealInputDerivatives(self.vrs(names), [order] * len(names), [float(v) for v in values])

    def do_step(self, t, h, no_set_prior=True):
        self.fmu.doStep(t, h, noSetFMUStatePriorToCurrentPoint=no_set_prior)

    def simulate(self, stop_time: float, step: float,
                 inputs: Mapping[str, float] | Callable[[float], Mapping[str, float]] | None = None,
                 outputs: Sequence[str] = POSE) -> Result:
        """Steps from the start time to stop_time by `step`. `inputs` maps
        input names to values: fixed, or a function of the step's start time
        called before each step. Returns the outputs at every communication
        point, the start included."""
        n = round((stop_time - self.start_time) / step)
        if n < 1 or not np.isclose(self.start_time + n * step, stop_time, rtol=0, atol=1e-9 * step):
            raise ValueError(f"stop_time {stop_time} is not a whole number of steps of {step} after "
                             f"the start time {self.start_time}")

        def apply(fmu, k, t):
            values = inputs(t) if callable(inputs) else inputs
            if values:
                fmu.set(list(values), list(values.values()))

        t, Y = run(self, self.start_time, step, n, apply, outputs)
        return Result(t, outputs, Y)

    # -- FMU state ----------------------------------------------------------
    def get_state(self):
        return self.fmu.getFMUState() if self.fmi3 else self.fmu.getFMUstate()

    def set_state(self, state):
        (self.fmu.setFMUState if self.fmi3 else self.fmu.setFMUstate)(state)

    def free_state(self, state):
        (self.fmu.freeFMUState if self.fmi3 else self.fmu.freeFMUstate)(state)

    def serialize(self, state):
        return (self.fmu.serializeFMUState if self.fmi3 else self.fmu.serializeFMUstate)(state)

    def deserialize(self, blob):
        return (self.fmu.deserializeFMUState if self.fmi3 else self.fmu.deSerializeFMUstate)(blob)


def run(fmu, t0, h, n, inputs, out_names, first_row=True):
    """Steps `fmu` n times by h from t0; before step k (at t = t0 + k h) calls
    inputs(fmu, k, t) to set the inputs. Returns (t, Y): the outputs out_names
    at the communication points, one row per point (including t0 when
    first_row)."""
    rows, times = [], []
    if first_row:
        times.append(t0)
        rows.append(fmu.get(out_names))
    for k in range(n):
        t = t0 + k * h
        inputs(fmu, k, t)
        fmu.do_step(t, h)
        times.append(t0 + (k + 1) * h)
        rows.append(fmu.get(out_names))
    return np.array(times), np.array(rows)


def inverse_forces(inv, times):
    """Actuator forces F1..F4 from the inverse FMU on the prescribed motion at
    each of `times` (no external wrench): one row per time."""
    out = np.empty((len(times), 4))
    for i, t in enumerate(times):
        inv.set(POSE + VEL + ACC, np.concatenate(autotest_motion(t)))
        out[i] = inv.get(F)
    return out
