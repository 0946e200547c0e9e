# SPDX-License-Identifier: BSD-2-Clause
"""ctypes binding of this project's C API (pkm.h), for the engine
comparisons. The library is locate.LIBRARY of the build directory when one
is asked for (the `build` argument, else $PKM_BUILD_DIR), else the
installed package's own (a wheel's), else ./build's: see locate::

    lib = load()                      # or load(path)
    with Plant(lib) as m:             # spec defaults; Plant(lib, g=0.0) etc.
        m.set_solver(solver=PKM_SOLVER_CVODE, rtol=1e-12, atol=1e-14)
        m.init_pose(0.0, [0, 0, 0.05, 0])
        m.advance_fn(1.0, lambda t: (F, wrench))
        out = m.outputs(F)
"""
import ctypes as ct
from pathlib import Path

import numpy as np

from . import locate

PKM_OK = 0
PKM_SOLVER_CVODE, PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK = 0, 1, 2
PKM_CVODE_ADAMS, PKM_CVODE_BDF = 0, 1
PKM_FORM_AUGMENTED, PKM_FORM_NULLSPACE_QR, PKM_FORM_LEG_PARTITIONED = 0, 1, 2
# pkm_forward_derivatives: the state (x, y, z, phi, dx, dy, dz, dphi) and the
# plant's inputs, in pkm.h's order (PKM_PLANT_INPUTS)
PLANT_STATES = 8
PLANT_INPUTS = 12  # F[1..4] (N), Fe[1..3] (N), Me_z (N m), tau[1..4] (N m)

D4 = ct.c_double * 4
# Every struct the library writes into ends in this reserve, so that fields
# appended to a pkm.h struct later (filled by the library's own defaults:
# pkm_default_params, pkm_default_solver_settings) cannot overrun the buffer;
# the fields before it must be pkm.h's, in order (test_engines_models.py
# checks them against the header).
RESERVE = ("_reserved", ct.c_double * 64)


class Params(ct.Structure):
    _fields_ = [("h", ct.c_double), ("l", ct.c_double), ("h_prime", ct.c_double), ("r_b", ct.c_double),
                ("r_Q", ct.c_double), ("beta", ct.c_double * 4), ("gamma", ct.c_double * 4),
                ("m_slider", ct.c_double), ("m_rod", ct.c_double), ("I_rod", ct.c_double * 3),
                ("m_platform", ct.c_double), ("Izz_platform", ct.c_double), ("g", ct.c_double), RESERVE]


class SolverSettings(ct.Structure):
    _fields_ = [("solver", ct.c_int), ("rk4_step", ct.c_double), ("rtol", ct.c_double), ("atol", ct.c_double),
                ("cvode_method", ct.c_int), ("formulation", ct.c_int), RESERVE]


class Outputs(ct.Structure):
    _fields_ = [("t", ct.c_double), ("pose", ct.c_double * 4), ("velocity", ct.c_double * 4),
                ("acceleration", ct.c_double * 4), ("rho", ct.c_double * 4), ("drho", ct.c_double * 4),
                ("theta1", ct.c_double * 4), ("theta2", ct.c_double * 4), ("q", ct.c_double * 16),
                ("qd", ct.c_double * 16), ("qdd", ct.c_double * 16), ("lambda_", ct.c_double * 12),
                ("constraint_residual", ct.c_double), ("jacobian_condition", ct.c_double), RESERVE]


class InverseResult(ct.Structure):
    _fields_ = [("F", ct.c_double * 4), ("lambda_", ct.c_double * 12), ("q", ct.c_double * 16),
                ("qd", ct.c_double * 16), ("qdd", ct.c_double * 16), RESERVE]


class MachineParams(ct.Structure):
    _fields_ = [("screw_lead", ct.c_double), ("rotor_inertia", ct.c_double), ("friction_viscous", ct.c_double),
                ("friction_coulomb", ct.c_double), ("friction_velocity", ct.c_double), ("rho_min", ct.c_double),
                ("rho_max", ct.c_double), ("stop_stiffness", ct.c_double), ("stop_damping", ct.c_double),
                ("payload_mass", ct.c_double), ("payload_com", ct.c_double * 2), ("payload_Izz", ct.c_double),
                RESERVE]


