# SPDX-License-Identifier: BSD-2-Clause
"""The engine comparison's report: the tables `pkm4puu engines` prints, the
files it writes (engines_comparison.csv and the three figures) and the
verdict against the bounds, all from engine_comparison's results."""

import csv
import math
from pathlib import Path

import numpy as np

from .. import spec
from ..plots import pyplot, save_figure
from .engine_comparison import (CAPI_SOLVERS, MUJOCO_MACHINE_STEP, OUT, REF_RTOL, TOL_CONSTRAINT, TOL_FMU_PHI,
                                TOL_FMU_POS, TOL_ID, TOL_MACHINE_ID, TOL_MACHINE_PHI, TOL_MACHINE_POS, TOL_PHI,
                                TOL_POS, TOL_REF_PHI, TOL_REF_POS, deviation, deviation_series)


def format_machine_table(results):
    """Lines of a table: per machine case, this model and MuJoCo against Pinocchio."""
    lines = [f"The machine on the comparison test (bounds: C API {TOL_POS:g} m, {TOL_PHI:g} rad; MuJoCo "
             f"{TOL_MACHINE_POS:g} m, {TOL_MACHINE_PHI:g} rad, RK4 {MUJOCO_MACHINE_STEP * 1e3:g} ms)",
             f"  {'case':<18} {'term effect (m, rad)':>22} {'C API CVODE':>20} {'C API RK4 1 ms':>20} "
             f"{'MuJoCo':>20} {'MuJoCo ||C||':>13}"]
    for name, r in results.items():
        eff = deviation(r["ref"], r["ideal"])
        cells = [f"{eff[0]:.1e}, {eff[1]:.1e}"]
        for solver in CAPI_SOLVERS:
            d = deviation(r["capi"][solver], r["ref"])
            cells.append(f"{d[0]:.1e}, {d[1]:.1e}")
        if "mujoco" in r:
            d = deviation(r["mujoco"], r["ref"])
            cells += [f"{d[0]:.1e}, {d[1]:.1e}", f"{r['mujoco']['constraint'].max():.1e}"]
        else:
            cells += ["-", "-"]
        lines.append(f"  {name:<18} {cells[0]:>22} {cells[1]:>20} {cells[2]:>20} {cells[3]:>20} {cells[4]:>13}")
    return lines




def _mark(ok):
    return "ok" if ok else "FAIL"


