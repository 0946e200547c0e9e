# SPDX-License-Identifier: BSD-2-Clause
# The plant FMU held at home by the static forces (2.655616050 N each,
# docs/model.md), one simulated second with fmpy; run in the folder of the FMU.
from fmpy import simulate_fmu

hold = {f"F[{i}]": 2.655616050 for i in range(1, 5)}
res = simulate_fmu("PKM4PUU.fmu", stop_time=1.0, output_interval=1e-3,
                   start_values={**hold, "solver": 1},  # RK4 at 1 ms
                   output=["x", "y", "z", "phi", "rho[1]"])
print("final pose x, y, z, phi:", [float(res[-1][n]) for n in ("x", "y", "z", "phi")])
print("rho[1] (m):", float(res[-1]["rho[1]"]))
