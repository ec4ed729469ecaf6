"""Sample-by-sample estimation for co-simulation (the FMU): the batch path's compiled step,
one call per sample, with the sample time taken from each call."""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from .gyro_offset import coefficients as offset_coefficients
from .gyro_offset import initial_state as offset_initial_state
from .gyro_offset import resolve as offset_resolve
from .gyro_offset import run as offset_run
from .heading import HARD_IRON_OFFSET, MAG_DELAY_IN_USE
from .heading import coefficients as heading_coefficients
from .heading import heading_step
from .heading import initial_state as heading_initial_state
from .heading import resolve as heading_resolve
from .jit import kernel
from .timing import carry_forward, check_latency, check_samples, interval_end, interval_mean
from .methods import method as get_method, stepper
from .quaternion import quat_euler_zyx
from .sensor_frame import SensorFrameStepper, sensor_frame_step, start_gravity
from .stages import split_params

IO_INPUTS = slice(0, 6)  # gyr x, y, z (rad/s), acc x, y, z (m/s²)
IO_OUTPUTS = slice(6, 16)  # q w, x, y, z; unit up x, y, z; roll, pitch, yaw (rad)
IO_MAG = slice(16, 19)  # magnetic field x, y, z (µT), for heading=True
# relative difference below which two sample times are one: a master that keeps time in
# integer nanoseconds, or sums steps in floating point, hands over Ts with rounding noise
STEP_TOLERANCE = 1e-9


def same_step(Ts: float, reference: float) -> bool:
    """Whether the sample time Ts (s) is reference (s) up to STEP_TOLERANCE."""
    return abs(Ts - reference) <= STEP_TOLERANCE * reference


@kernel(inline=True)
def _finite_inputs(io):
    for i in range(6):
        if not math.isfinite(io[i]):
            return False
    return True


@kernel(inline=True)
def _write_outputs(io, q, heading_state, heading_coef, heading, latency):
    """io[10:13] holds ĝ: normalise it; q, turned to the magnetometer's heading when asked
    (io[16:19] not finite or all 0: no new field sample), both carried forward over latency
    (s) with the gyro in io[0:3] (blocks.timing), and q's Euler angles into io[6:10],
    io[13:16]."""
    norm = math.sqrt(io[10] * io[10] + io[11] * io[11] + io[12] * io[12])
    for i in range(3):
        io[10 + i] /= norm
    out = (q[0], q[1], q[2], q[3])
    if heading:
        out, used = heading_step(heading_state, heading_coef, out, (io[16], io[17], io[18]))
    if latency != 0.0:
        out, up = carry_forward(out, (io[10], io[11], io[12]), (io[0], io[1], io[2]), latency)
        io[10], io[11], io[12] = up
    io[6], io[7], io[8], io[9] = out
    io[13], io[14], io[15] = quat_euler_zyx(out)


@kernel()
def online_step(X, q, Xr, io, Ad, Bd, C, D, Ts, heading_state, heading_coef, heading, latency):
    """One sample through sensor_frame_step with its inputs in io[0:6] (io[16:19] the
    field); writes io[6:16]. Returns False, touching nothing, when an input is not finite.
    (The sensor-frame methods' path: one compiled call per sample.)
    """
    if not _finite_inputs(io):
        return False
    rows = io[0:6].reshape((2, 3))
    sensor_frame_step(X, q, rows[0:1], rows[1:2], 0, Ad, Bd, C, D, Ts, Xr, io[10:13].reshape((1, 3)))
    _write_outputs(io, q, heading_state, heading_coef, heading, latency)
    return True


@kernel()
def finish_outputs(io, q, heading_state, heading_coef, heading, latency):
    """The other methods' path: _write_outputs after their own step."""
    _write_outputs(io, q, heading_state, heading_coef, heading, latency)


