# SPDX-License-Identifier: BSD-2-Clause
"""Systems integration: the auto-test as an SSP system run by libcosim.

PKM4PUU_autotest.ssp (a zip: SystemStructure.ssd plus both FMUs under
resources/) declares two components, `inverse` (PKM4PUU_Inverse.fmu) and
`plant` (PKM4PUU.fmu), and four connections inverse.F[i] -> plant.F[i]: the
inverse dynamics' computed forces drive the forward dynamics, open loop, as in
the paper's Fig. 4. libcosim (Open Simulation Platform, PyPI libcosimpy)
loads the .ssp and runs it with its fixed-step algorithm at 1 ms.

Where the trajectory comes from: libcosim has no signal generator, and no
third FMU is built for it. The inverse FMU's 12 motion inputs (x .. phi,
dx .. dphi, ddx .. ddphi) are left unconnected in the SSP; this script sets
them before every step through libcosim's override manipulator (the same
mechanism its scenario files use), and its initial values through the SSP's
parameter binding. Only F travels through the SSP connection.

Timing, and why the inputs lead by 3/2 of a step. libcosim's fixed-step
algorithm does, for the step from t_k:
  1. every FMU gets its inputs (connected values, overrides) and steps from
     t_k to t_k + h, all in parallel;
  2. then the outputs are copied along the connections to the inputs.
So the plant's step from t_k uses the F that the inverse FMU produced in the
step before (from t_{k-1}): a connection delays by one step. The inverse FMU
is algebraic (its F follows from its inputs at the same communication point),
so the delay is compensated exactly by giving it the motion of the moment the
plant will need: before the step from t_k, the inputs are set to the motion at
    t_k + 3h/2 = (t_k + h) + h/2,
the midpoint of the plant's next step, and the SSP's initial values (seen
during libcosim's initialisation, which transfers them before the first step)
are the motion at h/2. The plant then holds over every step [t_k, t_k + h] the
force F(t_k + h/2): exactly the midpoint-held case of the auto-test through
the FMUs (`pkm4puu autotest`), whose max pose error over the 2 s is O(h^2):
~1.1e-8 m with CVODE. With no lead (inputs at t_k) the plant would hold
F(t_k - h) over [t_k, t_k + h], a lag of 3h/2: an O(h) error of ~3e-5 m.

Writes to --out DIR:
  PKM4PUU_autotest.ssp     the system structure (with both FMUs inside)
  ssp_autotest.csv         plant pose and error vs the prescribed motion, per step
  ssp_autotest_errors.png  the error with the 3h/2 lead and without one

usage: ssp_cosim.py [--build DIR] [--out DIR] [--solver {cvode,rk4}]
"""
import argparse
import csv
import sys
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

import matplotlib
import numpy as np

from pkm4puu.program import add_common_args, start, write_outputs
from pkm4puu.closed_loop import PoseErrors
from pkm4puu.plots import save_figure
from pkm4puu.interface import ACC, F, POSE, START_P0, VEL
from pkm4puu.motions import motion, pose_at
from pkm4puu.spec import STEP as H, T_MOVE

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PLANT_FMU, INVERSE_FMU = "PKM4PUU.fmu", "PKM4PUU_Inverse.fmu"  # their names inside the SSP
H_NS = 1_000_000  # libcosim counts time in integer nanoseconds: 1 ms
N_STEPS = round(T_MOVE / H)
LEAD = 1.5  # steps: the inverse FMU's inputs lead the plant by 3h/2 (see the module's doc)
SOLVERS = {"cvode": 0, "rk4": 1}

MOTION_INPUTS = POSE + VEL + ACC
NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
}


# --- the system structure ------------------------------------------------------------------
def _connector(name, kind):
    return f'        <ssd:Connector name={quoteattr(name)} kind="{kind}"><ssc:Real/></ssd:Connector>'


def _parameter(name, value):
    kind = "Integer" if isinstance(value, int) else "Real"
    return (f'            <ssv:Parameter name={quoteattr(name)}><ssv:{kind} value="{value!r}"/>'
            f"</ssv:Parameter>")


def _parameter_binding(name, values):
    params = "\n".join(_parameter(k, v) for k, v in values.items())
    return f"""      <ssd:ParameterBindings>
        <ssd:ParameterBinding>
          <ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name={quoteattr(name)}>
           <ssv:Parameters>
{params}
           </ssv:Parameters>
          </ssv:ParameterSet>
          </ssd:ParameterValues>
        </ssd:ParameterBinding>
      </ssd:ParameterBindings>"""


