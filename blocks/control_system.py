"""Any per-sample step as a discrete-time python-control nonlinear I/O system."""
from __future__ import annotations

import numpy as np

REMEMBERED = 16  # steps (state, input) remembered: an interconnect asks a block for several inputs per step


def sample_system(advance, inputs, outputs, states, dt: float, name: str, start=None):
    """A discrete python-control system from advance(x, u) → (next state, output at k):
    the output at k is taken after the update with the inputs at k, as a batch path that
    writes each sample's estimate after taking it. python-control asks the update and the
    output function separately for one step: advance runs once per (x, u) and serves both.
    start(u) → the state to begin with at a first input u, used where x is all zeros
    (python-control's default initial state, no state a step can be in): the block then
    starts at rest on its first sample, as the batch path and the FMU do."""
    import control
    remembered: dict[tuple[bytes, bytes], tuple[np.ndarray, np.ndarray]] = {}

    def step(x, u):
        x, u = np.array(x, dtype=float), np.asarray(u, dtype=float)
        key = (x.tobytes(), u.tobytes())
        if key not in remembered:
            if start is not None and x.size and not x.any():
                x = np.array(start(u), dtype=float)
            state, output = advance(x, u)
            if len(remembered) >= REMEMBERED:
                remembered.pop(next(iter(remembered)))
            remembered[key] = (np.array(state, dtype=float), np.array(output, dtype=float))
        return remembered[key]

    return control.nlsys(lambda t, x, u, params: step(x, u)[0], lambda t, x, u, params: step(x, u)[1],
                         inputs=list(inputs), outputs=list(outputs), states=list(states), dt=dt, name=name)
