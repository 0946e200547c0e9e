# SPDX-License-Identifier: BSD-2-Clause
"""The outcome each fixed-step run of test_fmu_fixed_step.py must have,
derived from the parameters and the stability bound docs/solvers.md states
(nothing here is read from the code under test or its runs).

The scene: F = 0 at the home pose, 1 ms communication steps. Without
friction the machine falls freely (the symmetric drop keeps x, y, phi, and
rho_i - z constant: everything moves with z) until every slider meets
rho_min = 0 together, after rho(P0) of fall.

RK4 (docs/solvers.md "The stability bound", "The work budget"): with
m = m_slider + rotor_inertia (2 pi / screw_lead)^2 its sub-steps keep
h |lambda| <= 0.1 on the bound
    out of contact  r_free    = (b + F_c / v_s) / m
    in contact      r_contact = sqrt(k / m) + (d + b + F_c / v_s) / m.
 - more than work_budget sub-steps per rk4_step out of contact: refused at
   initialisation ("unstable at every step");
 - else, in a contact, a communication step of grid steps g gets
   work_budget H / g inner steps; the contact's part T of it needs
   T r_contact / 0.1 of them, besides one per grid step and the bisection
   that locates the impact (30 halvings take 1 ms to 1e-12 s; BISECTION
   allows twice that). More: Discard in the step of the impact ("ran out
   in an end-stop contact").
   T is what is left of the impact's step, or the whole contact if it ends
   sooner: half a period pi / omega_d of the stop against the quarter of
   the moving mass each stop holds (damping ratio zeta < 1); with zeta >= 1
   the platform stays on its stops.
ROS2 is L-stable: no step size is refused, and none of these cases is one
of the three where docs/solvers.md says it runs out of its budget.
"""
import math
from dataclasses import dataclass

from pkm4puu import spec

# docs/solvers.md: the budget's default, RK4's h |lambda| on the bound, the cap per call.
WORK_BUDGET = 1000.0
STIFF_FRACTION = 0.1
MAX_INNER_STEPS_PER_CALL = 1e5
BISECTION = 64
# A case is pinned only where the estimate is at least this far from the
# budget (the contact time of a linear oscillator, the bisection's allowance).
MARGIN = 1.25
# The free fall's impact time against the plant's located one: the plant
# locates it to 1e-12 s; a refusal may come that early before the formula's.
LOCATED = 1e-9  # s

DEFAULTS = {"m_slider": spec.M_SLIDER, "m_rod": spec.M_ROD, "m_platform": spec.M_PLATFORM, "g": spec.G,
            "friction_viscous": 0.0, "friction_coulomb": 0.0, "friction_velocity": spec.FRICTION_VELOCITY,
            "stop_stiffness": spec.STOP_STIFFNESS, "stop_damping": spec.STOP_DAMPING, "rotor_inertia": 0.0,
            "screw_lead": spec.SCREW_LEAD, "rk4_step": spec.SOLVER_DEFAULTS["rk4_step"]}


@dataclass
class Outcome:
    ok_steps: int  # communication steps answered OK
    refusal: str = ""  # "" (completes), "init" or "contact"
    rate: float = 0.0  # the bound (1/s) the refusal's message must state
    earliest: float = 0.0  # the Discard's time is at least this (s): the impact

    def __str__(self):
        if not self.refusal:
            return f"completes {self.ok_steps} steps"
        return f"refused ({self.refusal}, bound {self.rate:.4g} 1/s) after {self.ok_steps} OK steps"


def rates(p):
    """(m, r_free, r_contact) of docs/solvers.md's bound."""
    m = p["m_slider"] + p["rotor_inertia"] * (2 * math.pi / p["screw_lead"]) ** 2
    c = p["friction_viscous"] + (p["friction_coulomb"] / p["friction_velocity"] if p["friction_coulomb"] else 0.0)
    return m, c / m, math.sqrt(p["stop_stiffness"] / m) + (p["stop_damping"] + c) / m


