# SPDX-License-Identifier: BSD-2-Clause
"""The plant FMU in a control loop: a 1 kHz joint-space controller drives
PKM4PUU.fmu along the spec's auto-test motion (2 s, P0 -> P1) while the plant
is the machine, not the ideal mechanism: each prismatic joint has viscous and
Coulomb friction, and the platform carries an off-centre payload
(docs/model.md "The machine around the mechanism").

Every 1 ms, at t_k, the controller
  1. reads the plant's actuator positions and rates rho(t_k), drho(t_k)
     (its outputs, the sensors);
  2. asks the inverse FMU (PKM4PUU_Inverse.fmu) for the motion at t_k: the
     desired rho_d, drho_d and the computed-force feed-forward F_ff;
  3. applies, per actuator, held over [t_k, t_k + 1 ms] (zero-order hold),
         F = F_ff + Kp (rho_d - rho) + Kd (drho_d - drho)      (PD + feed-forward)
     or  F =        Kp (rho_d - rho) + Kd (drho_d - drho)      (PD only)
     and steps the plant by 1 ms.

Three controllers, on the same plant:
  "ff"         feed-forward from an inverse FMU given the plant's machine
               parameters (friction and payload): its F_ff includes the
               friction along the desired motion, friction compensation;
  "ff_nofric"  feed-forward from an inverse FMU that knows the payload but
               not the friction (friction parameters at their defaults, 0);
  "pd"         PD only, no model at all.

The PD carries whatever the feed-forward leaves out, through a position
error ~ dF / Kp: without friction compensation that is the friction,
F_c tanh(drho / v_s) + b drho, ~F_c = 0.3 N per moving joint, 0.12 mm; PD
alone also carries the weight, ~3 N per joint, ~1.2 mm. With compensation
only the zero-order hold's lag is left (F_ff changes by at most a few mN per
1 ms step): well under a micrometre.

Writes to --out DIR:
  closed_loop.csv            per time: rho errors, pose errors and forces of the three runs
  closed_loop_tracking.png   tracking error with and without friction compensation
  closed_loop_run.csv        the compensated run in render_robot.py's format

usage: closed_loop_control.py [--build DIR] [--out DIR] [--payload KG] [--coulomb N]
                              [--viscous NS_PER_M] [--t-end S]
"""
import argparse
import csv
import math
import sys

import matplotlib
import numpy as np

from pkm4puu.program import add_common_args, run_program
from pkm4puu.closed_loop import run_closed_loop
from pkm4puu.plots import save_figure
from pkm4puu.drawing import write_run_csv
from pkm4puu.interface import RK4, START_P0
from pkm4puu.spec import STEP as H, T_MOVE

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# --- gains ------------------------------------------------------------------------------
# Effective mass seen by one actuator: its slider (0.093 kg), about half of its
# rod (0.064 kg) and a quarter of the platform plus payload ((0.455 + 0.1)/4 kg),
# so m_eff ~ 0.3 kg. A closed-loop bandwidth of f_c = 15 Hz (omega = 94 rad/s,
# a tenth of the 1 kHz sampling rate: omega h = 0.094, so the zero-order hold's
# phase lag of omega h / 2 = 2.7 deg is negligible) and critical damping
# (zeta = 1) give
#   Kp = m_eff omega^2       = 0.3 * 94.2^2   ~ 2660 N/m   -> 2500 N/m
#   Kd = 2 zeta m_eff omega  = 2 * 0.3 * 94.2 ~   57 N s/m ->   55 N s/m
# (discrete check: Kd h / m_eff = 0.18 and Kp h^2 / m_eff = 0.008, far inside
# the stability limits of the sampled loop). With these, an unmodelled force dF
# leaves a static position error dF / Kp: 1 mm per 2.5 N.
KP = 2500.0  # N/m
KD = 55.0  # N s/m
T_END = 2.5  # s: the 2-s motion, then 0.5 s at rest at P1

# --- the machine --------------------------------------------------------------------------
# Friction of a small preloaded linear guide plus screw nut: Coulomb F_c =
# 0.3 N per joint (11 % of the 2.66 N each slider holds up), viscous b =
# 2 N s/m (0.07 N at the auto-test's fastest slider, 0.033 m/s), regularised
# over v_s = 1 mm/s (the spec's default, 3 % of that speed). A 100 g payload
# (22 % of the platform's 0.455 kg), a 40 mm x 40 mm block whose centre sits
# at (10, -5) mm from P: Izz = m (a^2 + b^2) / 12.
COULOMB = 0.3  # N
VISCOUS = 2.0  # N s/m
V_S = 1e-3  # m/s
PAYLOAD = 0.1  # kg
PAYLOAD_COM = (0.010, -0.005)  # m, in the platform frame relative to P
PAYLOAD_SIDE = 0.040  # m: the block's side, for its Izz

