# SPDX-License-Identifier: BSD-2-Clause
"""cffi binding of this project's C API (pkm.h), read from the header itself.

The build preprocesses include/pkm4puu/pkm.h into lib/pkm_cdef.h beside the
library (locate.CDEF; a wheel ships both): cffi declares every function, enum
and struct from it, so no field can go missing, and a struct's fields are read
by name. The parameters are the FMUs' (same names, ranges and defaults), which
the library lists (pkm_parameter_info); nothing here spells them out::

    lib = load()                      # or load(path): libpkm of the build or the package (locate)
    with Plant(lib, g=0.0, payload_mass=0.25) as m:   # the FMUs' parameter names
        m.set_solver(solver=lib.PKM_SOLVER_CVODE, rtol=1e-12, atol=1e-14)
        m.init_pose(0.0, [0, 0, 0.05, 0])
        m.advance_fn(1.0, lambda t: (F, wrench))
        out = m.outputs(F)            # every field of pkm_outputs: out.pose, out.F_hold, ...

An unknown keyword raises TypeError naming it and the known ones; a value
the library refuses raises PkmError with its message.
"""
import os
from collections import namedtuple
from functools import lru_cache
from keyword import iskeyword
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from . import locate


def library_path(build=None):
    """libpkm: the asked-for build directory's, else the package's, else
    ./build's (locate.library_path)."""
    return locate.library_path(build)


def cdef_path(library):
    """pkm.h as cffi reads it (lib/pkm_cdef.h), beside the library."""
    return Path(library).with_name(Path(locate.CDEF).name)


@lru_cache(maxsize=None)
def _ffi(cdef):
    import cffi
    ffi = cffi.FFI()
    ffi.cdef(Path(cdef).read_text())
    return ffi


# What pkm_parameter_info says of a parameter (its fields but the size).
ParameterInfo = namedtuple("ParameterInfo", "name unit description start min max is_integer is_solver_setting "
                                            "is_tunable fmus value_reference")


class Library:
    """libpkm loaded with its declarations: `c` holds the functions and enum
    constants (lib.c.PKM_OK), `ffi` the types; `parameters` maps each
    parameter's name to its ParameterInfo, in the library's order."""

    def __init__(self, path):
        self.path = Path(path)
        cdef = cdef_path(self.path)
        if not cdef.is_file():
            raise FileNotFoundError(f"{cdef} does not exist: the build writes it beside {self.path.name} "
                                    f"(target pkm)")
        self.ffi = _ffi(str(cdef))
        self.c = self.ffi.dlopen(str(self.path))
        self.parameters = {}
        info = self.new("pkm_parameter")
        for i in range(self.c.pkm_parameter_count()):
            if self.c.pkm_parameter_info(i, info) != self.c.PKM_OK:
                raise PkmError(f"pkm_parameter_info({i}) failed")
            fields = to_python(self, info)
            self.parameters[fields["name"]] = ParameterInfo(**fields)

    def new(self, struct):
        """A zeroed pkm.h struct with its size field set."""
        p = self.ffi.new(f"{struct}*")
        p.size = self.ffi.sizeof(struct)
        return p

    def __getattr__(self, name):
        # lib.PKM_SOLVER_RK4, lib.pkm_version(): the library's own names.
        if name.startswith(("pkm_", "PKM_")) and "c" in self.__dict__:
            return getattr(self.c, name)
        raise AttributeError(name)


def load(path=None):
    """libpkm (library_path() when no path is given) with its declarations,
    loaded once per file: every later call for it returns the same Library."""
    return _load(Path(os.path.abspath(path or library_path())))


@lru_cache(maxsize=None)
def _load(path):
    return Library(path)


def to_python(lib, struct):
    """{field: value} of a pkm.h struct but its size: strings as str, arrays
    as numpy arrays (copies), numbers as float or int."""
    ffi = lib.ffi
    out = {}
    for name, kind in _fields(ffi, ffi.typeof(struct[0])):
        if kind == "double[]":
            out[name] = np.frombuffer(ffi.buffer(getattr(struct, name)), dtype=float).copy()
        elif kind == "array":
            out[name] = np.array(list(getattr(struct, name)), dtype=np.int64)
        elif kind == "string":
            value = getattr(struct, name)
            out[name] = ffi.string(value).decode() if value != ffi.NULL else None
        else:
            out[name] = getattr(struct, name)
    return out