def first_impact(p):
    """The free fall's impact time (s), or None where friction slows the fall
    (a friction bound small enough that no contact can refuse is checked
    instead, in expected())."""
    if p["friction_viscous"] or p["friction_coulomb"]:
        return None
    rho0 = spec.leg_inverse_kinematics(spec.P0)[0][0]
    return math.sqrt(2 * rho0 / p["g"])


def contact_time(p):
    """How long one stop holds its quarter of the moving mass after the
    impact (s; inf if it holds it for good)."""
    quarter = (p["m_platform"] + 4 * p["m_slider"] + 4 * p["m_rod"]) / 4
    k, d = p["stop_stiffness"], p["stop_damping"]
    if k == 0.0:
        return math.inf if d > 0 else 0.0
    omega = math.sqrt(k / quarter)
    zeta = d / (2 * math.sqrt(k * quarter))
    return math.pi / (omega * math.sqrt(1 - zeta**2)) if zeta < 1 else math.inf


def expected(params, solver, steps, h=spec.STEP):
    """The Outcome of `steps` communication steps of h from rest at P0 with
    F = 0, for `params` (FMU names over the defaults) and solver 1 or 2."""
    p = {**DEFAULTS, **params}
    if solver == 2:
        return Outcome(steps)
    _, r_free, r_contact = rates(p)
    if math.ceil(p["rk4_step"] * r_free / STIFF_FRACTION - 1e-9) > WORK_BUDGET:
        return Outcome(0, "init", r_free)
    grid = min(p["rk4_step"], h)
    budget = min(WORK_BUDGET * round(h / grid), MAX_INNER_STEPS_PER_CALL)

    def needed(seconds):  # inner steps of the impact's communication step
        return seconds * r_contact / STIFF_FRACTION + h / grid + BISECTION

    t_impact = first_impact(p)
    if t_impact is None or t_impact >= steps * h:
        # No contact known: then it must not matter, in a whole step of contact.
        assert needed(h) * MARGIN < budget, f"{params}: the outcome depends on contact the test does not derive"
        return Outcome(steps)
    k = math.floor(t_impact / h)
    first = needed(min(contact_time(p), (k + 1) * h - t_impact))
    worst = needed(min(contact_time(p), h))
    if first > MARGIN * budget:
        return Outcome(k, "contact", r_contact, t_impact - LOCATED)
    assert worst * MARGIN < budget, f"{params}: {worst:.0f} inner steps against a budget of {budget:.0f}: too close"
    return Outcome(steps)


def expected_long_step(params, solver, span):
    """"OK", or the reason a Discard's message names, for one doStep of `span`
    from rest at P0 with F = 0 (docs/solvers.md "The work budget"), and the
    earliest time it may stop. The fixed-step solvers' grid has span /
    rk4_step steps, each needing one inner step at least; the budget is
    work_budget per grid step, at most MAX_INNER_STEPS_PER_CALL:
     - a grid at the cap has nothing left for the bisection that locates
       the impact: Discard in the impact's grid step;
     - else RK4 needs what expected() derives in the contact, ROS2 (L-stable)
       one step per grid step resting on the stops, at most work_budget in
       the impact's.
    CVODE: the platform rests on the stops after the impact, a constant
    solution, over which BDF's steps grow tenfold per step (CVODE's largest
    step ratio): a few hundred evaluations, far below its cap."""
    p = {**DEFAULTS, **params}
    if solver == 0:
        return "OK", 0.0
    t_impact = first_impact(p)
    grid_steps = span / p["rk4_step"]
    budget = min(WORK_BUDGET * grid_steps, MAX_INNER_STEPS_PER_CALL)
    start_of_impact_step = math.floor(t_impact / p["rk4_step"]) * p["rk4_step"]
    if grid_steps >= MAX_INNER_STEPS_PER_CALL:
        return "locating contact events by bisection" if solver == 1 else "the last Rosenbrock step", \
            start_of_impact_step
    if solver == 2:
        assert (grid_steps + WORK_BUDGET) * MARGIN < budget
        return "OK", 0.0
    _, _, r_contact = rates(p)
    assert (min(contact_time(p), span - t_impact) * r_contact / STIFF_FRACTION > MARGIN * budget)
    return "in an end-stop contact", t_impact - LOCATED
