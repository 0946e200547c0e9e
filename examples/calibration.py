# SPDX-License-Identifier: BSD-2-Clause
"""Calibration of the plant to a machine, the loop closed with the FMUs: a
"true" machine whose masses and inertias differ from the spec's by 25-40 %,
with rotors, friction and a payload, is driven by the plant FMU along an
optimised excitation trajectory; its drive log (forces with 1 % noise,
slider positions quantised to 1 um) is identified (pkm4puu.identify); the
identified parameters are then checked on a different trajectory against
the spec's (docs/calibration.md).

Steps:
  1. the excitation: a 5-harmonic Fourier series per axis (period 2.5 s),
     optimised for the condition number of the stacked base regressor within
     the workspace, the end stops and the drives' limits;
  2. the drive log: the inverse FMU with the true parameters as feed-forward
     plus a PD on the sliders drives the plant FMU with the true parameters
     for two periods (5 s at 1 kHz); noise and quantisation added;
  3. identification: base parameters with standard deviations, FMU start
     values;
  4. validation on a random Fourier trajectory (period 3 s): the inverse FMU
     with the identified and with the nominal (spec) parameters predicts the
     logged forces; the plant FMU with each replays the logged forces
     (low-passed as the identification does) from the logged start, open
     loop, and its sliders are compared with the logged ones.

Writes to --out DIR:
  calibration.png          measured against predicted forces on the
                           validation trajectory, nominal and identified
  calibration_start.json   the identified FMU start values

usage: calibration.py [--build DIR] [--out DIR] [--seed N]
"""
import argparse
import json
import sys
from dataclasses import dataclass

import matplotlib
import numpy as np

from pkm4puu import capi
from pkm4puu.calibration import identify, optimise_excitation, random_trajectory
from pkm4puu.calibration.drive_log import DriveLog, feedforward, replay, simulate_drive_log
from pkm4puu.calibration.identification import filtered_derivatives
from pkm4puu.calibration.parameters import make_plant
from pkm4puu.program import add_common_args, run_program
from pkm4puu.plots import save_figure

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The Coulomb friction's regularising speed is the model's, known (m/s).
V_S = 0.005
# What the machine's builder knows: the spec's bodies, no rotors, no
# friction, and the payload as drawn (0.2 kg, 10 mm off centre).
NOMINAL = {"payload_mass": 0.2, "payload_com[1]": 0.01, "payload_com[2]": -0.005, "payload_Izz": 1e-4,
           "friction_velocity": V_S}
# The machine as built: every mass and inertia 25-40 % off the spec's (the
# rod's inertias keep their triangle inequality), rotors, friction.
TRUE = {"m_slider": 0.09331 * 1.30, "m_rod": 0.06371 * 0.75, "I_rod[1]": 3.83e-6 * 1.40,
        "I_rod[2]": 49.86e-6 * 1.25, "I_rod[3]": 52.64e-6 * 1.25, "m_platform": 0.45474 * 1.35,
        "Izz_platform": 2874.21e-6 * 0.70, "payload_mass": 0.2 * 1.25, "payload_com[1]": 0.014,
        "payload_com[2]": -0.003, "payload_Izz": 1e-4 * 1.40, "rotor_inertia": 1.5e-7, "friction_viscous": 5.0,
        "friction_coulomb": 0.6, "friction_velocity": V_S}
CUTOFF = 20.0      # Hz, the identification's low-pass
DURATION = 5.0     # s of excitation log (two periods)
VALIDATION = 3.0   # s of validation log (one period)
REPLAY = 0.5       # s of open-loop replay under the logged forces


@dataclass
class Calibration:
    excitation: object
    log: DriveLog
    result: object
    pi_true_base: np.ndarray     # the true base parameters
    validation: DriveLog
    F_nominal: np.ndarray        # the inverse FMU's forces along the validation, nominal parameters
    F_identified: np.ndarray     # ... identified parameters
    force_error: dict            # "nominal"/"identified" -> RMS(F_pred - F_log) / RMS(F_log)
    rho_nominal: np.ndarray      # the replay's sliders, nominal parameters (NaN after a stop)
    rho_identified: np.ndarray
    motion_error: dict           # "nominal"/"identified" -> RMS(rho_replay - rho_log), m, over "window" s


def rms(a):
    return float(np.sqrt(np.nanmean(np.square(a))))