@lru_cache(maxsize=None)
def _fields(ffi, ctype):
    """[(field, kind)] of a struct type but its size field: how to_python reads each."""
    kinds = []
    for name, field in ctype.fields:
        t = field.type
        if name == "size":
            continue
        if t.kind == "array":
            kinds.append((name, "double[]" if t.item.cname == "double" else "array"))
        elif t.kind == "pointer" and t.item.cname == "char":
            kinds.append((name, "string"))
        else:
            kinds.append((name, "number"))
    return kinds


def _namespace(fields):
    """Attributes for fields; a field named like a Python keyword gets a
    trailing underscore (lambda -> lambda_)."""
    return SimpleNamespace(**{(k + "_" if iskeyword(k) else k): v for k, v in fields.items()})


def regressor_params(lib):
    """[(name, unit)] of the regressor's parameter vector pi (pkm.h's
    pkm_regressor_param_name/unit), in pi's order."""
    c, ffi = lib.c, lib.ffi
    return [(ffi.string(c.pkm_regressor_param_name(j)).decode(), ffi.string(c.pkm_regressor_param_unit(j)).decode())
            for j in range(c.PKM_REGRESSOR_PARAMS)]


class PkmError(RuntimeError):
    """A call that failed: the function, the status and the library's message."""

    def __init__(self, message, status=None):
        super().__init__(message)
        self.status = status


