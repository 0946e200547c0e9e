# SPDX-License-Identifier: BSD-2-Clause
"""Time-optimal pick-and-place with real drives: the standard cycle
(docs/pick_and_place.md) planned by pkm4puu.plan_cycle for the spec's
limits (|F_i| <= 10 N, |drho_i/dt| <= 0.5 m/s, an ideal machine), then for
the machine of drive_sizing.py: its motors' rotor inertia (reflected through
the 4 mm ball screw as 1.48 kg per slider), the joints' friction, and the
illustrative motor's peak torque and corner speed as the limits, so that
every operating point stays in the motor's constant-torque region.

Friction (Coulomb 0.5 N, viscous 2 N s/m) is not of the planner's form
F = a sdd + b sd^2 + c, so the plan keeps the friction-free forces within
the limit less |F_fric| <= b v_lim + F_c, and the forces with friction are
then recomputed from the C API along the plan; this example prints how
much of the limit that leaves unused.

Writes to --out DIR:
  pick_and_place.csv   per cycle (spec, drives) and sample: t, motor torques
                       tau_i (N m) and speeds omega_i (rad/s)
  pick_and_place.png   each plan's torques against time, and the drives'
                       operating points in the motor's torque-speed envelope

usage: pick_and_place.py [--build DIR] [--out DIR] [--payload KG]
"""
import argparse
import csv
import importlib.util
import math
import sys
from pathlib import Path

import matplotlib
import numpy as np

import pkm4puu
from pkm4puu.program import add_common_args, run_program
from pkm4puu.plots import save_figure

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _drive_sizing():
    """examples/drive_sizing.py, whose machine and motor this example plans for."""
    if "drive_sizing" not in sys.modules:
        spec = importlib.util.spec_from_file_location("drive_sizing", Path(__file__).with_name("drive_sizing.py"))
        module = importlib.util.module_from_spec(spec)
        sys.modules["drive_sizing"] = module
        spec.loader.exec_module(module)
    return sys.modules["drive_sizing"]


DRIVE_FIELDS = ("screw_lead", "rotor_inertia", "friction_viscous", "friction_coulomb", "friction_velocity")


def drives():
    """(machine, motor): drive_sizing.py's drives and friction (its payload
    left out: the cycle sets its own), and its motor."""
    ds = _drive_sizing()
    return {k: ds.MACHINE[k] for k in DRIVE_FIELDS}, ds.MOTOR


def plan_with_drives(payload, build=None):
    """The standard cycle for the machine with drives, limited by the motor's
    peak torque and corner speed (f_max and v_max set out of the way)."""
    machine, motor = drives()
    return pkm4puu.plan_cycle(payload, f_max=1e3, v_max=1e3, torque_max=motor.peak_torque,
                              motor_speed_max=motor.corner_speed, machine=machine, build=build)


def motor_use(cycle, motor):
    """Per segment: (torques tau (n, 4), speeds omega (n, 4), the largest
    |tau| / the motor's torque limit at that speed)."""
    lead = drives()[0]["screw_lead"]
    out = []
    for seg in cycle.segments:
        tau, omega = seg.F * lead / (2 * math.pi), seg.drho * 2 * math.pi / lead
        out.append((tau, omega, float(np.max(np.abs(tau) / motor.torque_limit(omega)))))
    return out


def report(ideal, real, motor):
    lines = ["the spec's limits, ideal machine:"] + ["  " + line for line in ideal.summary()[1:]]
    lines += [f"the machine of drive_sizing.py ({motor.name}):"] + ["  " + line for line in real.summary()[1:]]
    for seg, (_, _, use) in zip(real.segments, motor_use(real, motor)):
        lines.append(f"  {seg.name}: friction bound {seg.friction_bound:.2f} N taken off the force limit; with "
                     f"friction the peak |F| is {100 * seg.excess()[0]:.2f} % of it; peak |tau| / motor envelope "
                     f"{use:.3f}")
    lines.append(f"cycle time with the drives / with the spec's limits: {real.duration / ideal.duration:.3f}")
    return "\n".join(lines)


