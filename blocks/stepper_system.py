"""Any estimator's stepper as a discrete-time python-control nonlinear I/O system."""
from __future__ import annotations

import control
import numpy as np

INPUTS = [f"{s}_{a}" for s in ("gyr", "acc") for a in "xyz"]
OUTPUTS = [f"ghat_{a}" for a in "xyz"] + ["q_w", "q_x", "q_y", "q_z"]


def stepper_system(stepper, dt: float, name: str = "estimator"):
    """Inputs gyr_x..z (rad/s), acc_x..z (m/s²); outputs ghat_x..z (m/s²) and q_w..q_z.

    The output at k is taken after the update with the inputs at k, so it equals the
    batch path's estimate at k; x0 should come from stepper.initial_state.
    """
    def advance(x, u):
        state = np.array(x, dtype=float)
        gravity, quat = np.empty((1, 3)), np.empty((1, 4))
        u = np.asarray(u, dtype=float)
        stepper.run(state, u[0:3].reshape(1, 3).copy(), u[3:6].reshape(1, 3).copy(), gravity, quat)
        return state, np.concatenate([gravity[0], quat[0]])

    return control.nlsys(
        lambda t, x, u, params: advance(x, u)[0], lambda t, x, u, params: advance(x, u)[1],
        inputs=INPUTS, outputs=OUTPUTS, states=list(stepper.state_names), dt=dt, name=name,
    )
