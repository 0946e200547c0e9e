# SPDX-License-Identifier: BSD-2-Clause
"""Drive sizing from the inverse FMU: along the spec's auto-test (P0 -> P1,
rest to rest) with a realistic machine, each motor's torque tau_i(t) and
speed omega_i = 2 pi drho_i / p, drawn as operating points in the
torque-speed plane beside a motor's limits, with the RMS torque against the
rated torque.

PKM4PUU_Inverse.fmu, given the machine's parameters (docs/model.md "The machine
around the mechanism"), reports besides F[1..4] the motor torques
tau[1..4] = F_i p / (2 pi) that include gravity, the mechanism's dynamics,
the rotors' inertia J (reflected mass J (2 pi / p)^2 per slider), the
joint friction and the payload. The move is done in the paper's 2 s and,
for comparison, 4 times faster (0.5 s: speeds x4, accelerations x16).

The motor is illustrative, not a datasheet: a small brushless servo of the
right size for a robot whose sliders each hold ~3 N, with
  rated (continuous) torque  5 mN m,
  peak torque               15 mN m up to the corner speed 3000 rpm (314 rad/s),
  constant power above it   (tau <= tau_peak omega_corner / omega, 4.7 W),
  maximum speed             6000 rpm (628 rad/s).

Writes to --out DIR:
  drive_sizing.csv   per time and duration: tau_i (N m) and omega_i (rad/s)
  drive_sizing.png   torque against speed, the motor's envelope, tau(t)

usage: drive_sizing.py [--build DIR] [--out DIR] [--durations S [S ...]]
"""
import argparse
import csv
import math
import sys
from dataclasses import dataclass

import matplotlib
import numpy as np

from pkm4puu.program import add_common_args, run_program
from pkm4puu.plots import save_figure
from pkm4puu.fmu import Fmu
from pkm4puu.interface import ACC, indexed_names, DRHO, F, POSE, RHO, VEL
from pkm4puu.motions import motion
from pkm4puu.spec import STEP as H, T_MOVE

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TAU = indexed_names("tau", 4)

# --- the machine ---------------------------------------------------------------------------
# Lead 4 mm (the spec's default; an 8 mm x 4 mm mini ball screw). Rotor
# inertia per axis J = 6e-7 kg m^2: a 22 mm-class brushless motor's rotor
# (~1e-7) plus the steel screw, 8 mm x 150 mm (pi rho L d^4 / 32 = 4.7e-7),
# the coupling neglected; reflected through the screw that is
# J (2 pi / p)^2 = 1.48 kg per slider, 16 times the slider's 0.093 kg.
# Friction per joint: Coulomb 0.5 N (a preloaded ball nut's ~0.2 mN m drag
# torque is 0.3 N on the slider, plus the guide's seals), viscous 2 N s/m,
# regularised over the spec's default 1 mm/s. Payload: 0.2 kg at (20, -15) mm
# from P, Izz 1.5e-4 kg m^2 (the case the engine checks use).
MACHINE = {
    "screw_lead": 0.004, "rotor_inertia": 6e-7,
    "friction_viscous": 2.0, "friction_coulomb": 0.5, "friction_velocity": 1e-3,
    "payload_mass": 0.2, "payload_com[1]": 0.020, "payload_com[2]": -0.015, "payload_Izz": 1.5e-4,
}
DURATIONS = (T_MOVE, T_MOVE / 4)  # s: the paper's auto-test, and the same path 4 x faster


