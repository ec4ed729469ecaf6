"""PythonSystem: the pythonfmu model of `export_fmu(..., backend="python")`: any discrete
python-control system, pickled (cloudpickle) into the FMU's resources as system.pickle with its
initial state and sample time, stepped by python-control's own update and output functions.

Its inputs and outputs are Real variables named after the system's labels. After the doStep that
ends at t[k+1], with the inputs of sample k held over it, the outputs are the system's outputs at
sample k (control.input_output_response's); a step other than the system's dt is refused. The FMU
needs, where it runs, a Python with pythonfmu, numpy, control, cloudpickle and whatever the
system's functions import (attitude_fmu for the project's blocks).
"""
from __future__ import annotations

import math
import pickle
from pathlib import Path

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from attitude_fmu.systems.fmi.export.python import SYSTEM_FILE



class PythonSystem(Fmi2Slave):
    """The pickled system's inputs, outputs and step (a subclass names the model)."""

    description = "a discrete python-control system stepped in Python (attitude_fmu.export_fmu, backend='python')"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        with open(Path(self.resources) / SYSTEM_FILE, "rb") as file:
            self.system, self.x0, self.dt = pickle.load(file)
        self.x = np.array(self.x0, dtype=float)
        self.u = np.zeros(self.system.ninputs)
        self.y = np.zeros(self.system.noutputs)
        for i, label in enumerate(self.system.input_labels):
            self.register_variable(Real(label, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                                        getter=lambda i=i: float(self.u[i]),
                                        setter=lambda value, i=i: self.u.__setitem__(i, value)))
        for i, label in enumerate(self.system.output_labels):
            self.register_variable(Real(label, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                                        getter=lambda i=i: float(self.y[i])))

    def do_step(self, current_time, step_size):
        if not math.isclose(step_size, self.dt, rel_tol=1e-9):
            self.log(f"this system is discrete with sample time {self.dt!r} s; a step of {step_size!r} s is refused",
                     Fmi2Status.error)
            return False
        y = np.asarray(self.system._out(current_time, self.x, self.u), dtype=float).reshape(-1)
        x = np.asarray(self.system._rhs(current_time, self.x, self.u), dtype=float).reshape(-1)
        if not (np.isfinite(y).all() and np.isfinite(x).all()):
            self.log(f"t={current_time!r}: the system's outputs or next state are not finite; step refused",
                     Fmi2Status.error)
            return False
        self.y, self.x = y, x
        return True

    def _get_fmu_state(self) -> dict:  # FMU states: the system's state, its inputs and outputs
        return {"x": self.x.copy(), "u": self.u.copy(), "y": self.y.copy()}

    def _set_fmu_state(self, state: dict) -> None:
        self.x, self.u, self.y = (np.array(state[k], dtype=float) for k in ("x", "u", "y"))
