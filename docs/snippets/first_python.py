# SPDX-License-Identifier: BSD-2-Clause
# The paper's auto-test in a few lines: the inverse FMU gives the forces of the
# prescribed motion, the plant FMU driven by them open loop reproduces it.
import matplotlib.pyplot as plt
import numpy as np
import pkm4puu as pkm

times = (np.arange(2000) + 0.5) * pkm.STEP          # the midpoint of every 1 ms step
with pkm.Fmu.open("PKM4PUU_Inverse") as inverse:   # FMI 2.0; fmi=3 for the FMI 3.0 archive
    forces = pkm.inverse_forces(inverse, times)     # F1..F4 (N) of the prescribed motion

with pkm.Fmu.open("PKM4PUU", start=pkm.START_P0) as plant:
    run = plant.simulate(pkm.T_MOVE, pkm.STEP, outputs=pkm.POSE,
                         inputs=lambda t: dict(zip(pkm.F, forces[round(t / pkm.STEP)])))

error = run.values - np.array([pkm.pose_at(t) for t in run.t])
print(f"largest position error {abs(error[:, :3]).max():.1e} m")
plt.plot(run.t, run["z"], label="z (m)"); plt.xlabel("t (s)"); plt.legend(); plt.show()
