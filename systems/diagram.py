"""The closed-loop diagram motion → IMU sensor model → estimator → attitude error,
assembled from python-control blocks with control.interconnect."""
from __future__ import annotations

import control
import numpy as np

from blocks.methods import estimator_system, stepper
from blocks.sensor_frame import GRAVITY_OUTPUTS, QUAT_NAMES

from .errors import inclination_error
from .motion import AXES, HumanMotion
from .sensor_model import ImuModel

NOISE_INPUTS = [f"eps_{s}_{a}" for s in "vw" for a in AXES] + [f"{s}_{a}" for s in ("n", "na") for a in AXES]


def attitude_error_system(fs: float, name: str = "error"):
    """Static block: inclination error (rad) between ghat_* and the true up of qt_*."""
    def output(t, x, u, params):
        q = u[3:7]
        # true up in sensor coordinates: third row of R(q)
        up = [2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]),
              1 - 2 * (q[1] ** 2 + q[2] ** 2)]
        return [float(inclination_error(u[0:3], up))]

    return control.nlsys(None, output, inputs=GRAVITY_OUTPUTS + ["qt_w", "qt_x", "qt_y", "qt_z"],
                         outputs=["incl_err"], dt=1.0 / fs, name=name)


def closed_loop(motion: HumanMotion, imu: ImuModel, fs: float, method: str = "wiener",
                params: dict | None = None):
    """The diagram and its initial state (estimator at rest on g·ẑ, motion level at rest).

    Inputs: NOISE_INPUTS (unit-normal samples); outputs: incl_err (rad), ghat_*, q_*.
    """
    blocks = [motion.system(fs), imu.system(fs), estimator_system(method, params, 1.0 / fs),
              attitude_error_system(fs)]
    diagram = control.interconnect(
        blocks, inplist=NOISE_INPUTS, outlist=["incl_err"] + GRAVITY_OUTPUTS + QUAT_NAMES,
        name="closed_loop",
    )
    start = stepper(method, tuple(sorted((params or {}).items())), 1.0 / fs).initial_state([0.0, 0.0, motion.g])
    x0 = np.concatenate([motion.initial_state(), start])
    return diagram, x0


def simulate_closed_loop(motion: HumanMotion, imu: ImuModel, fs: float, duration: float,
                         method: str = "wiener", params: dict | None = None, seed: int = 0):
    """Short run of the diagram with fixed-seed noise: (noise N×9, response)."""
    diagram, x0 = closed_loop(motion, imu, fs, method, params)
    n = int(round(duration * fs))
    noise = np.random.default_rng(seed).standard_normal((n, len(NOISE_INPUTS)))
    t = np.arange(n) / fs
    return noise, control.input_output_response(diagram, t, noise.T, X0=x0)
