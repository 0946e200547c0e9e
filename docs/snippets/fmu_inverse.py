# SPDX-License-Identifier: BSD-2-Clause
# Inverse dynamics at one instant through fmpy's FMU2Slave: set the motion as
# inputs, read the forces; run in the folder of the FMU.
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

md = read_model_description("PKM4PUU_Inverse.fmu")
vr = {v.name: v.valueReference for v in md.modelVariables}
inv = FMU2Slave(guid=md.guid, unzipDirectory=extract("PKM4PUU_Inverse.fmu"),
                modelIdentifier=md.coSimulation.modelIdentifier, instanceName="inv")
inv.instantiate(); inv.setupExperiment(startTime=0.0)
inv.enterInitializationMode(); inv.exitInitializationMode()
inv.setReal([vr["z"], vr["ddz"]], [0.06, 0.5])            # at z = 60 mm, accelerating up at 0.5 m/s^2
print("F (N):", inv.getReal([vr[f"F[{i}]"] for i in range(1, 5)]))
inv.terminate(); inv.freeInstance()