def format_tables(r, sweep=None):
    lines = []
    idd = r["id"]
    lines.append("Inverse dynamics along the auto-test (2001 samples, 1 ms): max |F - F_Pinocchio| (N)")
    d = np.abs(idd["capi"] - idd["pinocchio"]).max()
    lines.append(f"  C API (pkm_inverse_dynamics)  {d:.2e}  (bound {TOL_ID:g}: {_mark(d <= TOL_ID)}); "
                 f"lambda {np.abs(idd['lambda_capi'] - idd['lambda_pinocchio']).max():.2e}")
    if "fmu" in idd:
        d = np.abs(idd["fmu"] - idd["pinocchio"]).max()
        lines.append(f"  inverse FMU                    {d:.2e}  (bound {TOL_ID:g}: {_mark(d <= TOL_ID)})")
    ref = r["ref"]
    lines.append("")
    lines.append(f"Comparison test (g = 0, F1 = -F4 = {spec.CMP_AMPLITUDE:g} N sin(2 pi t / 1.5 s), 1.5 s), against "
                 f"Pinocchio (DOP853 rtol {REF_RTOL:g}, {ref['nfev']} evaluations, max ||C|| "
                 f"{ref['constraint'].max():.1e} m)")
    lines.append(f"  {'run':<46} {'max |d pos| (m)':>16} {'max |d phi| (rad)':>18} {'max ||C(q)|| (m)':>17}  bound")
    dp, dphi = deviation(r["ref_rk4"], ref)
    ok = dp <= TOL_REF_POS and dphi <= TOL_REF_PHI
    lines.append(f"  {'Pinocchio constraintDynamics, RK4 0.5 ms':<46} {dp:16.2e} {dphi:18.2e} "
                 f"{r['ref_rk4']['constraint'].max():17.1e}  {TOL_REF_POS:g} m, {TOL_REF_PHI:g} rad: {_mark(ok)}")
    for name, run in r["capi"].items():
        dp, dphi = deviation(run, ref)
        c = run["constraint"].max()
        ok = dp <= TOL_POS and dphi <= TOL_PHI and c <= TOL_CONSTRAINT
        label = "C API, CVODE rtol 1e-12 (F at own times)" if name == "CVODE" else "C API, RK4 1 ms (F at own times)"
        lines.append(f"  {label:<46} {dp:16.2e} {dphi:18.2e} {c:17.1e}  {TOL_POS:g} m, {TOL_PHI:g} rad: {_mark(ok)}")
    held = r["ref_held"]
    dp, dphi = deviation(held, ref)
    lines.append(f"  {'Pinocchio, midpoint-held F (the hold itself)':<46} {dp:16.2e} {dphi:18.2e} "
                 f"{held['constraint'].max():17.1e}  (reported)")
    for name, run in r.get("fmu", {}).items():
        dp, dphi = deviation(run, ref)
        c = run["constraint"].max()
        ok = dp <= TOL_FMU_POS and dphi <= TOL_FMU_PHI and c <= TOL_CONSTRAINT
        label = f"plant FMU, {name}, 1 ms, midpoint-held F"
        hp, hphi = deviation(run, held)
        lines.append(f"  {label:<46} {dp:16.2e} {dphi:18.2e} {c:17.1e}  {TOL_FMU_POS:g} m, {TOL_FMU_PHI:g} rad: "
                     f"{_mark(ok)}; vs held: {hp:.1e} m, {hphi:.1e} rad")
    mj = r["mujoco"]
    dp, dphi = deviation(mj, ref)
    hp, hphi = deviation(mj, held)
    lines.append(f"  {'MuJoCo, RK4 1 ms, midpoint-held F':<46} {dp:16.2e} {dphi:18.2e} "
                 f"{mj['constraint'].max():17.1e}  (reported); vs held: {hp:.1e} m, {hphi:.1e} rad")
    if "machine" in r:
        lines.append("")
        lines += format_machine_table(r["machine"])
    if "machine_id" in r:
        mid = r["machine_id"]
        d = np.abs(mid["capi"]["F"] - mid["pinocchio"]).max()
        dt = np.abs(mid["capi"]["tau"] - mid["pinocchio"] * mid["screw_lead"] / (2 * math.pi)).max()
        lines.append(f"  inverse dynamics with every term along the auto-test: max |F - F_Pinocchio| {d:.2e} N "
                     f"(bound {TOL_MACHINE_ID:g}: {_mark(d <= TOL_MACHINE_ID)}), tau {dt:.2e} N m")
    if sweep:
        lines.append("")
        lines.append("MuJoCo's equality constraints (connect), RK4 1 ms, against Pinocchio with the same "
                     "midpoint-held forces:")
        lines.append(f"  {'setting':<52} {'max ||C(q)|| (m)':>17} {'max |d pos| (m)':>16} {'max |d phi| (rad)':>18}")
        for label, c, dp, dphi in sweep:
            lines.append(f"  {label:<52} {c:17.2e} {dp:16.2e} {dphi:18.2e}")
    return "\n".join(lines)


# --- results ---------------------------------------------------------------------------------------------
THIS_STYLE = {"linestyle": "--", "linewidth": 1.6}