class MachineOutputs(ct.Structure):
    _fields_ = [("stop_force", ct.c_double * 4), ("friction_force", ct.c_double * 4), ("F_hold", ct.c_double * 4),
                ("kinetic_energy", ct.c_double), ("potential_energy", ct.c_double), ("actuator_work", ct.c_double),
                ("dissipated_energy", ct.c_double), ("stop_indicators", ct.c_double * 8), RESERVE]


class InverseMachineResult(ct.Structure):
    _fields_ = [("F", ct.c_double * 4), ("tau", ct.c_double * 4), ("lambda_", ct.c_double * 12),
                ("beyond_stops", ct.c_uint), RESERVE]


INPUT_FN = ct.CFUNCTYPE(None, ct.c_void_p, ct.c_double, ct.POINTER(ct.c_double), ct.POINTER(ct.c_double))
TORQUE_FN = ct.CFUNCTYPE(None, ct.c_void_p, ct.c_double, ct.POINTER(ct.c_double))


def library_path(build=None):
    """libpkm.so: the asked-for build directory's, else the package's, else
    ./build's (locate.library_path)."""
    return locate.library_path(build)


def load(path=None):
    """Loads libpkm.so and declares the signatures of pkm.h."""
    lib = ct.CDLL(str(path or library_path()))
    P, vp, dp, i = ct.POINTER, ct.c_void_p, ct.POINTER(ct.c_double), ct.c_int
    lib.pkm_default_params.argtypes = [P(Params)]
    lib.pkm_default_params.restype = None
    lib.pkm_default_solver_settings.argtypes = [P(SolverSettings)]
    lib.pkm_default_solver_settings.restype = None
    lib.pkm_create.argtypes = [P(Params), P(vp), ct.c_char_p, ct.c_size_t]
    lib.pkm_create.restype = i
    lib.pkm_destroy.argtypes = [vp]
    lib.pkm_destroy.restype = None
    lib.pkm_last_error.argtypes = [vp]
    lib.pkm_last_error.restype = ct.c_char_p
    lib.pkm_set_solver.argtypes = [vp, P(SolverSettings)]
    lib.pkm_set_solver.restype = i
    lib.pkm_set_step_checks.argtypes = [vp, ct.c_double, ct.c_double]
    lib.pkm_set_step_checks.restype = i
    lib.pkm_get_step_checks.argtypes = [vp, dp, dp]
    lib.pkm_get_step_checks.restype = i
    lib.pkm_init_pose.argtypes = [vp, ct.c_double, dp, dp]
    lib.pkm_init_pose.restype = i
    lib.pkm_inverse_dynamics.argtypes = [vp, dp, dp, dp, dp, P(InverseResult)]
    lib.pkm_inverse_dynamics.restype = i
    lib.pkm_advance.argtypes = [vp, ct.c_double, dp, dp]
    lib.pkm_advance.restype = i
    lib.pkm_advance_fn.argtypes = [vp, ct.c_double, INPUT_FN, vp, i]
    lib.pkm_advance_fn.restype = i
    lib.pkm_get_outputs.argtypes = [vp, dp, dp, P(Outputs)]
    lib.pkm_get_outputs.restype = i
    lib.pkm_get_state.argtypes = [vp, dp, dp, dp]
    lib.pkm_get_state.restype = i
    lib.pkm_set_state.argtypes = [vp, ct.c_double, dp, dp]
    lib.pkm_set_state.restype = i
    # the machine around the mechanism
    lib.pkm_default_machine_params.argtypes = [P(MachineParams)]
    lib.pkm_default_machine_params.restype = None
    lib.pkm_create_machine.argtypes = [P(Params), P(MachineParams), P(vp), ct.c_char_p, ct.c_size_t]
    lib.pkm_create_machine.restype = i
    lib.pkm_advance_fn_drives.argtypes = [vp, ct.c_double, INPUT_FN, TORQUE_FN, vp, i]
    lib.pkm_advance_fn_drives.restype = i
    lib.pkm_get_machine_outputs.argtypes = [vp, dp, dp, dp, P(MachineOutputs)]
    lib.pkm_get_machine_outputs.restype = i
    lib.pkm_inverse_dynamics_machine.argtypes = [vp, dp, dp, dp, dp, P(InverseMachineResult)]
    lib.pkm_inverse_dynamics_machine.restype = i
    # analytic derivatives
    lib.pkm_forward_derivatives.argtypes = [vp, dp, dp, dp, dp, dp]
    lib.pkm_forward_derivatives.restype = i
    lib.pkm_inverse_derivatives.argtypes = [vp, dp, dp, dp, dp, dp, dp]
    lib.pkm_inverse_derivatives.restype = i
    # calibration: the regressor of the forces in the dynamic parameters
    sz = ct.c_size_t
    lib.pkm_regressor_param_count.argtypes = []
    lib.pkm_regressor_param_count.restype = i
    for f in (lib.pkm_regressor_param_name, lib.pkm_regressor_param_unit):
        f.argtypes = [i]
        f.restype = ct.c_char_p
    lib.pkm_regressor_params.argtypes = [vp, dp]
    lib.pkm_regressor_params.restype = i
    lib.pkm_regressor.argtypes = [vp, dp, dp, dp, dp, dp, dp]
    lib.pkm_regressor.restype = i
    lib.pkm_regressor_poses.argtypes = [vp, sz, dp, dp, dp, dp, dp, dp, dp]
    lib.pkm_regressor_poses.restype = i
    lib.pkm_regressor_joints.argtypes = [vp, sz, dp, dp, dp, dp, dp, dp, dp, P(sz)]
    lib.pkm_regressor_joints.restype = i
    return lib