class OnlineEstimator:
    """State of one estimator between samples.

    method and params as for `attitude estimate`; they are validated here. Inputs go to
    io[0:6] (and the magnetometer to io[16:19] with heading=True: blocks.heading, as the
    batch path's mag argument), outputs come from io[6:16] (see IO_*). gyro_offset=True:
    the gyro offset is estimated and removed first (blocks.gyro_offset, as the batch
    path's gyro_offset argument). latency (s): the outputs are carried forward over the
    IMU's delay (blocks.timing, as the batch path's latency argument); gyr_samples "point":
    each gyro input is the rate at the sample's time, averaged with the last finite one
    into the mean over the sample time (blocks.timing.interval_means); acc_samples "mean":
    each accelerometer input is the mean over the sample time, turned into the sensor frame
    at its end (blocks.timing.interval_end). The filter starts
    at rest on the first accelerometer sample with non-zero norm, as the batch path starts
    on its first sample; until then `ready` is False.
    """

    def __init__(self, method: str = "wiener", params: Mapping[str, float] | None = None, heading: bool = False,
                 gyro_offset: bool = False, latency: float = 0.0, gyr_samples: str = "mean",
                 acc_samples: str = "point"):
        params, offset_params, heading_params = split_params(method, params, gyro_offset, heading)
        m = get_method(method)
        m.runs_kernel(m.resolve(params))  # refuse bad parameters now
        self.method = method
        self.params = tuple(sorted(params.items()))
        self._offset_params, self._heading_params = offset_resolve(offset_params), heading_resolve(heading_params)
        self.heading = heading
        self.gyro_offset = gyro_offset
        self.latency = check_latency(latency)
        gyr_samples, acc_samples = check_samples(gyr_samples, acc_samples)
        self.point_samples, self.mean_acc = gyr_samples == "point", acc_samples == "mean"
        self.offset = np.zeros((2, 3))  # offset estimate (rad/s) and its variance ((rad/s)²)
        self.io = np.zeros(19)
        self._Ts = None
        self.reset()

    def __getstate__(self) -> dict:
        """For copies (an FMU's saved state): everything but what the sample time derives
        (stepper, coefficients, views of the state), which the next step makes again."""
        derived = ("_stepper", "_heading_coef", "_offset_coef", "_views", "sensor_frame")
        return {**{k: v for k, v in self.__dict__.items() if k not in derived}, "_Ts": None}

    def reset(self) -> None:
        """Forget all samples."""
        self.state = None
        self._last_gyr = None  # the last finite gyro input (point samples)
        self._quat = np.zeros((1, 4))
        self._heading_state = heading_initial_state()
        self.io[IO_OUTPUTS] = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)

    @property
    def ready(self) -> bool:
        return self.state is not None

    @property
    def mag_offset(self) -> np.ndarray:
        """The magnetometer's hard-iron offset estimate (µT, blocks.hard_iron; 0 until one is proven)."""
        return self._heading_state[HARD_IRON_OFFSET:HARD_IRON_OFFSET + 3]

    @property
    def mag_delay(self) -> float:
        """The magnetometer's delay behind the gyro the heading allows for (s; the parameter
        mag_delay from the first step on, or blocks.mag_delay's online estimate: 0 until one
        is taken)."""
        return float(self._heading_state[MAG_DELAY_IN_USE])

    def step(self, gyr, acc, Ts: float, mag=(0.0, 0.0, 0.0)) -> bool:
        """Take one sample: gyr (rad/s) over the last Ts seconds, acc (m/s²) and mag (µT) now."""
        self.io[0:3] = gyr
        self.io[3:6] = acc
        self.io[IO_MAG] = mag
        return self.step_io(Ts)

    def step_io(self, Ts: float) -> bool:
        """Take the sample in io[0:6] (and io[16:19] with heading; Ts in s). Returns whether
        io[6:16] holds a new estimate: False for a non-finite input (the estimate is held)
        or before gravity was seen. A Ts within STEP_TOLERANCE of the last one keeps its
        discretisation."""
        if self._Ts is None or not same_step(Ts, self._Ts):
            if not (math.isfinite(Ts) and Ts > 0):
                raise ValueError(f"sample time must be a finite positive number of seconds, got {Ts!r}")
            self._stepper, self._Ts = stepper(self.method, self.params, Ts), Ts
            self.sensor_frame = isinstance(self._stepper, SensorFrameStepper)
            self._heading_coef = heading_coefficients(self._heading_params, Ts)
            if self.gyro_offset:
                self._offset_coef = offset_coefficients(self._offset_params, Ts)
            self._views = None

        if self.point_samples and np.isfinite(self.io[0:3]).all():
            raw = self.io[0:3].copy()
            if self._last_gyr is not None:
                self.io[0:3] = interval_mean(self._last_gyr, raw)
            self._last_gyr = raw
        if self.mean_acc:
            self.io[3:6] = interval_end(tuple(self.io[0:3]), tuple(self.io[3:6]), Ts)
        starting = self.state is None
        if starting:
            if not (np.isfinite(self.io[IO_INPUTS]).all() and np.any(self.io[3:6])):
                return False
            if self.gyro_offset:
                self._offset_state = offset_initial_state(self._offset_coef, self.io[0:3], self.io[3:6])
        if self.gyro_offset:  # the offset estimate after this sample, removed from the gyro
            if not np.isfinite(self.io[IO_INPUTS]).all():
                return False
            rows = self.io[0:6].reshape(2, 3)
            offset_run(self._offset_state, self._offset_coef, rows[0:1], rows[1:2], self.offset[0:1], self.offset[1:2])
            self.io[0:3] -= self.offset[0]
        if starting:
            self.state = self._stepper.initial_state(start_gravity(self.io[0:3], self.io[3:6], Ts))
            self._views = None
        if self.sensor_frame:
            d = self._stepper.disc
            if self._views is None:  # views of the state and scratch space, made once per state and Ts
                n = d.order
                self._views = (self.state[: 3 * n].reshape(n, 3), self.state[3 * n:], np.empty((n, 3)))
            return online_step(*self._views, self.io, d.Ad, d.Bd, d.C, d.D, d.Ts,
                               self._heading_state, self._heading_coef, self.heading, self.latency)
        if not np.isfinite(self.io[IO_INPUTS]).all():
            return False
        rows = self.io[0:6].reshape(2, 3)
        self._stepper.run(self.state, rows[0:1], rows[1:2], self.io[10:13].reshape(1, 3), self._quat)
        finish_outputs(self.io, self._quat[0], self._heading_state, self._heading_coef, self.heading,
                       self.latency)
        return True
