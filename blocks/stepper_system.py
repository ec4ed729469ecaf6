"""Any estimator's stepper as a discrete-time python-control nonlinear I/O system."""
from __future__ import annotations

import control
import numpy as np

INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]
OUTPUTS = [f"ghat_{a}" for a in "xyz"] + ["q_w", "q_x", "q_y", "q_z"]


def sample_system(advance, inputs, outputs, states, dt: float, name: str):
    """A discrete python-control system from advance(x, u) → (next state, output at k):
    the output at k is taken after the update with the inputs at k, as a batch path that
    writes each sample's estimate after taking it."""
    def step(x, u):
        return advance(np.array(x, dtype=float), np.asarray(u, dtype=float))

    return control.nlsys(lambda t, x, u, params: step(x, u)[0], lambda t, x, u, params: step(x, u)[1],
                         inputs=list(inputs), outputs=list(outputs), states=list(states), dt=dt, name=name)


def stepper_system(stepper, dt: float, name: str = "estimator"):
    """Inputs gyr_x..z (rad/s), acc_x..z (m/s²); outputs ghat_x..z (m/s²) and q_w..q_z,
    equal to the batch path's estimate at k; x0 should come from stepper.initial_state."""
    def advance(state, u):
        gravity, quat = np.empty((1, 3)), np.empty((1, 4))
        stepper.run(state, u[0:3].reshape(1, 3).copy(), u[3:6].reshape(1, 3).copy(), gravity, quat)
        return state, np.concatenate([gravity[0], quat[0]])

    return sample_system(advance, INPUTS, OUTPUTS, stepper.state_names, dt, name)
