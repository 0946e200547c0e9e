# SPDX-License-Identifier: BSD-2-Clause
"""Linearising the plant FMU and an LQR designed on it: the hanging machine's
modes, and a task-space state feedback against the joint-space PD of
closed_loop_control.py.

1. A = d der(y)/dy and B = d der(y)/du at the home pose P0, held at rest by
   the spec's forces (2.655616050 N each), from the Model Exchange FMU through
   fmpy's fmi2GetDirectionalDerivative (pkm4puu.linearization); y = (pose,
   rates), u = (F[1..4], Fe[1..3], Me_z, tau[1..4]); the ideal machine (the
   spec's defaults).
2. The open-loop modes. At rest the rate terms vanish (the velocity forces
   are quadratic in the rates; the ideal machine has no friction), so
   A = [[0, I], [-M^-1 K, 0]] and its eigenvalues are +-i omega with omega^2
   the eigenvalues of M^-1 K: the hanging machine oscillates (docs/model.md
   "Working mode": elbow-down, Hessian eigenvalues +307, +95, +1.3 and 0
   along z). Computed here independently of the FMU: K the Hessian of the
   potential U(p) = gravity - sum F_i rho_i over the pose, the legs from the
   spec's closed-form inverse kinematics (Richardson-extrapolated second
   differences); M = T^T M16 T from Pinocchio's CRBA on the independent model
   (T = dq/dp).
3. The linearisation against the nonlinear plant: from the equilibrium
   plus a small dy0, the Co-Simulation FMU (RK4, 1 ms, the holding forces)
   against expm(A t) dy0, at dy0 and dy0 / 2 (the error is second order).
4. An LQR on (A, B_F), the four actuator forces as controls, by Bryson's
   rule: a pose error of 1 mm (phi: 1 mm at the spec's 0.1 m lever) costs as
   much as a correction of one holding force, 2.66 N per actuator; the rates
   are not penalised. scipy.linalg.solve_continuous_are; the 1 kHz sampled
   loop is checked on the zero-order-hold discretisation.
5. The closed loop on the Co-Simulation FMU at 1 kHz along the auto-test,
   the plant starting 1 mm off the path (along (1, 1, 1)/sqrt 3) on the
   machine of closed_loop_control.py (joint friction, off-centre payload):
       LQR:  F = F_ff + K (y_d - y)                     (pose and rates measured)
       PD:   F = F_ff + Kp (rho_d - rho) + Kd (drho_d - drho)   (closed_loop_control.run_loop)
   with the same feed-forward F_ff (the inverse FMU, friction compensated).
   The PD's gains act through the actuator Jacobian, whose x, y and phi
   columns nearly cancel (its condition number is ~25): in that direction
   the PD is soft and lightly damped, and its linearised loop has a slow
   pair; the LQR weights the pose itself.

Writes to --out DIR:
  linearize_lqr.csv   per time: position and phi errors of both loops, the LQR's forces
  linearize_lqr.png   the modes (open loop, Hessian, both closed loops) and the tracking errors

usage: linearize_lqr.py [--build DIR] [--out DIR] [--t-end S] [--offset MM]
"""
import argparse
import csv
import math
import sys
from pathlib import Path

import matplotlib
import numpy as np
import scipy.linalg as sla

from pkm4puu.program import add_common_args, run_program
from pkm4puu.plots import save_figure
from pkm4puu.closed_loop import run_closed_loop
from pkm4puu.fmu import Fmu
from pkm4puu.interface import F, POSE, RK4, VEL, start_pose
from pkm4puu.linearization import INPUTS, ModelExchange
from pkm4puu.motions import autotest_motion
from pkm4puu.references.pinocchio_derivatives import PinocchioReducedDerivatives
from pkm4puu import spec
from pkm4puu.spec import STEP as H, T_MOVE

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:
    sys.path.insert(0, str(_HERE))  # the sibling example, closed_loop_control.py