# What test_examples_control.py requires of the RMS error ratio (without /
# with friction compensation). Without compensation the PD carries the
# friction, ~F_c = 0.3 N on every moving joint (2 s of the 2.5 s run), an error
# ~F_c / Kp; with it, only the zero-order hold's lag, at most the largest
# change of F_ff over one step (<= 4 mN here, largest where the tanh turns over
# as a slider starts), / Kp. 0.3 N / 4 mN = 75, times sqrt(2 / 2.5) for the
# quiet end: ~67; asked for 50.
MIN_RATIO = 50.0

MODES = ("ff", "ff_nofric", "pd")
LABELS = {"ff": "PD + feed-forward with friction compensation",
          "ff_nofric": "PD + feed-forward without friction model",
          "pd": "PD only"}


def machine(payload=PAYLOAD, coulomb=COULOMB, viscous=VISCOUS):
    """The plant's machine parameters (FMU names): friction and payload."""
    a = PAYLOAD_SIDE
    return {"friction_viscous": viscous, "friction_coulomb": coulomb, "friction_velocity": V_S,
            "payload_mass": payload, "payload_com[1]": PAYLOAD_COM[0], "payload_com[2]": PAYLOAD_COM[1],
            "payload_Izz": payload * (a * a + a * a) / 12.0}


def without_friction(params):
    """The same machine as the inverse FMU sees it without a friction model."""
    return {k: v for k, v in params.items() if not k.startswith("friction_")}


def friction(params, drho):
    """The spec's joint friction opposing drho, as the force the actuator must
    add: b drho + F_c tanh(drho / v_s) (N)."""
    return (params["friction_viscous"] * drho
            + params["friction_coulomb"] * np.tanh(drho / params["friction_velocity"]))


def run_loop(plant_fmu, inverse_fmu, plant_machine=None, model=None, feed_forward=True, kp=KP, kd=KD,
             t_end=T_END, T=T_MOVE, h=H, log=None):
    """One closed-loop run of t_end seconds at period h (see the module's doc).
    plant_machine: the plant's machine parameters (default machine());
    model: the inverse FMU's (default: the plant's; without_friction(...) for
    no friction compensation). With feed_forward=False the inverse FMU only
    gives rho_d, drho_d (which do not depend on the masses or the friction)."""
    plant_machine = machine() if plant_machine is None else plant_machine
    model = plant_machine if model is None else model

    def pd(r, k, F_ref):
        F_ff = F_ref if feed_forward else 0.0
        return F_ff, F_ff + kp * (r.rho_d[k] - r.rho[k]) + kd * (r.drho_d[k] - r.drho[k])

    def progress(r, k):
        return f"|rho_d - rho| = {1e3 * np.abs(r.rho_d[k] - r.rho[k]).max():.6f} mm"

    return run_closed_loop(plant_fmu, inverse_fmu, {**START_P0, **RK4, **plant_machine}, model, pd, progress,
                           t_end, T, h, log)


def compare(plant_fmu, inverse_fmu, plant_machine=None, t_end=T_END, log=None):
    """The three controllers on the same plant: ({mode: LoopResult}, RMS ratio
    without / with friction compensation)."""
    plant_machine = machine() if plant_machine is None else plant_machine
    models = {"ff": (plant_machine, True), "ff_nofric": (without_friction(plant_machine), True),
              "pd": ({}, False)}
    runs = {}
    for mode in MODES:
        if log:
            log(f"{LABELS[mode]}: {t_end:g} s at {1 / H:g} Hz")
        model, ff = models[mode]
        runs[mode] = run_loop(plant_fmu, inverse_fmu, plant_machine, model, feed_forward=ff, t_end=t_end, log=log)
    return runs, runs["ff_nofric"].rms / runs["ff"].rms


def describe(params):
    return (f"friction F_c = {params['friction_coulomb']:g} N, b = {params['friction_viscous']:g} N s/m, "
            f"v_s = {1e3 * params['friction_velocity']:g} mm/s; payload {1e3 * params['payload_mass']:g} g at "
            f"({1e3 * params['payload_com[1]']:g}, {1e3 * params['payload_com[2]']:g}) mm")


def summary(runs, ratio, params):
    lines = [f"closed loop, 1 kHz, Kp = {KP:g} N/m, Kd = {KD:g} N s/m; plant: {describe(params)}",
             f"{'':<46} {'RMS rho error':>14} {'max rho error':>14} {'max |p - p_d|':>14} {'max phi error':>14}"]
    for mode in MODES:
        r = runs[mode]
        lines.append(f"{LABELS[mode]:<46} {1e3 * r.rms:11.6f} mm {1e3 * np.abs(r.e_rho).max():11.6f} mm "
                     f"{1e3 * r.pos_err.max():11.6f} mm {math.degrees(r.phi_err.max()):11.6f} deg")
    lines.append(f"RMS error ratio (without / with friction compensation): {ratio:.1f}")
    return "\n".join(lines)