@dataclass(frozen=True)
class Motor:
    """A torque-speed envelope: peak torque up to the corner speed, constant
    power above it up to the maximum speed; the rated torque is the
    continuous (thermal, RMS) limit."""
    rated_torque: float = 5e-3  # N m
    peak_torque: float = 15e-3  # N m
    corner_speed: float = 3000 * 2 * math.pi / 60  # rad/s
    max_speed: float = 6000 * 2 * math.pi / 60  # rad/s
    name: str = "illustrative small servo (not a datasheet)"

    def torque_limit(self, omega):
        """Largest |tau| the motor gives at speed |omega| (N m), 0 beyond max_speed."""
        w = np.abs(np.asarray(omega, dtype=float))
        lim = np.where(w <= self.corner_speed, self.peak_torque,
                       self.peak_torque * self.corner_speed / np.maximum(w, 1e-300))
        return np.where(w <= self.max_speed, lim, 0.0)

    def envelope(self, n=200):
        """The envelope as a closed polyline (omega, tau) over all four quadrants."""
        w = np.linspace(-self.max_speed, self.max_speed, 2 * n + 1)
        top = self.torque_limit(w)
        top[[0, -1]] = self.torque_limit(w[[1, -2]])  # the vertical edges at +-max_speed
        return np.concatenate([w, w[::-1], w[:1]]), np.concatenate([top, -top[::-1], top[:1]])


MOTOR = Motor()


@dataclass
class DriveProfile:
    """The inverse FMU along the move of duration T (sampled every h): times
    t (n,), forces F, torques tau, actuator positions rho and rates drho (n, 4)."""
    T: float
    t: np.ndarray
    F: np.ndarray
    tau: np.ndarray
    rho: np.ndarray
    drho: np.ndarray
    lead: float

    @property
    def omega(self):
        """Motor speeds 2 pi drho / p (rad/s)."""
        return 2 * math.pi * self.drho / self.lead

    @property
    def peak(self):
        return np.abs(self.tau).max(axis=0)

    @property
    def rms(self):
        """RMS torque over the move, per motor (N m): the trapezoidal mean of tau^2."""
        return np.sqrt(np.trapezoid(self.tau ** 2, self.t, axis=0) / (self.t[-1] - self.t[0]))

    @property
    def max_speed(self):
        return np.abs(self.omega).max(axis=0)


def drive_profile(inverse_fmu, machine=None, T=T_MOVE, h=H):
    """Sample the inverse FMU, given `machine`, along the auto-test's path done in T seconds."""
    machine = MACHINE if machine is None else machine
    t = np.linspace(0.0, T, round(T / h) + 1)
    out = np.empty((len(t), 16))
    with Fmu(inverse_fmu, start=machine, instance_name="drive_sizing") as inv:
        vr_in, vr_out = inv.vrs(POSE + VEL + ACC), inv.vrs(F + TAU + RHO + DRHO)
        for k, tk in enumerate(t):
            inv.fmu.setReal(vr_in, motion(tk, T))
            out[k] = inv.fmu.getReal(vr_out)
    lead = machine.get("screw_lead", 0.004)
    return DriveProfile(T, t, out[:, :4], out[:, 4:8], out[:, 8:12], out[:, 12:16], lead)


def table(profiles, motor=MOTOR):
    lines = [f"motor: {motor.name}: rated {1e3 * motor.rated_torque:g} mN m, peak {1e3 * motor.peak_torque:g} mN m "
             f"to {motor.corner_speed * 60 / (2 * math.pi):.0f} rpm, max {motor.max_speed * 60 / (2 * math.pi):.0f} rpm",
             f"{'move':>6} {'motor':>5} {'peak |tau|':>12} {'RMS tau':>12} {'RMS / rated':>11} "
             f"{'max |omega|':>12} {'max speed':>10} {'peak / limit':>12}"]
    for pr in profiles:
        use = np.abs(pr.tau) / motor.torque_limit(pr.omega)
        for i in range(4):
            lines.append(f"{pr.T:5.2f}s {i + 1:>5} {1e3 * pr.peak[i]:7.3f} mN m {1e3 * pr.rms[i]:7.3f} mN m "
                         f"{pr.rms[i] / motor.rated_torque:11.2f} {pr.max_speed[i]:6.1f} rad/s "
                         f"{pr.max_speed[i] * 60 / (2 * math.pi):6.0f} rpm {use[:, i].max():12.2f}")
    return "\n".join(lines)


def write_csv(profiles, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["T_s", "t_s"] + [f"tau{i}_Nm" for i in range(1, 5)] + [f"omega{i}_rad_s" for i in range(1, 5)])
        for pr in profiles:
            for k, tk in enumerate(pr.t):
                w.writerow([f"{pr.T:g}", f"{tk:.6f}"] + [f"{v:.9e}" for v in pr.tau[k]]
                           + [f"{v:.9e}" for v in pr.omega[k]])