def regressor_params(lib):
    """[(name, unit)] of the regressor's parameter vector pi (pkm.h's
    pkm_regressor_param_name/unit), in pi's order."""
    return [(lib.pkm_regressor_param_name(j).decode(), lib.pkm_regressor_param_unit(j).decode())
            for j in range(lib.pkm_regressor_param_count())]


_DP = ct.POINTER(ct.c_double)


def _d4(a):
    return None if a is None else D4(*[float(v) for v in a])


class PkmError(RuntimeError):
    pass


class Plant:
    """One pkm_model handle. Keyword arguments override the default parameters
    (pkm_default_params), e.g. Plant(lib, g=0.0). machine: a dict of
    pkm_machine_params fields overriding pkm_default_machine_params (the
    model is then made by pkm_create_machine), e.g. {"rotor_inertia": 1e-7}."""

    def __init__(self, lib, machine=None, **params):
        self.lib = lib
        p = Params()
        lib.pkm_default_params(ct.byref(p))
        for k, v in params.items():
            setattr(p, k, v)
        self.params = p
        self.handle = ct.c_void_p()
        err = ct.create_string_buffer(256)
        if machine is None:
            s = lib.pkm_create(ct.byref(p), ct.byref(self.handle), err, 256)
            what = "pkm_create"
        else:
            mp = MachineParams()
            lib.pkm_default_machine_params(ct.byref(mp))
            for k, v in machine.items():
                if k == "payload_com":
                    mp.payload_com[0], mp.payload_com[1] = v
                else:
                    setattr(mp, k, v)
            self.machine = mp
            s = lib.pkm_create_machine(ct.byref(p), ct.byref(mp), ct.byref(self.handle), err, 256)
            what = "pkm_create_machine"
        if s != PKM_OK:
            raise PkmError(f"{what}: status {s}: {err.value.decode()}")
        self._callback = None

    def close(self):
        if self.handle:
            self.lib.pkm_destroy(self.handle)
            self.handle = ct.c_void_p()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _check(self, s, what):
        if s != PKM_OK:
            raise PkmError(f"{what}: status {s}: {self.lib.pkm_last_error(self.handle).decode()}")

    def set_solver(self, **settings):
        s = SolverSettings()
        self.lib.pkm_default_solver_settings(ct.byref(s))
        for k, v in settings.items():
            setattr(s, k, v)
        self._check(self.lib.pkm_set_solver(self.handle, ct.byref(s)), "pkm_set_solver")

    def set_step_checks(self, work_budget=1000.0, energy_tolerance=0.0):
        """The fixed-step solvers' work budget (inner steps per grid step) and
        the energy audit's run-time check (J, 0 = off): docs/solvers.md."""
        self._check(self.lib.pkm_set_step_checks(self.handle, work_budget, energy_tolerance), "pkm_set_step_checks")

    def step_checks(self):
        """(work_budget, energy_tolerance)."""
        b, e = ct.c_double(), ct.c_double()
        self._check(self.lib.pkm_get_step_checks(self.handle, ct.byref(b), ct.byref(e)), "pkm_get_step_checks")
        return b.value, e.value

    def init_pose(self, t0, pose, velocity=None):
        self._check(self.lib.pkm_init_pose(self.handle, t0, _d4(pose), _d4(velocity)), "pkm_init_pose")

    def inverse_dynamics(self, pose, velocity, acceleration, wrench=None):
        r = InverseResult()
        self._check(self.lib.pkm_inverse_dynamics(self.handle, _d4(pose), _d4(velocity), _d4(acceleration),
                                                  _d4(wrench), ct.byref(r)), "pkm_inverse_dynamics")
        return r

    def advance(self, t_end, F=None, wrench=None):
        self._check(self.lib.pkm_advance(self.handle, t_end, _d4(F), _d4(wrench)), "pkm_advance")

    @staticmethod
    def _input_callback(inputs):
        """The C callback that writes inputs(t) -> F[4], or (F, wrench), into the C arrays."""

        def cb(_user, t, F, w):
            r = inputs(t)
            f, wr = (r if isinstance(r, tuple) else (r, None))
            for k in range(4):
                F[k] = f[k]
            if wr is not None:
                for k in range(4):
                    w[k] = wr[k]

        return cb

    def advance_fn(self, t_end, inputs, continuous=True):
        """inputs(t) -> F[4] (N), or (F, wrench); evaluated at the integrator's own times."""

        self._callback = INPUT_FN(self._input_callback(inputs))  # kept alive for the call
        self._check(self.lib.pkm_advance_fn(self.handle, t_end, self._callback, None, int(continuous)),
                    "pkm_advance_fn")

    def advance_fn_drives(self, t_end, inputs, torques, continuous=True):
        """inputs(t) -> F[4] (N), or (F, wrench); torques(t) -> tau[4] (N m);
        both evaluated at the integrator's own times (pkm_advance_fn_drives)."""

        cb = self._input_callback(inputs)

        def cb_tau(_user, t, tau):
            r = torques(t)
            for k in range(4):
                tau[k] = r[k]

        self._callback = (INPUT_FN(cb), TORQUE_FN(cb_tau))  # kept alive for the call
        self._check(self.lib.pkm_advance_fn_drives(self.handle, t_end, self._callback[0], self._callback[1], None,
                                                   int(continuous)), "pkm_advance_fn_drives")

    def machine_outputs(self, F=None, tau=None, wrench=None):
        o = MachineOutputs()
        self._check(self.lib.pkm_get_machine_outputs(self.handle, _d4(F), _d4(tau), _d4(wrench), ct.byref(o)),
                    "pkm_get_machine_outputs")
        return o

    def inverse_dynamics_machine(self, pose, velocity, acceleration, wrench=None):
        r = InverseMachineResult()
        self._check(self.lib.pkm_inverse_dynamics_machine(self.handle, _d4(pose), _d4(velocity), _d4(acceleration),
                                                          _d4(wrench), ct.byref(r)), "pkm_inverse_dynamics_machine")
        return r

    def forward_derivatives(self, state, inputs=None):
        """pkm_forward_derivatives: (ydot (8,), A (8, 8), B (8, 12)) of the
        reduced forward dynamics at state (x, y, z, phi, dx, dy, dz, dphi) and
        inputs (PLANT_INPUTS order; None: zero), as numpy arrays."""
        y = np.ascontiguousarray(state, dtype=float)
        if y.shape != (PLANT_STATES,):
            raise ValueError(f"state must have {PLANT_STATES} values, not shape {y.shape}")
        u = None
        if inputs is not None:
            u = np.ascontiguousarray(inputs, dtype=float)
            if u.shape != (PLANT_INPUTS,):
                raise ValueError(f"inputs must have {PLANT_INPUTS} values, not shape {u.shape}")
        yd = np.empty(PLANT_STATES)
        A, B = np.empty((PLANT_STATES, PLANT_STATES)), np.empty((PLANT_STATES, PLANT_INPUTS))
        self._check(self.lib.pkm_forward_derivatives(
            self.handle, y.ctypes.data_as(_DP), None if u is None else u.ctypes.data_as(_DP), yd.ctypes.data_as(_DP),
            A.ctypes.data_as(_DP), B.ctypes.data_as(_DP)), "pkm_forward_derivatives")
        return yd, A, B

    def inverse_derivatives(self, pose, velocity, acceleration, wrench=None):
        """pkm_inverse_derivatives: (F (4,), dF (4, 16)), dF with respect to
        (pose, velocity, acceleration, wrench)."""
        F, dF = np.empty(4), np.empty((4, 16))
        self._check(self.lib.pkm_inverse_derivatives(self.handle, _d4(pose), _d4(velocity), _d4(acceleration),
                                                     _d4(wrench), F.ctypes.data_as(_DP), dF.ctypes.data_as(_DP)),
                    "pkm_inverse_derivatives")
        return F, dF

    def regressor_params(self):
        """pkm_regressor_params: the model's own parameter vector pi."""
        pi = np.empty(self.lib.pkm_regressor_param_count())
        self._check(self.lib.pkm_regressor_params(self.handle, pi.ctypes.data_as(_DP)), "pkm_regressor_params")
        return pi

    def regressor(self, pose, velocity, acceleration, wrench=None):
        """pkm_regressor: (Y (4, n_pi), F0 (4,)) with F = Y pi + F0."""
        Y, F0 = np.empty((4, self.lib.pkm_regressor_param_count())), np.empty(4)
        self._check(self.lib.pkm_regressor(self.handle, _d4(pose), _d4(velocity), _d4(acceleration), _d4(wrench),
                                           Y.ctypes.data_as(_DP), F0.ctypes.data_as(_DP)), "pkm_regressor")
        return Y, F0

    def regressor_poses(self, pose, velocity, acceleration):
        """pkm_regressor_poses over (n, 4) arrays: (Y (n, 4, n_pi), F0, rho, drho (n, 4))."""
        P, V, A = (np.ascontiguousarray(a, dtype=float).reshape(-1, 4) for a in (pose, velocity, acceleration))
        n = len(P)
        if len(V) != n or len(A) != n:
            raise ValueError("pose, velocity and acceleration need the same number of rows")
        Y = np.empty((n, 4, self.lib.pkm_regressor_param_count()))
        F0, rho, drho = np.empty((n, 4)), np.empty((n, 4)), np.empty((n, 4))
        self._check(self.lib.pkm_regressor_poses(self.handle, n, *(a.ctypes.data_as(_DP) for a in (P, V, A, Y, F0, rho,
                                                                                                  drho))),
                    "pkm_regressor_poses")
        return Y, F0, rho, drho

    def regressor_joints(self, rho, drho, ddrho, guess=None):
        """pkm_regressor_joints over (n, 4) arrays of the sliders' positions,
        rates, accelerations: (Y (n, 4, n_pi), F0 (n, 4), pose (n, 4)). On a
        failure PkmError says which sample; its attribute `sample` holds it."""
        R, V, A = (np.ascontiguousarray(a, dtype=float).reshape(-1, 4) for a in (rho, drho, ddrho))
        n = len(R)
        if len(V) != n or len(A) != n:
            raise ValueError("rho, drho and ddrho need the same number of rows")
        Y = np.empty((n, 4, self.lib.pkm_regressor_param_count()))
        F0, pose = np.empty((n, 4)), np.empty((n, 4))
        done = ct.c_size_t(0)
        s = self.lib.pkm_regressor_joints(self.handle, n, R.ctypes.data_as(_DP), V.ctypes.data_as(_DP),
                                          A.ctypes.data_as(_DP), _d4(guess), Y.ctypes.data_as(_DP),
                                          F0.ctypes.data_as(_DP), pose.ctypes.data_as(_DP), ct.byref(done))
        if s != PKM_OK:
            err = PkmError(f"pkm_regressor_joints: status {s}: {self.lib.pkm_last_error(self.handle).decode()}")
            err.sample, err.status = done.value, s
            raise err
        return Y, F0, pose

    def outputs(self, F=None, wrench=None):
        o = Outputs()
        self._check(self.lib.pkm_get_outputs(self.handle, _d4(F), _d4(wrench), ct.byref(o)), "pkm_get_outputs")
        return o