import closed_loop_control as clc  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LEVER = 0.1  # m: phi as arc length at this lever (docs/model.md's jacobian_condition convention)
F_HOLD = np.full(4, spec.STATIC_FORCE_P0)  # N: the spec's holding forces at P0
U0 = np.concatenate([F_HOLD, np.zeros(8)])  # the plant's 12 inputs at the equilibrium
Y0 = np.concatenate([spec.P0, np.zeros(4)])

# Bryson's rule for the LQR (see the module's doc)
X_MAX = 1e-3  # m, pose error
F_MAX = spec.STATIC_FORCE_P0  # N, actuator correction

OFFSET = 1e-3  # m, the initial offset from the path
OFFSET_DIR = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)
T_END = 2.5  # s: the 2-s motion, then 0.5 s at rest at P1
SETTLE = 0.5  # s: the offset's transient, left out of the "after" figures (shorter runs: half the run)

# The prediction check: a small perturbation of the equilibrium (pose, rates)
DELTA = np.array([20e-6, -15e-6, 10e-6, 2e-4, 2e-4, 1e-4, -1e-4, 3e-3])
T_PREDICT = 0.5  # s: about one period of the slowest mode


# --- 1. the linearisation -------------------------------------------------------------
def linearize(plant_fmu, y=Y0, u=U0):
    """(ydot, A 8x8, B 8x12) of the plant FMU (spec defaults) at (y, u), by
    its directional derivatives through fmpy."""
    with ModelExchange(plant_fmu, instance_name="linearize") as me:
        return me.jacobians(y, u)


def modes(A):
    """The open loop's eigenvalues, and the angular frequencies (rad/s, ascending)
    of its oscillatory pairs (eigenvalues with positive imaginary part)."""
    ev = np.linalg.eigvals(A)
    return ev, np.sort(ev.imag[ev.imag > 1e-6])


# --- 2. the independent Hessian and mass matrix -------------------------------------------------
def potential(pose, forces=F_HOLD):
    """U(p) (J) of docs/model.md "Working mode": gravity minus sum F_i rho_i, the
    legs by the spec's closed-form inverse kinematics (up to a constant)."""
    legs = spec.leg_inverse_kinematics(pose)
    rho, th2 = legs[:, 0], legs[:, 2]
    gravity = spec.G * (spec.M_PLATFORM * pose[2]
                        + np.sum(spec.M_SLIDER * rho + spec.M_ROD * (rho + spec.H + 0.5 * spec.L * np.sin(th2))))
    return gravity - float(np.dot(forces, rho))


def potential_hessian(pose=spec.P0, forces=F_HOLD, h=(2e-4, 2e-4, 2e-4, 2e-3), levels=3):
    """The 4x4 Hessian of potential() over (x, y, z, phi): central second
    differences at steps h, h/2, ... and Richardson's extrapolation (N/m,
    N/rad, N m/rad)."""
    pose = np.asarray(pose, float)
    h = np.asarray(h, float)

    def second_difference(s):
        K = np.empty((4, 4))
        for i in range(4):
            for j in range(i, 4):
                ei, ej = np.eye(4)[i] * s * h[i], np.eye(4)[j] * s * h[j]
                K[i, j] = K[j, i] = (potential(pose + ei + ej, forces) - potential(pose + ei - ej, forces)
                                     - potential(pose - ei + ej, forces)
                                     + potential(pose - ei - ej, forces)) / (4 * s * s * h[i] * h[j])
        return K

    T = []
    for k in range(levels):
        T.append(second_difference(0.5**k))
        factor = 4.0
        for j in range(k - 1, -1, -1):
            T[j] = (factor * T[j + 1] - T[j]) / (factor - 1.0)
            factor *= 4.0
    return T[0]


def reduced_mass_matrix(pose=spec.P0):
    """M = T^T M16 T (4x4) on the pose, from Pinocchio's CRBA on the
    independent model, T = dq/dp from its constraint Jacobian."""
    ref = PinocchioReducedDerivatives()
    q = ref.pm.q_from_pose(np.asarray(pose, float))
    T, _ = ref.tangent(q)
    return T.T @ ref.pm.mass_matrix(q) @ T


def hessian_frequencies(K, M):
    """sqrt of the nonzero eigenvalues of M^-1 K (rad/s, ascending), and all of them."""
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    return np.sqrt(w2[w2 > 1e-6 * w2.max()]), w2


