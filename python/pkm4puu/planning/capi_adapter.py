# SPDX-License-Identifier: BSD-2-Clause
"""Every call the planner makes into the C API (pkm.h), in one place: the
actuator forces and the slider positions and rates at platform poses,
velocities and accelerations for one machine and payload (forces_and_rates),
and the C API's own workspace and singularity guards on those poses
(check_poses).

Arrays are (n, 4), one row per sample: the pose (x, y, z, phi) in m and
rad, its rates in m/s and rad/s, its accelerations in m/s^2 and rad/s^2;
forces in N.
"""
import re

import numpy as np

from .. import capi

class PoseError(ValueError):
    """A pose the machine cannot take. kind: "unreachable" (a leg cannot
    reach it elbow-down), "singular" (beyond the singularity guards) or
    "end stop" (a slider beyond its travel); index: the sample; leg: 1..4
    where the C API names one; the message is the C API's."""

    def __init__(self, kind, index, message, leg=None):
        super().__init__(message)
        self.kind, self.index, self.leg = kind, index, leg


# The friction parameters a frictionless model sets to zero.
FRICTIONLESS = {"friction_viscous": 0.0, "friction_coulomb": 0.0}


def model_parameters(machine=None, params=None):
    """One dict of the model's parameters by the FMUs' names from the
    planner's two, `machine`'s value where both give one."""
    return {**(params or {}), **(machine or {})}


class InverseDynamics:
    """One model of the machine (pkm_create, then its parameters by the
    FMUs' names): `params` and `machine`, both by those names, override the
    defaults (e.g. {"g": 0.0}; screw_lead, rotor_inertia, friction_viscous,
    ...), `machine` where both give one; the payload `payload_mass` kg at P.
    ValueError naming the parameter if the C API refuses one.

    screw_lead (m) and friction (friction_viscous N s/m, friction_coulomb
    N) are read back from the model as given; `frictionless` then zeroes
    its friction (FRICTIONLESS) in the forces it computes."""

    def __init__(self, payload_mass=0.0, machine=None, params=None, build=None, frictionless=False):
        values = {**model_parameters(machine, params), "payload_mass": float(payload_mass)}
        try:
            self._plant = capi.Plant(capi.load(capi.library_path(build)), **values)
            self.screw_lead = self._plant.get("screw_lead")
            self.friction = (self._plant.get("friction_viscous"), self._plant.get("friction_coulomb"))
            if frictionless:
                self._plant.set(**FRICTIONLESS)
        except (capi.PkmError, TypeError) as e:
            raise ValueError(str(e)) from None
        self.rho_limits = (self._plant.get("rho_min"), self._plant.get("rho_max"))
        self._pi = self._plant.regressor_params()

    def close(self):
        self._plant.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def forces_and_rates(self, pose, velocity, acceleration):
        """(F, rho, drho), each (n, 4): the actuator forces that move the
        platform along the samples (payload, rotor inertia and friction
        included) and the slider positions and rates, in one call of
        pkm_regressor_poses (F = Y pi + F0 with the model's own pi: the
        inverse dynamics in its linear-in-the-parameters form)."""
        P, V, A = (np.ascontiguousarray(x, dtype=float).reshape(-1, 4) for x in (pose, velocity, acceleration))
        try:
            Y, F0, rho, drho = self._plant.regressor_poses(P, V, A)
        except capi.PkmError as e:
            raise ValueError(str(e)) from None
        return Y @ self._pi + F0, rho, drho

    def forces(self, pose, velocity, acceleration):
        """The actuator forces F (n, 4) along the samples (forces_and_rates)."""
        return self.forces_and_rates(pose, velocity, acceleration)[0]

    def check_poses(self, pose):
        """Raises PoseError at the first pose the machine cannot take: the C
        API's guards (pkm_init_pose: each leg's reach, leg and parallel
        singularities), then the sliders' travel (pkm_inverse_dynamics's
        beyond_stops)."""
        P = np.asarray(pose, dtype=float).reshape(-1, 4)
        plant = self._plant
        zero = np.zeros(4)
        for k in range(len(P)):
            try:
                plant.init_pose(0.0, P[k])
            except capi.PkmError as e:
                text = plant.ffi.string(plant.c.pkm_last_error(plant.handle)).decode()
                kind = {plant.c.PKM_ERR_UNREACHABLE: "unreachable", plant.c.PKM_ERR_SINGULAR: "singular"}.get(e.status,
                                                                                                "invalid")
                leg = re.search(r"\bleg (\d)\b", text)
                raise PoseError(kind, k, text, int(leg.group(1)) if leg else None) from None
            beyond = plant.inverse_dynamics(P[k], zero, zero).beyond_stops
            if beyond:
                bit = (beyond & -beyond).bit_length() - 1  # bit i-1: below rho_min; 3+i: above rho_max
                leg, low = bit % 4 + 1, bit < 4
                _, rho, _ = self.forces_and_rates(P[k], zero, zero)
                raise PoseError("end stop", k, f"slider {leg} at rho = {1e3 * rho[0, leg - 1]:.2f} mm, "
                                f"{'below rho_min' if low else 'above rho_max'} = "
                                f"{1e3 * self.rho_limits[0 if low else 1]:g} mm", leg)