def _component(name, fmu, inputs, outputs, binding, values):
    """An ssd:Component: the FMU resources/<fmu>, its Real connectors and
    one parameter set `binding` of start values."""
    connectors = "\n".join([_connector(n, "input") for n in inputs] + [_connector(n, "output") for n in outputs])
    return f"""      <ssd:Component name="{name}" source="resources/{fmu}">
        <ssd:Connectors>
{connectors}
        </ssd:Connectors>
{_parameter_binding(binding, values)}
      </ssd:Component>"""


def system_structure(solver="cvode", lead=LEAD, h=H):
    """SystemStructure.ssd as text. The plant starts at rest at P0 with the
    given solver; the inverse FMU's motion inputs start at the motion at
    (lead - 1) h, what the plant's first step needs (see the module's doc)."""
    plant_params = {**{k: float(v) for k, v in START_P0.items()}, "solver": SOLVERS[solver]}
    if solver == "rk4":
        plant_params["rk4_step"] = float(h)
    inverse_start = dict(zip(MOTION_INPUTS, (float(v) for v in motion((lead - 1.0) * h))))
    xmlns = " ".join(f'xmlns:{k}="{v}"' for k, v in NS.items())
    connections = "\n".join(
        f'      <ssd:Connection startElement="inverse" startConnector="{n}" endElement="plant" endConnector="{n}"/>'
        for n in F)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- The paper's auto-test (docs/model.md "The paper's two tests") as a system: inverse dynamics -> forces -> forward
     dynamics. The inverse FMU's motion inputs are unconnected: the master sets them every step
     (examples/ssp_cosim.py, libcosim's override manipulator); their values here are the initial ones. -->
<ssd:SystemStructureDescription {xmlns} name="PKM4PUU_autotest" version="1.0">
  <ssd:System name="autotest" description="4-PUU PKM: computed-force feed-forward driving the plant open loop">
    <ssd:Elements>
{_component("inverse", INVERSE_FMU, MOTION_INPUTS, F, "initial motion", inverse_start)}
{_component("plant", PLANT_FMU, F, POSE, "plant set-up", plant_params)}
    </ssd:Elements>
    <ssd:Connections>
{connections}
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{T_MOVE:g}">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm><osp:FixedStepAlgorithm baseStepSize="{h:g}"/></osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def write_ssp(plant_fmu, inverse_fmu, path, solver="cvode", lead=LEAD):
    """The .ssp archive: SystemStructure.ssd and resources/<the two FMUs>."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", system_structure(solver, lead))
        z.write(plant_fmu, f"resources/{PLANT_FMU}")
        z.write(inverse_fmu, f"resources/{INVERSE_FMU}")
    return path


# --- running it with libcosim ----------------------------------------------------------------
@dataclass
class SspRun(PoseErrors):
    """Communication times t (s), the plant's pose (x, y, z, phi) there and
    the prescribed pose pose_d; pos_err (m) and phi_err (rad) as in `pkm4puu autotest`."""
    t: np.ndarray
    pose: np.ndarray
    pose_d: np.ndarray


def _libcosim():
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)
    return CosimExecution, CosimManipulator, CosimObserver


def run_ssp(ssp_path, lead=LEAD, n_steps=N_STEPS, log=None):
    """Loads the .ssp into libcosim and runs n_steps of 1 ms; before the step
    from t_k the inverse FMU's motion inputs are overridden with the motion at
    t_k + lead h. `lead` must match the one the .ssp was written with (its
    initial values are the motion at (lead - 1) h)."""
    CosimExecution, CosimManipulator, CosimObserver = _libcosim()
    ssp_path = Path(ssp_path).resolve()  # libcosim resolves the FMUs from the .ssd's absolute URI
    execution = CosimExecution.from_ssp_file(str(ssp_path), step_size=H_NS)
    names = {s.name.decode(): s.index for s in execution.slave_infos()}
    if set(names) != {"inverse", "plant"}:
        raise RuntimeError(f"{ssp_path.name}: expected the components inverse and plant, libcosim loaded {names}")
    inv, plant = names["inverse"], names["plant"]
    ref_inv = {v.name.decode(): v.reference for v in execution.slave_variables(inv)}
    ref_plant = {v.name.decode(): v.reference for v in execution.slave_variables(plant)}
    observer = CosimObserver.create_last_value()
    override = CosimManipulator.create_override()
    if not (execution.add_observer(observer=observer) and execution.add_manipulator(manipulator=override)):
        raise RuntimeError("libcosim: could not add the observer or the override manipulator")
    vr_motion = [ref_inv[n] for n in MOTION_INPUTS]
    vr_pose = [ref_plant[n] for n in POSE]

    t = np.arange(n_steps + 1) * H
    poses = np.empty((n_steps + 1, 4))
    poses[0] = [START_P0[k] for k in ("x0", "y0", "z0", "phi0")]
    for k in range(n_steps):
        if not override.slave_real_values(inv, vr_motion, [float(v) for v in motion((k + lead) * H)]):
            raise RuntimeError(f"libcosim: could not override the inverse FMU's inputs at step {k}")
        if not execution.step():
            raise RuntimeError(f"libcosim: the step from t = {t[k]:.3f} s failed: {execution.status()}")
        poses[k + 1] = observer.last_real_values(plant, vr_pose)
        if log and (k + 1) % 500 == 0:
            log(f"  t = {t[k + 1]:.2f} s")
    now = execution.status().current_time
    if now != n_steps * H_NS:
        raise RuntimeError(f"libcosim stopped at {now} ns, not {n_steps * H_NS} ns")
    return SspRun(t, poses, np.array([pose_at(ti) for ti in t]))


def write_csv(runs, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        head = ["t_s"]
        for name in runs:
            head += [f"{name}_{q}" for q in ("x_m", "y_m", "z_m", "phi_rad", "pos_err_m", "phi_err_rad")]
        w.writerow(head)
        first = next(iter(runs.values()))
        for k, tk in enumerate(first.t):
            row = [f"{tk:.6f}"]
            for r in runs.values():
                row += [f"{v:.15e}" for v in r.pose[k]] + [f"{r.pos_err[k]:.6e}", f"{r.phi_err[k]:.6e}"]
            w.writerow(row)


def plot(runs, path, solver):
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for (name, r), style in zip(runs.items(), ("C3-", "k--")):
        axes[0].semilogy(r.t, np.maximum(r.pos_err, 1e-18), style, label=name)
        axes[1].semilogy(r.t, np.maximum(r.phi_err, 1e-18), style, label=name)
    axes[0].set_ylabel("|p - p_prescribed| (m)")
    axes[1].set_ylabel("|phi - phi_prescribed| (rad)")
    axes[1].set_xlabel("time (s)")
    axes[0].set_title(f"Auto-test as an SSP system in libcosim: inverse.F -> plant.F, 1 ms fixed step, "
                      f"plant {solver.upper()}", fontsize=10)
    for ax in axes:
        ax.set_ylim(bottom=1e-12)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    save_figure(fig, path, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="ssp_cosim", description=__doc__.split("\n\n")[0])
    add_common_args(ap, "PKM4PUU_autotest.ssp, ssp_autotest.csv and ssp_autotest_errors.png")
    ap.add_argument("--solver", choices=sorted(SOLVERS), default="cvode",
                    help="the plant's integrator (default %(default)s)")
    args, log, fmus = start(ap, argv)
    if fmus is None:
        return 1
    args.out.mkdir(parents=True, exist_ok=True)
    ssp = write_ssp(*fmus, args.out / "PKM4PUU_autotest.ssp", solver=args.solver)
    log(f"wrote {ssp}")
    cases = {"inputs lead by 3h/2 (compensated)": LEAD, "no lead (inputs at t_k)": 0.0}
    runs = {}
    try:
        for name, lead in cases.items():
            path = ssp if lead == LEAD else write_ssp(*fmus, args.out / "PKM4PUU_autotest_nolead.ssp",
                                                      solver=args.solver, lead=lead)
            log(f"libcosim: {name}, {N_STEPS} steps of {H * 1e3:g} ms")
            runs[name] = run_ssp(path, lead=lead, log=log)
            if lead != LEAD:
                path.unlink()
    except Exception as exc:
        log(f"error: {exc}")
        return 1
    print(f"auto-test in libcosim from {ssp.name} (plant {args.solver.upper()}), max errors over {T_MOVE:g} s:")
    for name, r in runs.items():
        print(f"  {name:<36} {r.pos_err.max():.3e} m  {r.phi_err.max():.3e} rad")
    write_outputs(args.out, log, {"ssp_autotest.csv": lambda p: write_csv(runs, p),
                                  "ssp_autotest_errors.png": lambda p: plot(runs, p, args.solver)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