# --- 3. the linearisation against the nonlinear plant --------------------------------------------
def predict(plant_fmu, A, dy0, t_end=T_PREDICT, h=H):
    """(t, the plant's y(t) - Y0, expm(A t) dy0): the Co-Simulation FMU
    (RK4, h) started at Y0 + dy0 under the holding forces."""
    start = {**start_pose(Y0[:4] + dy0[:4]), **dict(zip(("dx0", "dy0", "dz0", "dphi0"), map(float, dy0[4:]))), **RK4}
    n = round(t_end / h)
    t = np.arange(n + 1) * h
    with Fmu(plant_fmu, start=start, instance_name="prediction") as plant:
        plant.set(F, F_HOLD)
        Y = [plant.get(POSE + VEL)]
        for k in range(n):
            plant.do_step(t[k], h)
            Y.append(plant.get(POSE + VEL))
    lin = np.array([sla.expm(A * tk) @ dy0 for tk in t])
    return t, np.array(Y) - Y0, lin


def prediction_error(plant_fmu, A, dy0=DELTA):
    """max_t |y - Y0 - expm(A t) dy0| / max_t |expm(A t) dy0| (phi at LEVER)."""
    _, nl, lin = predict(plant_fmu, A, dy0)
    w = np.array([1, 1, 1, LEVER] * 2)
    return np.abs((nl - lin) * w).max() / np.abs(lin * w).max()


# --- 4. the LQR ------------------------------------------------------------------------------
def bryson_weights(x_max=X_MAX, f_max=F_MAX):
    """Q (8x8) and R (4x4): pose errors of x_max (phi: x_max / LEVER) against
    corrections of f_max per actuator; rates free."""
    q = np.array([1 / x_max**2] * 3 + [1 / (x_max / LEVER) ** 2] + [0.0] * 4)
    return np.diag(q), np.eye(4) / f_max**2


def lqr(A, B_F, Q, R):
    """The continuous LQR gain K (4x8), u = -K y, from the algebraic Riccati equation."""
    P = sla.solve_continuous_are(A, B_F, Q, R)
    return np.linalg.solve(R, B_F.T @ P)


def sampled(A, B_F, h=H):
    """Zero-order-hold discretisation (Ad, Bd) of the linearisation at period h."""
    n, m = B_F.shape
    E = sla.expm(np.block([[A, B_F], [np.zeros((m, n + m))]]) * h)
    return E[:n, :n], E[:n, n:]


def actuator_jacobian(pose=spec.P0, h=1e-6):
    """d rho / d pose (4x4) from the spec's closed-form inverse kinematics
    (central differences; phi step h / LEVER)."""
    pose = np.asarray(pose, float)
    steps = np.array([h, h, h, h / LEVER])
    return np.column_stack([(spec.leg_inverse_kinematics(pose + e * s)[:, 0]
                             - spec.leg_inverse_kinematics(pose - e * s)[:, 0]) / (2 * s)
                            for e, s in zip(np.eye(4), steps)])


def pd_gain(pose=spec.P0, kp=clc.KP, kd=clc.KD):
    """closed_loop_control's joint PD as a state feedback on (pose, rates):
    F = -Kp Ja dp - Kd Ja dpd, near the pose."""
    Ja = actuator_jacobian(pose)
    return np.hstack([kp * Ja, kd * Ja])


# --- 5. the closed loops ----------------------------------------------------------------------
def offset_start(offset=OFFSET):
    """The plant's initial pose parameters: P0 moved by `offset` along OFFSET_DIR."""
    return start_pose(spec.P0 + np.concatenate([offset * OFFSET_DIR, [0.0]]))