class Plant:
    """One pkm_model handle. Keyword arguments set parameters by the FMUs'
    names (``Plant(lib, g=0.0, payload_mass=0.25)``); an array parameter
    takes all its values (``beta=[...]``, ``payload_com=(x, y)``) or one
    (``**{"beta[2]": 0.1}``)."""

    def __init__(self, lib, **params):
        self.lib, self.c, self.ffi = lib, lib.c, lib.ffi
        handle = self.ffi.new("pkm_model**")
        s = self.c.pkm_create(handle)
        if s != self.c.PKM_OK:
            raise PkmError(f"pkm_create: {self._status(s)}", s)
        self.handle = self.ffi.gc(handle[0], self.c.pkm_destroy)  # destroyed with the object, or by close()
        self._callback = None
        try:
            self.set(**params)
        except Exception:
            self.close()
            raise

    def close(self):
        if self.handle is not None:
            self.ffi.release(self.handle)
            self.handle = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _status(self, s):
        return self.ffi.string(self.c.pkm_status_string(s)).decode()

    def _check(self, s, what):
        if s != self.c.PKM_OK:
            raise PkmError(f"{what}: status {s}: {self.ffi.string(self.c.pkm_last_error(self.handle)).decode()}", s)

    # ---- parameters
    def _expand(self, params, allowed=None):
        """[(FMU name, value)] of keyword arguments; TypeError for a name the
        library (or `allowed`) does not know."""
        known = self.lib.parameters if allowed is None else allowed
        items = []
        for key, value in params.items():
            if key in known:
                items.append((key, float(value)))
                continue
            elements = [n for n in known if n.startswith(key + "[")]
            if elements and np.ndim(value) == 1 and len(value) == len(elements):
                items += [(n, float(v)) for n, v in zip(elements, value)]
                continue
            if elements:
                raise TypeError(f"{key} has {len(elements)} values ({', '.join(elements)}): give them all, "
                                f"not {value!r}")
            raise TypeError(f"unknown parameter {key!r}; the known ones: {', '.join(known)}")
        return items

    def set(self, **params):
        """Sets parameters as one change (pkm_set_parameters: checked as a
        set, all or nothing). A run goes on through a change of the payload
        (the tunable parameters: a grasp or a release now, the velocity kept,
        the payload's energy booked into actuator_work) and of solver
        settings; a change of any other parameter ends it."""
        items = self._expand(params)
        if not items:
            return
        names = [self.ffi.new("char[]", n.encode()) for n, _ in items]
        s = self.c.pkm_set_parameters(self.handle, len(items), self.ffi.new("char*[]", names),
                                      self.ffi.new("double[]", [v for _, v in items]))
        self._check(s, "pkm_set_parameters")

    def set_solver(self, **settings):
        """Sets solver settings only (solver, rk4_step, rtol, atol,
        cvode_method, formulation, the guards, work_budget,
        energy_tolerance): they keep the run."""
        solver = {n: i for n, i in self.lib.parameters.items() if i.is_solver_setting}
        items = self._expand(settings, allowed=solver)
        self.set(**dict(items))

    def get(self, name):
        """The value of parameter `name` (pkm_get_parameter)."""
        if name not in self.lib.parameters:
            raise TypeError(f"unknown parameter {name!r}; the known ones: {', '.join(self.lib.parameters)}")
        v = self.ffi.new("double*")
        self._check(self.c.pkm_get_parameter(self.handle, name.encode(), v), "pkm_get_parameter")
        return v[0]

    def parameters(self):
        """{name: value} of every parameter."""
        return {n: self.get(n) for n in self.lib.parameters}

    # ---- helpers
    def _d4(self, a):
        return self.ffi.NULL if a is None else self.ffi.new("double[4]", [float(v) for v in a])

    def _inputs(self, F=None, wrench=None, tau=None):
        """u[PKM_PLANT_INPUTS] = (F, wrench, tau), zero where None."""
        u = np.zeros(self.c.PKM_PLANT_INPUTS)
        for k, part in enumerate((F, wrench, tau)):
            if part is not None:
                u[4 * k:4 * k + 4] = part
        return self.ffi.new("double[]", u.tolist())

    def _doubles(self, a):
        return self.ffi.from_buffer("double[]", a)

    # ---- forward dynamics
    def init_pose(self, t0, pose, velocity=None):
        self._check(self.c.pkm_init_pose(self.handle, t0, self._d4(pose), self._d4(velocity)), "pkm_init_pose")

    def advance(self, t_end, F=None, wrench=None, tau=None):
        """Forward dynamics to t_end with constant inputs (pkm_advance)."""
        self._check(self.c.pkm_advance(self.handle, t_end, self._inputs(F, wrench, tau)), "pkm_advance")

    def advance_fn(self, t_end, inputs, torques=None, continuous=True):
        """Forward dynamics to t_end with inputs(t) -> F[4] (N), or (F,
        wrench); torques(t) -> tau[4] (N m) if given: both evaluated at the
        integrator's own times (pkm_advance_fn)."""

        def cb(_user, t, u):
            r = inputs(t)
            f, wr = (r if isinstance(r, tuple) else (r, None))
            for k in range(4):
                u[k] = f[k]
            if wr is not None:
                for k in range(4):
                    u[4 + k] = wr[k]
            if torques is not None:
                tq = torques(t)
                for k in range(4):
                    u[8 + k] = tq[k]

        self._callback = self.ffi.callback("pkm_input_fn", cb)  # kept alive for the call
        self._check(self.c.pkm_advance_fn(self.handle, t_end, self._callback, self.ffi.NULL, int(continuous)),
                    "pkm_advance_fn")

    def outputs(self, F=None, wrench=None, tau=None):
        """Every field of pkm_outputs at the current time for these inputs."""
        o = self.lib.new("pkm_outputs")
        self._check(self.c.pkm_get_outputs(self.handle, self._inputs(F, wrench, tau), o), "pkm_get_outputs")
        return _namespace(to_python(self.lib, o))

    def state(self):
        """The run's state (pkm_state) for set_state."""
        s = self.lib.new("pkm_state")
        self._check(self.c.pkm_get_state(self.handle, s), "pkm_get_state")
        return s

    def set_state(self, state):
        self._check(self.c.pkm_set_state(self.handle, state), "pkm_set_state")

    # ---- inverse dynamics
    def inverse_dynamics(self, pose, velocity, acceleration, wrench=None):
        """Every field of pkm_inverse_result: F, tau, ``lambda_``, q, qd, qdd, beyond_stops."""
        r = self.lib.new("pkm_inverse_result")
        self._check(self.c.pkm_inverse_dynamics(self.handle, self._d4(pose), self._d4(velocity),
                                                self._d4(acceleration), self._d4(wrench), r), "pkm_inverse_dynamics")
        return _namespace(to_python(self.lib, r))

    # ---- derivatives
    def forward_derivatives(self, state, inputs=None):
        """pkm_forward_derivatives: (ydot (8,), A (8, 8), B (8, 12)) of the
        reduced forward dynamics at state (x, y, z, phi, dx, dy, dz, dphi) and
        inputs (PKM_PLANT_INPUTS order; None: zero), as numpy arrays."""
        n_u = self.c.PKM_PLANT_INPUTS
        y = np.ascontiguousarray(state, dtype=float)
        if y.shape != (8,):
            raise ValueError(f"state must have 8 values, not shape {y.shape}")
        u = self.ffi.NULL
        if inputs is not None:
            u_arr = np.ascontiguousarray(inputs, dtype=float)
            if u_arr.shape != (n_u,):
                raise ValueError(f"inputs must have {n_u} values, not shape {u_arr.shape}")
            u = self._doubles(u_arr)
        yd, A, B = np.empty(8), np.empty((8, 8)), np.empty((8, n_u))
        self._check(self.c.pkm_forward_derivatives(self.handle, self._doubles(y), u, self._doubles(yd),
                                                   self._doubles(A), self._doubles(B)), "pkm_forward_derivatives")
        return yd, A, B

    def inverse_derivatives(self, pose, velocity, acceleration, wrench=None):
        """pkm_inverse_derivatives: (F (4,), dF (4, 16)), dF with respect to
        (pose, velocity, acceleration, wrench)."""
        F, dF = np.empty(4), np.empty((4, 16))
        self._check(self.c.pkm_inverse_derivatives(self.handle, self._d4(pose), self._d4(velocity),
                                                   self._d4(acceleration), self._d4(wrench), self._doubles(F),
                                                   self._doubles(dF)), "pkm_inverse_derivatives")
        return F, dF

    # ---- calibration
    def regressor_params(self):
        """pkm_regressor_params: the model's own parameter vector pi."""
        pi = np.empty(self.c.PKM_REGRESSOR_PARAMS)
        self._check(self.c.pkm_regressor_params(self.handle, self._doubles(pi)), "pkm_regressor_params")
        return pi

    def regressor(self, pose, velocity, acceleration, wrench=None):
        """pkm_regressor: (Y (4, n_pi), F0 (4,)) with F = Y pi + F0."""
        Y, F0 = np.empty((4, self.c.PKM_REGRESSOR_PARAMS)), np.empty(4)
        self._check(self.c.pkm_regressor(self.handle, self._d4(pose), self._d4(velocity), self._d4(acceleration),
                                         self._d4(wrench), self._doubles(Y), self._doubles(F0)), "pkm_regressor")
        return Y, F0

    def _batch(self, name, n, args):
        """The batch call `name` (pkm.h's function) with its done count:
        PkmError names the function and carries `sample`, the first sample
        not computed."""
        done = self.ffi.new("size_t*")
        try:
            self._check(getattr(self.c, name)(self.handle, n, *args, done), name)
        except PkmError as err:
            err.sample = done[0]
            raise

    def regressor_poses(self, pose, velocity, acceleration):
        """pkm_regressor_poses over (n, 4) arrays: (Y (n, 4, n_pi), F0, rho,
        drho (n, 4)). On a failure PkmError names the sample; its attribute
        `sample` holds it."""
        P, V, A = (np.ascontiguousarray(a, dtype=float).reshape(-1, 4) for a in (pose, velocity, acceleration))
        n = len(P)
        if len(V) != n or len(A) != n:
            raise ValueError("pose, velocity and acceleration need the same number of rows")
        Y = np.empty((n, 4, self.c.PKM_REGRESSOR_PARAMS))
        F0, rho, drho = np.empty((n, 4)), np.empty((n, 4)), np.empty((n, 4))
        self._batch("pkm_regressor_poses", n, [self._doubles(a) for a in (P, V, A, Y, F0, rho, drho)])
        return Y, F0, rho, drho

    def regressor_joints(self, rho, drho, ddrho, guess=None):
        """pkm_regressor_joints over (n, 4) arrays of the sliders' positions,
        rates, accelerations: (Y (n, 4, n_pi), F0 (n, 4), pose (n, 4)). On a
        failure PkmError says which sample; its attribute `sample` holds it."""
        R, V, A = (np.ascontiguousarray(a, dtype=float).reshape(-1, 4) for a in (rho, drho, ddrho))
        n = len(R)
        if len(V) != n or len(A) != n:
            raise ValueError("rho, drho and ddrho need the same number of rows")
        Y = np.empty((n, 4, self.c.PKM_REGRESSOR_PARAMS))
        F0, pose = np.empty((n, 4)), np.empty((n, 4))
        self._batch("pkm_regressor_joints", n, [self._doubles(R), self._doubles(V), self._doubles(A),
                                                self._d4(guess), self._doubles(Y), self._doubles(F0),
                                                self._doubles(pose)])
        return Y, F0, pose