def calibrate(plant_fmu=None, inverse_fmu=None, lib=None, seed=0, log=lambda m: None) -> Calibration:
    lib = lib or capi.load()
    build = None if plant_fmu is None else plant_fmu.parent
    log("optimising the excitation trajectory")
    traj = optimise_excitation(lib, model=NOMINAL, seed=seed)
    log(f"excitation: condition number {traj.condition:.4g} (random start {traj.start_condition:.4g})")
    log(f"driving the true machine along it for {DURATION:g} s")
    drive = simulate_drive_log(traj, DURATION, TRUE, seed=seed + 1, build=build)
    log("identifying")
    result = identify(drive.t, drive.rho, drive.F, cutoff=CUTOFF, model=NOMINAL, lib=lib)
    with make_plant(lib, TRUE) as p:
        pi_true_base = result.base.K @ p.regressor_params()

    log(f"validation: a random trajectory for {VALIDATION:g} s")
    vtraj = random_trajectory(lib, model=NOMINAL, seed=seed + 7)
    val = simulate_drive_log(vtraj, VALIDATION, TRUE, seed=seed + 2, build=build)
    identified = {**NOMINAL, **result.start_values}
    F_nom = feedforward(vtraj, val.t, NOMINAL, build)[0]
    F_id = feedforward(vtraj, val.t, identified, build)[0]
    force_error = {k: rms(Fp - val.F) / rms(val.F) for k, Fp in (("nominal", F_nom), ("identified", F_id))}
    # Open loop under the logged forces, low-passed as the identification's rho.
    from scipy.signal import butter, sosfiltfilt
    sos = butter(4, CUTOFF, fs=1.0 / (val.t[1] - val.t[0]), output="sos")
    F_replay = sosfiltfilt(sos, val.F, axis=0)
    n = int(round(REPLAY / (val.t[1] - val.t[0]))) + 1
    t = val.t[:n]
    rho_nom, _ = replay(F_replay[:n], t, NOMINAL, val.pose_ref[0], val.vel_ref[0], build)
    rho_id, _ = replay(F_replay[:n], t, identified, val.pose_ref[0], val.vel_ref[0], build)
    # Over the time both replays ran (a replay that leaves the workspace
    # stops at its singularity guard).
    m = int(np.min([np.argmin(np.isfinite(r).all(axis=1)) if not np.isfinite(r).all() else n
                    for r in (rho_nom, rho_id)]))
    motion_error = {"nominal": rms(rho_nom[:m] - val.rho[:m]), "identified": rms(rho_id[:m] - val.rho[:m]),
                    "window": float(t[m - 1] - t[0])}
    return Calibration(traj, drive, result, pi_true_base, val, F_nom, F_id, force_error, rho_nom, rho_id,
                       motion_error)


def summary(c: Calibration):
    r = c.result
    z = (r.values_ls - c.pi_true_base) / r.std
    w = max(len(n) for n in r.names)
    lines = [f"excitation: condition number {c.excitation.condition:.4g} of the base regressor "
             f"(unit-norm columns; random start {c.excitation.start_condition:.4g})",
             f"identification: {r.samples} samples, condition {r.condition:.4g}, residual RMS {r.residual_rms:.4g} N",
             f"{'base parameter':<{w}}  {'true':>12}  {'identified':>12}  {'std':>10}  {'error/std':>9}"]
    for n, tv, v, s, zz in zip(r.names, c.pi_true_base, r.values_ls, r.std, z):
        lines.append(f"{n:<{w}}  {tv:12.6g}  {v:12.6g}  {s:10.3g}  {zz:9.2f}")
    lines += [f"validation forces, RMS error / RMS force: nominal {c.force_error['nominal']:.2%}, "
              f"identified {c.force_error['identified']:.2%}",
              f"validation motion under the logged forces, open loop for {c.motion_error['window']:.3g} s (of "
              f"{REPLAY:g} s; the nominal run "
              + ("held" if np.all(np.isfinite(c.rho_nominal)) else "left the workspace") +
              f"), RMS slider error: nominal {c.motion_error['nominal'] * 1e3:.4g} mm, identified "
              f"{c.motion_error['identified'] * 1e3:.4g} mm"]
    return "\n".join(lines)


def plot(c: Calibration, path):
    v = c.validation
    fig, axes = plt.subplots(4, 2, figsize=(11, 8), sharex=True)
    for i in range(4):
        for j, (F, name) in enumerate(((c.F_nominal, "nominal (spec)"), (c.F_identified, "identified"))):
            ax = axes[i, j]
            ax.plot(v.t, v.F[:, i], color="0.6", lw=0.6, label="measured")
            ax.plot(v.t, F[:, i], color="C3" if j == 0 else "C0", lw=1.0, label=f"predicted, {name}")
            if i == 0:
                key = "nominal" if j == 0 else "identified"
                ax.set_title(f"{name}: RMS error {c.force_error[key]:.2%}")
                ax.legend(loc="upper right", fontsize=7)
            ax.set_ylabel(f"$F_{i + 1}$ (N)")
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    fig.suptitle("Validation trajectory: measured and predicted actuator forces, before and after identification")
    save_figure(fig, path, dpi=100)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="calibration", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "calibration.png and calibration_start.json")
    ap.add_argument("--seed", type=int, default=0, help="seed of the excitation's start and the noise")

    def compute(args, fmus, log):
        lib = capi.load(capi.library_path(args.build))
        c = calibrate(fmus[0], fmus[1], lib, seed=args.seed, log=log)
        return summary(c), {"calibration.png": lambda p: plot(c, p),
                            "calibration_start.json": lambda p: p.write_text(
                                json.dumps(c.result.start_values, indent=2) + "\n")}

    return run_program(ap, argv, compute)


if __name__ == "__main__":
    sys.exit(main())