def write_csv(runs, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        head = ["t_s"]
        for tag in MODES:
            head += [f"{tag}_e_rho{i}_m" for i in range(1, 5)] + [f"{tag}_pos_err_m", f"{tag}_phi_err_rad"]
            head += [f"{tag}_F{i}_N" for i in range(1, 5)]
        head += [f"F_ff{i}_N" for i in range(1, 5)] + [f"F_ff_nofric{i}_N" for i in range(1, 5)]
        w.writerow(head)
        for k, tk in enumerate(runs["ff"].t):
            row = [f"{tk:.6f}"]
            for mode in MODES:
                r = runs[mode]
                row += [f"{v:.6e}" for v in r.e_rho[k]] + [f"{r.pos_err[k]:.6e}", f"{r.phi_err[k]:.6e}"]
                row += [f"{v:.9f}" for v in r.F[k]]
            row += [f"{v:.9f}" for v in runs["ff"].F_ff[k]] + [f"{v:.9f}" for v in runs["ff_nofric"].F_ff[k]]
            w.writerow(row)


def plot(runs, ratio, params, path):
    fig, axes = plt.subplots(3, 1, figsize=(8.5, 9.5), sharex=True,
                             gridspec_kw={"height_ratios": [1.2, 1, 1]})
    ff, nofric, pd = (runs[m] for m in MODES)
    t = ff.t
    for r, style, mode in ((pd, "k:", "pd"), (nofric, "C1--", "ff_nofric"), (ff, "C0-", "ff")):
        axes[0].semilogy(t, 1e3 * np.maximum(np.abs(r.e_rho).max(axis=1), 1e-12), style, lw=1.4,
                         label=f"{LABELS[mode]} (RMS {1e3 * r.rms:.3g} mm)")
    axes[0].set_ylim(1e-6, 5)
    axes[0].set_ylabel(r"$\max_i |\rho_{d,i} - \rho_i|$ (mm)")
    axes[0].legend(fontsize=7, loc="lower center")
    axes[0].set_title(f"1 kHz joint-space PD (Kp = {KP:g} N/m, Kd = {KD:g} N s/m) along the auto-test\n"
                      f"plant: {describe(params)}\n"
                      f"friction compensation cuts the RMS actuator error {ratio:.0f}-fold", fontsize=8.5)
    for i in range(4):
        axes[1].plot(t, 1e3 * nofric.e_rho[:, i], f"C{i}-", lw=1.4, label=f"leg {i + 1}")
        axes[1].plot(t, 1e3 * friction(params, nofric.drho_d[:, i]) / KP, f"C{i}:", lw=1.0)
    axes[1].plot(t, 1e3 * nofric.e_rho.sum(axis=1) / 4, "k-", lw=1.0, label="mean of the 4")
    axes[1].plot(t, 1e3 * friction(params, nofric.drho_d).sum(axis=1) / 4 / KP, "k:", lw=1.0)
    axes[1].set_ylabel(r"$\rho_{d,i} - \rho_i$ (mm)")
    axes[1].set_title("without friction model: solid the error, dotted the friction along the desired motion / Kp\n"
                      "(the legs share the load through the mechanism; their mean follows the mean friction)",
                      fontsize=8)
    axes[1].legend(fontsize=7, ncol=5, loc="lower left")
    for i in range(4):
        axes[2].plot(t, ff.F_ff[:, i] - nofric.F_ff[:, i], f"C{i}-", lw=1.4, label=f"leg {i + 1}")
    axes[2].set_ylabel("friction compensation (N)")
    axes[2].set_title(r"$F_{ff}$ with the friction parameters minus $F_{ff}$ without", fontsize=8)
    axes[2].set_xlabel("time (s)")
    axes[2].legend(fontsize=7, ncol=4, loc="lower left")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.axvline(T_MOVE, color="grey", lw=0.8)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="closed_loop_control", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "closed_loop.csv, closed_loop_tracking.png and closed_loop_run.csv")
    ap.add_argument("--payload", type=float, default=PAYLOAD,
                    help="payload on the platform, known to both feed-forwards (kg, default %(default)s)")
    ap.add_argument("--coulomb", type=float, default=COULOMB,
                    help="Coulomb friction of each joint (N, default %(default)s)")
    ap.add_argument("--viscous", type=float, default=VISCOUS,
                    help="viscous friction of each joint (N s/m, default %(default)s)")
    ap.add_argument("--t-end", type=float, default=T_END, help="run length (s, default %(default)s)")

    def compute(args, fmus, log):
        params = machine(args.payload, args.coulomb, args.viscous)
        runs, ratio = compare(*fmus, plant_machine=params, t_end=args.t_end, log=log)
        if ratio < MIN_RATIO:
            log(f"note: friction compensation cut the RMS error by {ratio:.1f}, less than the {MIN_RATIO:g} the "
                "test requires with the default machine")
        return summary(runs, ratio, params), {
            "closed_loop.csv": lambda p: write_csv(runs, p),
            "closed_loop_tracking.png": lambda p: plot(runs, ratio, params, p),
            "closed_loop_run.csv": lambda p: write_run_csv(p, runs["ff"].t, runs["ff"].run)}

    def invalid(args):
        if min(args.payload, args.coulomb, args.viscous) < 0 or args.t_end <= 0:
            return "--payload, --coulomb and --viscous must be >= 0 and --t-end > 0"
        return None

    return run_program(ap, argv, compute, invalid)


if __name__ == "__main__":
    sys.exit(main())
