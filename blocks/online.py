"""Sample-by-sample estimation for co-simulation (the FMU): the batch path's compiled step,
one call per sample, with the sample time taken from each call."""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from .jit import kernel
from .methods import method as get_method, stepper
from .quaternion import quat_euler_zyx
from .sensor_frame import sensor_frame_step

IO_INPUTS = slice(0, 6)  # gyr x, y, z (rad/s), acc x, y, z (m/s²)
IO_OUTPUTS = slice(6, 16)  # q w, x, y, z; unit up x, y, z; roll, pitch, yaw (rad)


@kernel(inline=True)
def _finite_inputs(io):
    for i in range(6):
        if not math.isfinite(io[i]):
            return False
    return True


@kernel(inline=True)
def _write_outputs(io, q):
    """io[10:13] holds ĝ: normalise it; q and its Euler angles into io[6:10], io[13:16]."""
    norm = math.sqrt(io[10] * io[10] + io[11] * io[11] + io[12] * io[12])
    for i in range(3):
        io[10 + i] /= norm
    for i in range(4):
        io[6 + i] = q[i]
    io[13], io[14], io[15] = quat_euler_zyx((q[0], q[1], q[2], q[3]))


@kernel()
def online_step(X, q, Xr, io, Ad, Bd, C, D, Ts):
    """One sample through sensor_frame_step with its inputs in io[0:6]; writes io[6:16].

    Returns False, touching nothing, when an input is not finite. (The sensor-frame
    methods' path: one compiled call per sample.)
    """
    if not _finite_inputs(io):
        return False
    rows = io[0:6].reshape((2, 3))
    sensor_frame_step(X, q, rows[0:1], rows[1:2], 0, Ad, Bd, C, D, Ts, Xr, io[10:13].reshape((1, 3)))
    _write_outputs(io, q)
    return True


class OnlineEstimator:
    """State of one estimator between samples.

    method and params as for `attitude estimate`; they are validated here. Inputs go to
    io[0:6], outputs come from io[6:16] (see IO_INPUTS, IO_OUTPUTS). The filter starts
    at rest on the first accelerometer sample with non-zero norm, as the batch path
    starts on its first sample; until then `ready` is False.
    """

    def __init__(self, method: str = "wiener", params: Mapping[str, float] | None = None):
        get_method(method).resolve(params)  # refuse unknown methods and bad parameters now
        self.sensor_frame = get_method(method).is_sensor_frame
        self.method = method
        self.params = tuple(sorted((params or {}).items()))
        self.io = np.zeros(16)
        self._Ts = None
        self.reset()

    def reset(self) -> None:
        """Forget all samples."""
        self.state = None
        self._quat = np.zeros((1, 4))
        self.io[IO_OUTPUTS] = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)

    @property
    def ready(self) -> bool:
        return self.state is not None

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
            self._stepper, self._Ts = stepper(self.method, self.params, Ts), Ts
        if self.state is None:
            acc = self.io[3:6]
            if not (np.isfinite(self.io[IO_INPUTS]).all() and np.any(acc)):
                return False
            self.state = self._stepper.initial_state(acc)
            if self.sensor_frame:  # views of the state and scratch space, made once
                n = self._stepper.disc.order
                self._views = (self.state[: 3 * n].reshape(n, 3), self.state[3 * n:], np.empty((n, 3)))
        if self.sensor_frame:
            d = self._stepper.disc
            return online_step(*self._views, self.io, d.Ad, d.Bd, d.C, d.D, d.Ts)
        if not _finite_inputs(self.io):
            return False
        rows = self.io[0:6].reshape(2, 3)
        self._stepper.run(self.state, rows[0:1], rows[1:2], self.io[10:13].reshape(1, 3), self._quat)
        _write_outputs(self.io, self._quat[0])
        return True