def run_lqr(plant_fmu, inverse_fmu, K, plant_machine=None, offset=OFFSET, t_end=T_END, h=H, log=None):
    """The LQR loop, F = F_ff + K (y_d - y) held over each step, from the
    offset start; a pkm4puu.closed_loop.LoopResult."""
    plant_machine = clc.machine() if plant_machine is None else plant_machine

    def lqr_law(r, k, F_ref):
        e = np.concatenate([r.pose_d[k] - r.pose[k], r.dpose_d[k] - r.dpose[k]])
        return F_ref, F_ref + K @ e

    def progress(r, k):
        return f"|p - p_d| = {1e3 * np.linalg.norm(r.pose_d[k, :3] - r.pose[k, :3]):.6f} mm"

    return run_closed_loop(plant_fmu, inverse_fmu, {**offset_start(offset), **RK4, **plant_machine}, plant_machine,
                           lqr_law, progress, t_end, T_MOVE, h, log, name="LQR loop")


def run_pd(plant_fmu, inverse_fmu, plant_machine=None, offset=OFFSET, t_end=T_END, log=None):
    """closed_loop_control's PD + feed-forward (friction compensated) from the same offset start."""
    plant_machine = clc.machine() if plant_machine is None else plant_machine
    return clc.run_loop(plant_fmu, inverse_fmu, plant_machine={**plant_machine, **offset_start(offset)},
                        model=plant_machine, feed_forward=True, t_end=t_end, log=log)


# --- the whole study ----------------------------------------------------------------------------
class Study:
    """Everything the example computes; run() fills it."""

    def __init__(self, plant_fmu, inverse_fmu, t_end=T_END, offset=OFFSET, log=None):
        self.plant_fmu, self.inverse_fmu = plant_fmu, inverse_fmu
        self.t_end, self.offset, self.log = t_end, offset, log or (lambda msg: None)

    def analyse(self):
        """Steps 1 to 4 (no closed-loop runs)."""
        log = self.log
        log("linearising the Model Exchange FMU at P0 (directional derivatives through fmpy)")
        self.ydot0, self.A, self.B = linearize(self.plant_fmu)
        self.eig_open, self.omega = modes(self.A)
        log("the potential's Hessian (spec inverse kinematics, Richardson differences) and Pinocchio's mass matrix")
        self.K_hess = potential_hessian()
        self.M = reduced_mass_matrix()
        self.omega_hess, self.w2_hess = hessian_frequencies(self.K_hess, self.M)
        log(f"the linearisation against the nonlinear plant over {T_PREDICT:g} s, at dy0 and dy0 / 2")
        self.pred_err = (prediction_error(self.plant_fmu, self.A, DELTA),
                         prediction_error(self.plant_fmu, self.A, DELTA / 2))
        self.B_F = self.B[:, :4]
        self.Q, self.R = bryson_weights()
        self.K = lqr(self.A, self.B_F, self.Q, self.R)
        self.eig_lqr = np.linalg.eigvals(self.A - self.B_F @ self.K)
        Ad, Bd = sampled(self.A, self.B_F)
        self.radius_lqr = np.abs(np.linalg.eigvals(Ad - Bd @ self.K)).max()
        self.K_pd = pd_gain()
        self.eig_pd = np.linalg.eigvals(self.A - self.B_F @ self.K_pd)
        self.radius_pd = np.abs(np.linalg.eigvals(Ad - Bd @ self.K_pd)).max()
        return self

    def run(self):
        self.analyse()
        log = self.log
        log(f"LQR + feed-forward, {self.t_end:g} s at {1 / H:g} Hz from a {1e3 * self.offset:g} mm offset")
        self.lqr_run = run_lqr(self.plant_fmu, self.inverse_fmu, self.K, offset=self.offset, t_end=self.t_end,
                               log=log)
        log(f"PD + feed-forward (closed_loop_control), the same")
        self.pd_run = run_pd(self.plant_fmu, self.inverse_fmu, offset=self.offset, t_end=self.t_end, log=log)
        return self


def rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def settle_time(t_end):
    return min(SETTLE, 0.5 * t_end)


def after(r, t0):
    """Index of the first sample at or after t0."""
    return int(np.searchsorted(r.t, t0 - 1e-12))


