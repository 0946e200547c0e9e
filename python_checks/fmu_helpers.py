"""Small helpers for the FMU checks: the spec's trajectory and constants, and a
thin, always-cleaning-up wrapper around fmpy's FMU2Slave and FMU3Slave.

Every number here is copied from /work/shared/MODEL_SPEC.md (the authoritative
definition of the mechanism), never from an output of the code under test.
"""
import math
import shutil

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

# --- MODEL_SPEC "Auto-test": rest-to-rest quintic from P0 to P1 in 2 s -------
T_MOVE = 2.0  # s
P0 = np.array([0.0, 0.0, 0.05, 0.0])  # x, y, z (m), phi (rad)
P1 = np.array([0.005, -0.005, 0.07, math.radians(4.0)])

# --- MODEL_SPEC "Bodies" (Table III) and "Geometry defaults" (Table II) ------
M_SLIDER = 0.09331  # kg
M_ROD = 0.06371  # kg
M_PLATFORM = 0.45474  # kg
L_ROD = 0.080  # m
G = 9.81  # m/s^2
# "A check anyone can derive": each actuator's share of the weight at P0.
STATIC_FORCE_P0 = 2.655616050  # N
TOTAL_WEIGHT = 10.622464200  # N

POSE = ["x", "y", "z", "phi"]
VEL = ["dx", "dy", "dz", "dphi"]
ACC = ["ddx", "ddy", "ddz", "ddphi"]


def arr(name, n):
    """FMI array names, 1-based: arr('F', 4) -> ['F[1]', ..., 'F[4]']."""
    return [f"{name}[{i}]" for i in range(1, n + 1)]


F = arr("F", 4)


def blend(tau):
    """s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 and its first two derivatives,
    held at rest before tau = 0 and after tau = 1 (the motion is rest to rest)."""
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
    ds = 30.0 * tau**2 * (1.0 - tau) ** 2
    dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau)
    return s, ds, dds


def p(t):
    """Prescribed pose (x, y, z, phi) at time t."""
    return P0 + (P1 - P0) * blend(t / T_MOVE)[0]


def pd(t):
    """Prescribed velocity at time t."""
    return (P1 - P0) * blend(t / T_MOVE)[1] / T_MOVE


def pdd(t):
    """Prescribed acceleration at time t."""
    return (P1 - P0) * blend(t / T_MOVE)[2] / T_MOVE**2


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

    def __init__(self, path, start=None, instance_name="instance", unzipdir=None, start_time=0.0):
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
    vr_in = inv.vrs(POSE + VEL + ACC)
    vr_out = inv.vrs(F)
    for i, t in enumerate(times):
        inv.fmu.setReal(vr_in, [*p(t), *pd(t), *pdd(t)])
        out[i] = inv.fmu.getReal(vr_out)
    return out