def plot(profiles, path, motor=MOTOR, machine=None):
    machine = MACHINE if machine is None else machine
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5.2), gridspec_kw={"width_ratios": [1.25, 1]})
    w, tau = motor.envelope()
    ax.fill(w, 1e3 * tau, color="0.92", zorder=0)
    ax.plot(w, 1e3 * tau, "k-", lw=1.2, label="peak torque / constant power / max speed")
    ax.axhline(1e3 * motor.rated_torque, color="k", ls="--", lw=1.0, label="rated (continuous) torque")
    styles = ("-", ":")
    for j, pr in enumerate(profiles):
        for i in range(4):
            lab = f"motor {i + 1}" if j == 0 else None
            ax.plot(pr.omega[:, i], 1e3 * pr.tau[:, i], f"C{i}{styles[j % 2]}", lw=1.5, label=lab)
            k = np.argmax(np.abs(pr.omega[:, i]))
            ax.plot(pr.omega[k, i], 1e3 * pr.rms[i], f"C{i}o" if j == 0 else f"C{i}s", ms=5, mfc="none")
    ax.axhline(-1e3 * motor.rated_torque, color="k", ls="--", lw=1.0)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.axvline(0.0, color="k", lw=0.5)
    ax.set_xlabel(r"motor speed $\omega_i = 2\pi\dot\rho_i/p$ (rad/s)")
    ax.set_ylabel(r"motor torque $\tau_i$ (mN m)")
    ax.set_xlim(-1.05 * motor.max_speed, 1.05 * motor.max_speed)
    ax.set_ylim(-0.4e3 * motor.peak_torque, 1.1e3 * motor.peak_torque)
    durs = " and ".join(f"{pr.T:g} s ({'solid' if j % 2 == 0 else 'dotted'})" for j, pr in enumerate(profiles))
    ax.set_title(f"operating points over the auto-test done in {durs}\n"
                 f"markers: RMS torque at the motor's top speed; envelope: {motor.name}", fontsize=8.5)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(True, alpha=0.3)
    for j, pr in enumerate(profiles):
        for i in range(4):
            ax2.plot(pr.t / pr.T, 1e3 * pr.tau[:, i], f"C{i}{styles[j % 2]}", lw=1.4,
                     label=f"motor {i + 1}" if j == 0 else None)
    ax2.axhline(1e3 * motor.rated_torque, color="k", ls="--", lw=1.0)
    ax2.set_xlabel("t / T (move time T as on the left)")
    ax2.set_ylabel(r"$\tau_i$ (mN m)")
    ax2.set_title(f"p = {1e3 * machine['screw_lead']:g} mm, J = {machine['rotor_inertia']:g} kg m², "
                  f"F_c = {machine['friction_coulomb']:g} N, b = {machine['friction_viscous']:g} N s/m,\n"
                  f"payload {machine['payload_mass']:g} kg at ({1e3 * machine['payload_com[1]']:g}, "
                  f"{1e3 * machine['payload_com[2]']:g}) mm; at rest each motor holds the weight", fontsize=8.5)
    ax2.legend(fontsize=7)
    ax2.grid(True, alpha=0.3)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="drive_sizing", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "drive_sizing.csv and drive_sizing.png")
    ap.add_argument("--durations", type=float, nargs="+", default=list(DURATIONS),
                    help="move times T of the auto-test's path (s, default %(default)s)")

    def compute(args, fmus, log):
        profiles = []
        for T in args.durations:
            log(f"inverse dynamics along the auto-test in {T:g} s")
            profiles.append(drive_profile(fmus[1], T=T))
        return table(profiles), {"drive_sizing.csv": lambda p: write_csv(profiles, p),
                                 "drive_sizing.png": lambda p: plot(profiles, p)}

    return run_program(ap, argv, compute, lambda args: "--durations must be > 0" if min(args.durations) <= 0 else None)


if __name__ == "__main__":
    sys.exit(main())