# --- the layout check against pkm.h ------------------------------------------------------
_C_TYPES = {"double": (8, 8), "int": (4, 4), "unsigned": (4, 4)}


def header_structs(path):
    """{struct name: [(field name, offset, size)]} for pkm.h's plain structs of
    doubles and ints (C layout rules for x86_64), and their sizes; `path` is
    the header pkm.h (in the source tree, which this package does not know)."""
    import re
    text = re.sub(r"/\*.*?\*/", " ", Path(path).read_text(), flags=re.S)
    out = {}
    for body, name in re.findall(r"typedef\s+struct\s*\{(.*?)\}\s*(\w+)\s*;", text, flags=re.S):
        fields, offset, align_max = [], 0, 1
        for decl in body.split(";"):
            decl = decl.strip()
            if not decl:
                continue
            ctype, rest = decl.split(None, 1)
            size, align = _C_TYPES[ctype]
            for item in rest.split(","):
                m = re.fullmatch(r"\s*(\w+)\s*(?:\[(\d+)\])?\s*", item)
                count = int(m.group(2) or 1)
                offset = (offset + align - 1) // align * align
                fields.append((m.group(1), offset, size * count))
                offset += size * count
                align_max = max(align_max, align)
        out[name] = (fields, (offset + align_max - 1) // align_max * align_max)
    return out


def binding_mismatches(path):
    """Differences between this binding's structs and those of the header
    pkm.h at `path` (empty: they agree).
    pkm.h may have appended fields, as long as they fit in the reserve."""
    structs = header_structs(path)
    bad = []
    for cname, cls in (("pkm_params", Params), ("pkm_solver_settings", SolverSettings), ("pkm_outputs", Outputs),
                       ("pkm_inverse_result", InverseResult), ("pkm_machine_params", MachineParams),
                       ("pkm_machine_outputs", MachineOutputs), ("pkm_inverse_machine_result", InverseMachineResult)):
        fields, size = structs[cname]
        ours = [(n.rstrip("_"), getattr(cls, n).offset, getattr(cls, n).size) for n, _ in cls._fields_
                if n != "_reserved"]
        if fields[:len(ours)] != ours:
            bad.append(f"{cname}: pkm.h {fields[:len(ours)]} != binding {ours}")
        if size > ct.sizeof(cls):
            bad.append(f"{cname}: pkm.h's struct ({size} bytes) does not fit the binding's ({ct.sizeof(cls)} bytes)")
    return bad
