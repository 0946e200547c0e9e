# SPDX-License-Identifier: BSD-2-Clause
"""The plant's linearisation through its FMI 2.0 Model Exchange interface and
fmpy, as any importer would get it: A = d der(y)/dy (8 x 8) and
B = d der(y)/du (8 x 12) by fmi2GetDirectionalDerivative, y the pose and
rates, u the plant's inputs in pkm.h's order (the C API's
pkm_forward_derivatives uses the same).

    with ModelExchange(find_fmu("PKM4PUU")) as me:
        ydot, A, B = me.jacobians(y, u)

The FMU's two further states, the running integrals actuator_work and
dissipated_energy, do not act on the motion: they are left out of A and B
(kept at the values the instance has).
"""
import shutil
from ctypes import POINTER, c_double

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model

from .interface import F, POSE, VEL, WRENCH, indexed_names

STATES = POSE + VEL
INPUTS = F + WRENCH + indexed_names("tau", 4)


class ModelExchange:
    """One Model Exchange instance of the plant FMU (FMI 2.0) in continuous-time
    mode; `start` values (Real parameters by name) are set before
    initialisation. Use in a with block."""

    def __init__(self, path, start=None, instance_name="linearization"):
        self.path = str(path)
        self.start = dict(start or {})
        self.instance_name = instance_name
        self.md = read_model_description(self.path)
        if self.md.fmiVersion != "2.0" or self.md.modelExchange is None:
            raise ValueError(f"{self.path}: not an FMI 2.0 Model Exchange FMU")
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        by_state = {d.variable.derivative.name: d.variable.valueReference for d in self.md.derivatives}
        missing = [n for n in STATES if n not in by_state]
        if missing:
            raise ValueError(f"{self.path}: no state derivative for {missing}")
        self.state_names = [d.variable.derivative.name for d in self.md.derivatives]
        self.index = [self.state_names.index(n) for n in STATES]
        self.der_vrs = [by_state[n] for n in STATES]
        self.state_vrs = [self.vr[n] for n in STATES]
        self.input_vrs = [self.vr[n] for n in INPUTS]
        self.unzipdir = None
        self.fmu = None

    def __enter__(self):
        try:
            self.unzipdir = extract(self.path)
            self.fmu = FMU2Model(guid=self.md.guid, unzipDirectory=self.unzipdir,
                                 modelIdentifier=self.md.modelExchange.modelIdentifier,
                                 instanceName=self.instance_name)
            self.fmu.instantiate()
            self.fmu.setupExperiment(startTime=0.0)
            if self.start:
                self.fmu.setReal([self.vr[n] for n in self.start], [float(v) for v in self.start.values()])
            self.fmu.enterInitializationMode()
            self.fmu.exitInitializationMode()
            self.fmu.newDiscreteStates()
            self.fmu.enterContinuousTimeMode()
            self.n = len(self.state_names)
            self.x = np.zeros(self.n)
            self.dx = np.zeros(self.n)
            self.fmu.getContinuousStates(self.x.ctypes.data_as(POINTER(c_double)), self.n)
        except BaseException:
            self.close()
            raise
        return self

    def close(self):
        if self.fmu is not None:
            try:
                self.fmu.terminate()
            except Exception:
                pass
            self.fmu.freeInstance()
            self.fmu = None
        if self.unzipdir is not None:
            shutil.rmtree(self.unzipdir, ignore_errors=True)
            self.unzipdir = None

    def __exit__(self, *exc):
        self.close()
        return False

    def set_point(self, y, u):
        """Sets the pose and rates y (8) and the inputs u (12)."""
        y, u = np.asarray(y, float), np.asarray(u, float)
        if y.shape != (len(STATES),) or u.shape != (len(INPUTS),):
            raise ValueError(f"y must have {len(STATES)} values and u {len(INPUTS)}, not {y.shape} and {u.shape}")
        self.x[self.index] = y
        self.fmu.setContinuousStates(self.x.ctypes.data_as(POINTER(c_double)), self.n)
        self.fmu.setReal(self.input_vrs, list(u))

    def derivative(self, y, u):
        """der(y) (8) at (y, u): fmi2GetDerivatives."""
        self.set_point(y, u)
        self.fmu.getDerivatives(self.dx.ctypes.data_as(POINTER(c_double)), self.n)
        return self.dx[self.index].copy()

    def jacobians(self, y, u):
        """(der(y) (8,), A (8, 8), B (8, 12)) at (y, u): one
        fmi2GetDirectionalDerivative per known (a unit seed each)."""
        ydot = self.derivative(y, u)
        knowns = self.state_vrs + self.input_vrs
        J = np.column_stack([self.fmu.getDirectionalDerivative(self.der_vrs, knowns, list(seed))
                             for seed in np.eye(len(knowns))])
        return ydot, J[:, :len(STATES)], J[:, len(STATES):]