def summary(s):
    hz = 1 / (2 * math.pi)
    lines = [
        "linearisation at P0 (Model Exchange FMU, fmpy directional derivatives), held by the spec's forces:",
        f"  open-loop eigenvalues: {', '.join(f'{z.real:+.2e}{z.imag:+.4f}j' for z in sorted(s.eig_open, key=lambda z: z.imag))}",
        f"  oscillation frequencies: {', '.join(f'{w:.6f} rad/s ({w * hz:.4f} Hz)' for w in s.omega)}",
        f"  potential Hessian (spec IK, differences) eigenvalues: "
        f"{', '.join(f'{v:.4g}' for v in np.linalg.eigvalsh(s.K_hess))} (x, y, z in N/m; phi in N m/rad)",
        f"  sqrt(eig(M^-1 K)), M from Pinocchio: {', '.join(f'{w:.6f}' for w in s.omega_hess)} rad/s; "
        f"largest relative difference {np.abs(s.omega / s.omega_hess - 1).max():.1e}",
        f"  A against the nonlinear plant over {T_PREDICT:g} s: relative error {s.pred_err[0]:.2e} at dy0, "
        f"{s.pred_err[1]:.2e} at dy0 / 2 (ratio {s.pred_err[0] / s.pred_err[1]:.2f}; second order: 2)",
        f"LQR (Bryson: {1e3 * X_MAX:g} mm ~ {F_MAX:.2f} N per actuator), K (N/m, N/rad | N s/m, N s/rad):",
        *[f"  {' '.join(f'{v:9.1f}' for v in row[:4])} | {' '.join(f'{v:7.2f}' for v in row[4:])}" for row in s.K],
        f"  closed-loop poles: slowest decay {-s.eig_lqr.real.max():.1f} 1/s, fastest {-s.eig_lqr.real.min():.1f} 1/s; "
        f"1 kHz sampled: spectral radius {s.radius_lqr:.4f}",
        f"PD of closed_loop_control (Kp = {clc.KP:g} N/m, Kd = {clc.KD:g} N s/m per joint) on the same linearisation:",
        f"  slowest decay {-s.eig_pd.real.max():.2f} 1/s "
        f"(pair {s.eig_pd[np.argmax(s.eig_pd.real)].real:.2f} +- {abs(s.eig_pd[np.argmax(s.eig_pd.real)].imag):.2f}j), "
        f"sampled spectral radius {s.radius_pd:.4f}",
    ]
    if hasattr(s, "lqr_run"):
        lines.append(f"closed loop, 1 kHz, from a {1e3 * s.offset:g} mm offset along the auto-test "
                     f"(plant: {clc.describe(clc.machine())}):")
        ts = settle_time(s.t_end)
        lines.append(f"  {'':<22} {'RMS |p - p_d|':>14} {f'max after {ts:g} s':>16} {'at the end':>14} "
                     f"{'max phi error':>14}")
        for name, r in (("LQR + feed-forward", s.lqr_run), ("PD + feed-forward", s.pd_run)):
            k = after(r, ts)
            lines.append(f"  {name:<22} {1e3 * rms(r.pos_err):11.6f} mm {1e3 * r.pos_err[k:].max():13.6f} mm "
                         f"{1e3 * r.pos_err[-1]:11.6f} mm {math.degrees(r.phi_err.max()):10.6f} deg")
    return "\n".join(lines)


def write_csv(s, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s", "lqr_pos_err_m", "lqr_phi_err_rad", "pd_pos_err_m", "pd_phi_err_rad"]
                   + [f"lqr_F{i}_N" for i in range(1, 5)])
        a, b = s.lqr_run, s.pd_run
        for k, tk in enumerate(a.t):
            w.writerow([f"{tk:.6f}", f"{a.pos_err[k]:.6e}", f"{a.phi_err[k]:.6e}", f"{b.pos_err[k]:.6e}",
                        f"{b.phi_err[k]:.6e}"] + [f"{v:.9f}" for v in a.F[k]])


