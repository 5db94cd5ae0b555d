"""An fmpy FMU2Slave with value references by name, shared by the FMU tests."""

import numpy as np
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave


class Slave:
    """An FMU2Slave with value references by name."""

    def __init__(self, fmu, unzip_dir, name="inst", guid=None):
        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.s = FMU2Slave(guid=guid or md.guid, unzipDirectory=str(unzip_dir),
                           modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)

    def start(self, stop=None, reals=None, ints=None):
        """Instantiate, set parameters (name -> value) and initialise."""
        self.s.instantiate()
        if reals:
            self.s.setReal([self.vr[n] for n in reals], list(reals.values()))
        if ints:
            self.s.setInteger([self.vr[n] for n in ints], list(ints.values()))
        self.s.setupExperiment(startTime=0.0, stopTime=stop)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()
        return self

    def set(self, **values):
        names = [k.replace("__", ".") for k in values]
        self.s.setReal([self.vr[n] for n in names], list(values.values()))

    def get(self, *names):
        return np.array(self.s.getReal([self.vr[n] for n in names]))

    def free(self):
        self.s.terminate()
        self.s.freeInstance()