def write_csv(cycles, path, lead):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["cycle", "t_s"] + [f"tau{i}_Nm" for i in range(1, 5)] + [f"omega{i}_rad_s" for i in range(1, 5)])
        for name, cycle in cycles:
            t0 = 0.0
            for seg in cycle.segments:
                tau, omega = seg.F * lead / (2 * math.pi), seg.drho * 2 * math.pi / lead
                for k, tk in enumerate(seg.t):
                    w.writerow([name, f"{t0 + tk:.6f}"] + [f"{v:.9e}" for v in tau[k]] + [f"{v:.9e}" for v in omega[k]])
                t0 += seg.duration


def plot(ideal, real, motor, path, lead):
    fig, (ax_t, ax_e) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [1.3, 1]})
    for j, (name, cycle, style) in enumerate((("spec's limits", ideal, ":"), ("drives", real, "-"))):
        t0 = 0.0
        for seg in cycle.segments:
            for i in range(4):
                ax_t.plot(1e3 * (t0 + seg.t), 1e3 * seg.F[:, i] * lead / (2 * math.pi), f"C{i}{style}", lw=1.2,
                          label=f"motor {i + 1} ({name})" if t0 == 0.0 else None)
            t0 += seg.duration
    for sign in (1, -1):
        ax_t.axhline(sign * 1e3 * motor.peak_torque, color="k", ls="--", lw=1)
    ax_t.set_xlabel("t (ms)")
    ax_t.set_ylabel(r"motor torque $\tau_i = F_i p / 2\pi$ (mN m)")
    ax_t.set_title(f"the standard cycle: {ideal.duration:.3f} s with the spec's limits (dotted), "
                   f"{real.duration:.3f} s with the drives (solid)", fontsize=9)
    ax_t.legend(fontsize=6.5, ncol=2)
    ax_t.grid(True, alpha=0.3)
    w, tau = motor.envelope()
    ax_e.fill(w, 1e3 * tau, color="0.92", zorder=0)
    ax_e.plot(w, 1e3 * tau, "k-", lw=1.0, label="motor envelope")
    for tau_s, omega_s, _ in motor_use(real, motor):
        for i in range(4):
            ax_e.plot(omega_s[:, i], 1e3 * tau_s[:, i], f"C{i}", lw=1.0)
    ax_e.axvline(motor.corner_speed, color="0.5", ls=":", lw=1)
    ax_e.axvline(-motor.corner_speed, color="0.5", ls=":", lw=1)
    ax_e.set_xlabel(r"motor speed $\omega_i$ (rad/s)")
    ax_e.set_ylabel(r"$\tau_i$ (mN m)")
    ax_e.set_title("the drives' plan in the torque-speed plane (corner speed dotted)", fontsize=9)
    ax_e.grid(True, alpha=0.3)
    ax_e.legend(fontsize=7)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="pick_and_place", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "pick_and_place.csv and pick_and_place.png")
    ap.add_argument("--payload", type=float, default=pkm4puu.spec.CYCLE_PAYLOAD,
                    help="mass carried from A to B, kg (default %(default)g)")

    def compute(args, _fmus, log):
        log("planning the standard cycle with the spec's limits")
        ideal = pkm4puu.plan_cycle(args.payload, build=args.build)
        log("planning it for the machine with drives")
        real = plan_with_drives(args.payload, args.build)
        machine, motor = drives()
        lead = machine["screw_lead"]
        cycles = [("spec", ideal), ("drives", real)]
        return report(ideal, real, motor), {"pick_and_place.csv": lambda p: write_csv(cycles, p, lead),
                                            "pick_and_place.png": lambda p: plot(ideal, real, motor, p, lead)}

    return run_program(ap, argv, compute, lambda a: "--payload must be finite and >= 0"
                       if not (math.isfinite(a.payload) and a.payload >= 0) else None, models=())


if __name__ == "__main__":
    sys.exit(main())