def plot(s, path):
    fig = plt.figure(figsize=(9.5, 9.0))
    gs = fig.add_gridspec(2, 2, height_ratios=[1, 1.15])
    ax0 = fig.add_subplot(gs[0, 0])
    ax1 = fig.add_subplot(gs[0, 1])
    ax2 = fig.add_subplot(gs[1, :])
    hz = 1 / (2 * math.pi)
    # the open-loop modes against the Hessian
    ax0.plot(np.zeros_like(s.omega), s.omega * hz, "kx", ms=9, label="linearisation (FMU): eig(A)")
    ax0.plot(np.zeros_like(s.omega_hess), s.omega_hess * hz, "o", mfc="none", mec="C3", ms=12,
             label=r"$\sqrt{\mathrm{eig}(M^{-1}K)}$, K: potential Hessian")
    for w in s.omega:
        ax0.annotate(f"{w * hz:.3f} Hz", (0, w * hz), xytext=(8, -3), textcoords="offset points", fontsize=8)
    ax0.set_xlim(-1, 1)
    ax0.set_ylim(s.omega.min() * hz - 0.3, s.omega.max() * hz + 0.08)  # room for the legend below
    ax0.set_xticks([0])
    ax0.set_xlabel("real part (1/s)")
    ax0.set_ylabel("frequency (Hz)")
    ax0.set_title("open loop at P0, held: the hanging machine oscillates\n(and drifts along z: a double zero)",
                  fontsize=8.5)
    ax0.legend(fontsize=7, loc="lower center")
    # the closed loops' poles
    ax1.plot(s.eig_lqr.real, s.eig_lqr.imag, "C0o", label="LQR + A, B")
    ax1.plot(s.eig_pd.real, s.eig_pd.imag, "C1s", mfc="none", label="joint PD + A, B")
    ax1.plot(s.eig_open.real, s.eig_open.imag, "kx", label="open loop")
    ax1.axvline(0, color="grey", lw=0.8)
    ax1.set_xlabel("real part (1/s)")
    ax1.set_ylabel("imaginary part (rad/s)")
    ax1.set_title(f"closed-loop poles: LQR decays at >= {-s.eig_lqr.real.max():.1f} 1/s,\n"
                  f"the joint PD's slowest pair at {-s.eig_pd.real.max():.2f} 1/s", fontsize=8.5)
    ax1.legend(fontsize=7)
    # tracking
    for r, style, name in ((s.pd_run, "C1-", "PD + feed-forward"), (s.lqr_run, "C0-", "LQR + feed-forward")):
        ax2.semilogy(r.t, 1e3 * np.maximum(r.pos_err, 1e-12), style, lw=1.3,
                     label=f"{name}: |p - p_d| (RMS {1e3 * rms(r.pos_err):.3g} mm)")
        ax2.semilogy(r.t, 1e3 * LEVER * np.maximum(r.phi_err, 1e-14), style, lw=0.8, alpha=0.6,
                     label=fr"{name}: {LEVER:g} m $\cdot|\varphi - \varphi_d|$")
    ax2.axvline(T_MOVE, color="grey", lw=0.8)
    ax2.set_ylim(1e-6, 3)
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("tracking error (mm)")
    ax2.set_title(f"1 kHz closed loop on the plant FMU along the auto-test from a {1e3 * s.offset:g} mm offset\n"
                  f"plant: {clc.describe(clc.machine())}", fontsize=8.5)
    ax2.legend(fontsize=7, loc="upper right")
    for ax in (ax0, ax1, ax2):
        ax.grid(True, alpha=0.3)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="linearize_lqr", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "linearize_lqr.csv and linearize_lqr.png")
    ap.add_argument("--t-end", type=float, default=T_END, help="closed-loop run length (s, default %(default)s)")
    ap.add_argument("--offset", type=float, default=1e3 * OFFSET,
                    help="initial offset from the path (mm, default %(default)s)")

    def compute(args, fmus, log):
        s = Study(*fmus, t_end=args.t_end, offset=1e-3 * args.offset, log=log).run()
        return summary(s), {"linearize_lqr.csv": lambda p: write_csv(s, p), "linearize_lqr.png": lambda p: plot(s, p)}

    def invalid(args):
        if args.t_end <= 0 or not 0 <= args.offset <= 5:
            return "--t-end must be > 0 and --offset within [0, 5] mm"
        return None

    return run_program(ap, argv, compute, invalid)


if __name__ == "__main__":
    sys.exit(main())
