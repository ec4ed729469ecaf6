"""The causal pipeline one sample at a time (co-simulation: the FMU's doStep), with the
sample time taken from each call."""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from attitude_fmu.blocks.pipeline.causal import Rows, State, at, configure, run, valid_sample
from attitude_fmu.blocks.quaternion import quat_euler_zyx
from attitude_fmu.blocks.stages.heading import HARD_IRON_OFFSET, MAG_DELAY_IN_USE
from attitude_fmu.blocks.stages.timing import same_step

NO_FIELD = (0.0, 0.0, 0.0)  # a magnetometer input with no sample (NaN works too)


class OnlineEstimator:
    """The pipeline of `attitude estimate` (blocks.pipeline.causal) between samples.

    method, params, gyro_offset, heading (a magnetometer is given), latency (s),
    gyr_samples and acc_samples as for blocks.pipeline.causal.configure, validated here.
    step() takes one sample; its estimate is then in quat, up, euler, offset, mag_offset
    and mag_delay. A sample with a gyro or accelerometer value that is not finite or beyond
    every IMU's range (blocks.pipeline.causal.valid_sample) is not taken: the estimate is held;
    a finite gyro point sample still counts as the one before the next.
    The stages start at rest on the first sample whose accelerometer is not all zero,
    as the batch path starts on its first sample; until then `ready` is False.
    """

    def __init__(self, method: str = "wiener", params: Mapping[str, float] | None = None, heading: bool = False,
                 gyro_offset: bool = True, latency: float = 0.0, gyr_samples: str = "mean",
                 acc_samples: str = "point"):
        self.pipeline = configure(method, params, gyro_offset, heading, latency, gyr_samples, acc_samples)
        self._step = None  # the pipeline at the last sample time
        self._rows = Rows.empty(self.pipeline, 1)
        self.reset()

    def __getstate__(self) -> dict:
        """For copies (an FMU's saved state): all but the discretisation, which the next step makes again."""
        return {**self.__dict__, "_step": None}

    def reset(self) -> None:
        """Forget all samples."""
        self.state = State()
        self.quat = np.array([1.0, 0.0, 0.0, 0.0])  # sensor → earth
        self.up = np.array([0.0, 0.0, 1.0])  # unit up-vector, sensor coordinates
        self.euler = np.zeros(3)  # roll, pitch, yaw (rad, Z-Y-X) of quat

    @property
    def ready(self) -> bool:
        return self.state.method is not None

    @property
    def offset(self) -> np.ndarray:
        """The gyro-offset estimate after the last sample taken (rad/s; 0 without that stage or before a sample)."""
        if self.pipeline.offset_params is None or not self.ready:
            return np.zeros(3)
        return self._rows.offset[0].copy()

    @property
    def mag_offset(self) -> np.ndarray:
        """The magnetometer's hard-iron offset estimate (µT, blocks.stages.hard_iron; 0 until one is proven)."""
        return self.state.heading[HARD_IRON_OFFSET:HARD_IRON_OFFSET + 3].copy()

    @property
    def mag_delay(self) -> float:
        """The magnetometer's delay behind the gyro the heading allows for (s; the parameter
        mag_delay from the first step on, or blocks.stages.mag_delay's online estimate: 0
        until one is taken)."""
        return float(self.state.heading[MAG_DELAY_IN_USE])

    def step(self, gyr, acc, Ts: float, mag=NO_FIELD) -> bool:
        """Take one sample: gyr (rad/s) over the last Ts seconds, acc (m/s²) and mag (µT)
        now. Returns whether it was taken (the estimate is new). A Ts within
        blocks.stages.timing.STEP_TOLERANCE of the last one keeps its discretisation."""
        if self._step is None or not same_step(Ts, self._step.Ts):
            self._step = at(self.pipeline, Ts)
        gyr = np.array(gyr, dtype=float).reshape(1, 3)
        acc = np.array(acc, dtype=float).reshape(1, 3)
        if not (valid_sample(gyr[0], acc[0]) and (self.ready or acc.any())):
            if self.pipeline.point_gyr and np.isfinite(gyr).all():
                self.state.last_gyr = gyr[0]
            return False
        mag = np.array(mag, dtype=float).reshape(1, 3) if self.pipeline.heading_params is not None else None
        rows = run(self.pipeline, self._step, self.state, gyr, acc, mag, out=self._rows)
        self.quat = rows.quat[0].copy()
        self.up = rows.gravity[0] / math.sqrt(rows.gravity[0] @ rows.gravity[0])
        self.euler = np.array(quat_euler_zyx((self.quat[0], self.quat[1], self.quat[2], self.quat[3])))
        return True
