"""Sample-by-sample estimation for co-simulation (the FMU): the batch path's compiled step,
one call per sample, with the sample time taken from each call."""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from .jit import kernel
from .methods import discrete_filter, method as get_method
from .quaternion import quat_euler_zyx
from .sensor_frame import sensor_frame_step

IO_INPUTS = slice(0, 6)  # gyr x, y, z (rad/s), acc x, y, z (m/s²)
IO_OUTPUTS = slice(6, 16)  # q w, x, y, z; unit up x, y, z; roll, pitch, yaw (rad)


@kernel()
def online_step(X, q, Xr, io, Ad, Bd, C, D, Ts):
    """One sample through sensor_frame_step with its inputs in io[0:6]; writes io[6:16].

    Returns False, touching nothing, when an input is not finite.
    """
    for i in range(6):
        if not math.isfinite(io[i]):
            return False
    rows = io[0:6].reshape((2, 3))
    g = io[10:13].reshape((1, 3))
    sensor_frame_step(X, q, rows[0:1], rows[1:2], 0, Ad, Bd, C, D, Ts, Xr, g)
    norm = math.sqrt(io[10] * io[10] + io[11] * io[11] + io[12] * io[12])
    for i in range(3):
        io[10 + i] /= norm
    for i in range(4):
        io[6 + i] = q[i]
    io[13], io[14], io[15] = quat_euler_zyx((q[0], q[1], q[2], q[3]))
    return True


class OnlineEstimator:
    """State of one estimator between samples.

    method and params as for `attitude estimate`; they are validated here. Inputs go to
    io[0:6], outputs come from io[6:16] (see IO_INPUTS, IO_OUTPUTS). The filter starts
    at rest on the first accelerometer sample with non-zero norm, as the batch path
    starts on its first sample; until then `ready` is False.
    """

    def __init__(self, method: str = "wiener", params: Mapping[str, float] | None = None):
        get_method(method).filter(params)  # refuse unknown methods and bad parameters now
        self.method = method
        self.params = tuple(sorted((params or {}).items()))
        self.io = np.zeros(16)
        self._Ts = None
        self.reset()

    def reset(self) -> None:
        """Forget all samples."""
        self.X = None
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.io[IO_OUTPUTS] = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)

    @property
    def ready(self) -> bool:
        return self.X is not None

    def step(self, gyr, acc, Ts: float) -> bool:
        """Take one sample: gyr (rad/s) over the last Ts seconds, acc (m/s²) now."""
        self.io[0:3] = gyr
        self.io[3:6] = acc
        return self.step_io(Ts)

    def step_io(self, Ts: float) -> bool:
        """Take the sample in io[0:6] (Ts in s). Returns whether io[6:16] holds a new estimate:
        False for a non-finite input (the estimate is held) or before gravity was seen."""
        if Ts != self._Ts:
            if not (math.isfinite(Ts) and Ts > 0):
                raise ValueError(f"sample time must be a finite positive number of seconds, got {Ts!r}")
            self._disc, self._Ts = discrete_filter(self.method, self.params, Ts), Ts
        disc = self._disc
        if self.X is None:
            acc = self.io[3:6]
            if not (np.isfinite(self.io[IO_INPUTS]).all() and np.any(acc)):
                return False
            self.X = disc.rest_state(acc)
            self.Xr = np.empty_like(self.X)
        return online_step(self.X, self.q, self.Xr, self.io, disc.Ad, disc.Bd, disc.C, disc.D, disc.Ts)
