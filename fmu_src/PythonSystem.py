"""PythonSystem: the pythonfmu model of `export_fmu(..., backend="python")`: any discrete
python-control system, pickled (cloudpickle) into the FMU's resources as system.pickle with its
initial state and sample time, stepped by python-control's own update and output functions.

Its inputs and outputs are Real variables named after the system's labels. After the doStep that
ends at t[k+1], with the inputs of sample k held over it, the outputs are the system's outputs at
sample k (control.input_output_response's); before the first step, sample 0's. It runs on the grid of dt from the start time
(blocks.stages.timing.grid_samples): a step runs the samples it reaches, its inputs held, and one that
reaches none holds state and outputs. The FMU
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

from attitude_fmu.blocks.stages.timing import GRID_MAX_SAMPLES, grid_before, grid_samples
from attitude_fmu.systems.fmi.export.python import SYSTEM_FILE



class PythonSystem(Fmi2Slave):
    """The pickled system's inputs, outputs and step (a subclass names the model)."""

    description = "a discrete python-control system stepped in Python (attitude_fmu.export_fmu, backend='python')"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        with open(Path(self.resources) / SYSTEM_FILE, "rb") as file:
            self.system, self.x0, self.dt = pickle.load(file)
        self.x = np.array(self.x0, dtype=float)
        self.start_time = 0.0  # s: where the grid of dt begins
        self.u = np.zeros(self.system.ninputs)
        self.y = np.zeros(self.system.noutputs)
        self.stepped = False  # before the first step the outputs are sample 0's (start_outputs)
        for i, label in enumerate(self.system.input_labels):
            self.register_variable(Real(label, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                                        getter=lambda i=i: float(self.u[i]),
                                        setter=lambda value, i=i: self.u.__setitem__(i, value)))
        for i, label in enumerate(self.system.output_labels):
            self.register_variable(Real(label, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                                        getter=lambda i=i: float(self._outputs()[i])))

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self.start_time = float(start_time)

    def do_step(self, current_time, step_size):
        start, dt = self.start_time, self.dt
        n = grid_samples(start, dt, current_time, step_size) if math.isfinite(current_time + step_size) else math.inf
        if n > GRID_MAX_SAMPLES:
            self.log(f"a step of {step_size!r} s from t={current_time!r} reaches {n:.0f} samples of the system's "
                     f"sample time {dt!r} s; one step runs {GRID_MAX_SAMPLES:.0f} at most: step refused",
                     Fmi2Status.error)
            return False
        first = grid_before(start, dt, current_time)
        x, y = self.x, self.y
        for k in range(int(n)):
            t = first + k * dt
            y = np.asarray(self.system._out(t, x, self.u), dtype=float).reshape(-1)
            x = np.asarray(self.system._rhs(t, x, self.u), dtype=float).reshape(-1)
            if not (np.isfinite(y).all() and np.isfinite(x).all()):
                self.log(f"t={t!r}: the system's outputs or next state are not finite; step refused",
                         Fmi2Status.error)
                return False
        self.y, self.x, self.stepped = y, x, True
        return True

    def _outputs(self) -> np.ndarray:
        """The outputs: after a step, its; before the first, sample 0's at the initial state and the inputs as
        they are (what a Jacobi master reads before any step; the first step gives them again), or the zeros
        they start at where the system's output function fails or is not finite there."""
        if self.stepped:
            return self.y
        try:
            y = np.asarray(self.system._out(self.start_time, self.x, self.u), dtype=float).reshape(-1)
        except Exception:  # never raise into pythonfmu (it answers fmi2Fatal); the first step reports it
            return self.y
        return y if y.shape == self.y.shape and np.isfinite(y).all() else self.y

    def _get_fmu_state(self) -> dict:  # FMU states: the system's state, its inputs and outputs
        return {"x": self.x.copy(), "u": self.u.copy(), "y": self.y.copy(), "stepped": self.stepped}

    def _set_fmu_state(self, state: dict) -> None:
        self.x, self.u, self.y = (np.array(state[k], dtype=float) for k in ("x", "u", "y"))
        self.stepped = bool(state["stepped"])