def write_results(r, out_dir, figures=True):
    """Writes engines_comparison.csv and (with `figures`) the three PNG files
    into out_dir; returns their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    ref, mj, capi = r["ref"], r["mujoco"], r["capi"]["CVODE"]
    fmu = r.get("fmu", {}).get("RK4")
    t = ref["t"]
    paths = []

    csv_path = out_dir / "engines_comparison.csv"
    series = [("pinocchio", ref), ("capi_cvode", capi), ("capi_rk4", r["capi"]["RK4"]), ("mujoco", mj)]
    if fmu is not None:
        series.append(("fmu_rk4", fmu))
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t"] + [f"{s}_{n}" for s, _ in series for n in OUT + ["constraint"]])
        for k in range(len(t)):
            w.writerow([f"{t[k]:.6f}"] + [f"{run[n][k]:.15e}" for _, run in series for n in OUT + ["constraint"]])
    paths.append(csv_path)
    if not figures:
        return paths

    # Figs. 9-10: platform pose. Engines solid, this model dashed.
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.5), sharex=True)
    for ax, name, scale, unit in zip(axes.flat, ("x", "y", "z", "phi"), (1e3, 1e3, 1e3, 180 / math.pi),
                                     ("mm", "mm", "mm", "deg")):
        ax.plot(t, scale * ref[name], color="0.55", linewidth=4.0, label="Pinocchio (reference)")
        ax.plot(t, scale * mj[name], color="tab:blue", linewidth=1.3, label="MuJoCo")
        ax.plot(t, scale * capi[name], color="tab:red", label="this model (C API, CVODE)", **THIS_STYLE)
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    axes[0, 0].legend(loc="best", fontsize=8)
    fig.suptitle("Comparison test: platform pose, independent engines (solid) and this model (dashed)\n"
                 "g = 0, F1 = -F4 = 0.02 N sin(2 pi t / 1.5 s), F2 = F3 = 0", fontsize=11)
    p = out_dir / "engines_pose.png"
    save_figure(fig, p)
    paths.append(p)

    # Fig. 11: delta rho1.
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, 1e3 * ref["delta_rho1"], color="0.55", linewidth=4.0, label="Pinocchio (reference)")
    ax.plot(t, 1e3 * mj["delta_rho1"], color="tab:blue", linewidth=1.3, label="MuJoCo")
    ax.plot(t, 1e3 * capi["delta_rho1"], color="tab:red", label="this model (C API, CVODE)", **THIS_STYLE)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("delta rho1 (mm)")
    ax.set_title("Comparison test: displacement of actuator 1, engines (solid) and this model (dashed)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    p = out_dir / "engines_delta_rho1.png"
    save_figure(fig, p)
    paths.append(p)

    # Differences, and constraint violations. Runs driven by the exact forces
    # are compared with the reference; runs with midpoint-held forces with
    # Pinocchio driven by the same held forces (the hold's own error is the
    # green curve), so each curve shows the engine's or the integrator's part.
    tiny = 1e-18  # keeps exact zeros on the log axis
    held = r["ref_held"]
    fig, axes = plt.subplots(3, 1, figsize=(9, 10), sharex=True)
    curves = [("C API, CVODE rtol 1e-12, exact F", capi, ref, "tab:red", "--"),
              ("C API, RK4 1 ms, exact F", r["capi"]["RK4"], ref, "tab:orange", "--")]
    for name, run in r.get("fmu", {}).items():
        curves.append((f"plant FMU, {name}, held F, vs Pinocchio held", run, held,
                       "tab:purple" if name == "RK4" else "tab:brown", "--"))
    curves.append(("MuJoCo, RK4 1 ms, held F, vs Pinocchio held", mj, held, "tab:blue", "-"))
    curves.append(("the hold itself: Pinocchio held vs exact F", held, ref, "tab:green", "-"))
    for label, run, base, color, ls in curves:
        dp, dphi = deviation_series(run, base)
        axes[0].semilogy(t, dp + tiny, color=color, linestyle=ls, linewidth=1.2, label=label)
        axes[1].semilogy(t, dphi + tiny, color=color, linestyle=ls, linewidth=1.2)
        axes[2].semilogy(t, run["constraint"] + tiny, color=color, linestyle=ls, linewidth=1.2)
    axes[2].semilogy(t, ref["constraint"] + tiny, color="0.4", linestyle="-", linewidth=1.0,
                     label="Pinocchio reference (exact F)")
    for ax, b, text in ((axes[0], TOL_POS, "C API bound"), (axes[1], TOL_PHI, "C API bound"),
                        (axes[2], TOL_CONSTRAINT, "1e-12 m")):
        ax.axhline(b, color="k", linewidth=0.8, linestyle=":")
        ax.text(0.005, b * 1.6, text, fontsize=7, transform=ax.get_yaxis_transform())
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("|difference| of x, y, z, delta rho1 (m)")
    axes[1].set_ylabel("|difference| of phi (rad)")
    axes[2].set_ylabel("||C(q)|| (m)")
    axes[2].set_xlabel("time (s)")
    axes[0].set_title("Comparison test: differences from Pinocchio's constrained dynamics\n"
                      "(exact F: DOP853 rtol 1e-13; held F: the same forces held over each 1 ms step)",
                      fontsize=10)
    handles = [h for ax in (axes[0], axes[2]) for h in ax.get_legend_handles_labels()[0]]
    labels = [lb for ax in (axes[0], axes[2]) for lb in ax.get_legend_handles_labels()[1]]
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    p = out_dir / "engines_differences.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    paths.append(p)
    return paths


def check(r):
    """The issue's bounds: list of failure messages (empty: all hold)."""
    bad = []
    idd = r["id"]
    for key in ("capi", "fmu"):
        if key in idd:
            d = np.abs(idd[key] - idd["pinocchio"]).max()
            if not d <= TOL_ID:
                bad.append(f"inverse dynamics, {key}: {d:.3e} N > {TOL_ID:g} N")
    dp, dphi = deviation(r["ref_rk4"], r["ref"])
    if not (dp <= TOL_REF_POS and dphi <= TOL_REF_PHI):
        bad.append(f"the reference is not converged: {dp:.3e} m, {dphi:.3e} rad")
    for name, run in r["capi"].items():
        dp, dphi = deviation(run, r["ref"])
        if not (dp <= TOL_POS and dphi <= TOL_PHI):
            bad.append(f"C API {name}: {dp:.3e} m, {dphi:.3e} rad")
        if not run["constraint"].max() <= TOL_CONSTRAINT:
            bad.append(f"C API {name}: ||C|| {run['constraint'].max():.3e} m")
    for name, run in r.get("fmu", {}).items():
        dp, dphi = deviation(run, r["ref"])
        if not (dp <= TOL_FMU_POS and dphi <= TOL_FMU_PHI):
            bad.append(f"plant FMU {name}: {dp:.3e} m, {dphi:.3e} rad")
    for case, mr in r.get("machine", {}).items():
        for name, run in mr["capi"].items():
            dp, dphi = deviation(run, mr["ref"])
            if not (dp <= TOL_POS and dphi <= TOL_PHI):
                bad.append(f"machine {case}, C API {name}: {dp:.3e} m, {dphi:.3e} rad")
        if "mujoco" in mr:
            dp, dphi = deviation(mr["mujoco"], mr["ref"])
            if not (dp <= TOL_MACHINE_POS and dphi <= TOL_MACHINE_PHI):
                bad.append(f"machine {case}, MuJoCo: {dp:.3e} m, {dphi:.3e} rad")
    if "machine_id" in r:
        d = np.abs(r["machine_id"]["capi"]["F"] - r["machine_id"]["pinocchio"]).max()
        if not d <= TOL_MACHINE_ID:
            bad.append(f"inverse dynamics with the machine: {d:.3e} N > {TOL_MACHINE_ID:g} N")
    return bad
