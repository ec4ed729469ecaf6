"""The causal pipeline one sample at a time (co-simulation: the FMU's doStep), with the
sample time taken from each call: the C core's online estimator (blocks/core/pipeline/online.h)."""
from __future__ import annotations

from typing import Mapping

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.pipeline.causal import configure

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
    Copies (copy.deepcopy, pickle: an FMU's saved state) carry every stage's state.
    """

    def __init__(self, method: str = "wiener", params: Mapping[str, float] | None = None, heading: bool = False,
                 gyro_offset: bool = True, latency: float = 0.0, gyr_samples: str = "mean",
                 acc_samples: str = "point"):
        self.pipeline = configure(method, params, gyro_offset, heading, latency, gyr_samples, acc_samples)
        self._online = _core.Online(self.pipeline.core)

    def reset(self) -> None:
        """Forget all samples."""
        self._online.reset()

    @property
    def ready(self) -> bool:
        return self._online.started

    @property
    def quat(self) -> np.ndarray:
        """The orientation after the last sample taken, sensor → earth [w, x, y, z] (identity before one)."""
        return self._online.quat

    @property
    def up(self) -> np.ndarray:
        """The unit up-vector after the last sample taken, sensor coordinates (ẑ before one)."""
        return self._online.up

    @property
    def euler(self) -> np.ndarray:
        """Roll, pitch, yaw (rad, Z-Y-X) of quat."""
        return self._online.euler

    @property
    def offset(self) -> np.ndarray:
        """The gyro-offset estimate after the last sample taken (rad/s; 0 without that stage or before a sample)."""
        return self._online.offset

    @property
    def mag_offset(self) -> np.ndarray:
        """The magnetometer's hard-iron offset estimate (µT, blocks.stages.hard_iron; 0 until one is proven)."""
        return self._online.mag_offset

    @property
    def mag_delay(self) -> float:
        """The magnetometer's delay behind the gyro the heading allows for (s; the parameter
        mag_delay from the first step on, or blocks.stages.mag_delay's online estimate: 0
        until one is taken)."""
        return self._online.mag_delay

    def step(self, gyr, acc, Ts: float, mag=NO_FIELD) -> bool:
        """Take one sample: gyr (rad/s) over the last Ts seconds, acc (m/s²) and mag (µT)
        now. Returns whether it was taken (the estimate is new). A Ts within
        blocks.stages.timing.STEP_TOLERANCE of the last one keeps its discretisation."""
        return self._online.step(gyr, acc, Ts, mag, self.pipeline.holds)
