"""Batch estimation over whole recordings, running the compiled step of the blocks."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from blocks.methods import stepper


@dataclass
class AttitudeEstimate:
    """Per-sample output of an estimator.

    gravity: N×3 gravity estimate ĝ in sensor coordinates, m/s² (points up);
    quat: N×4 orientation [w, x, y, z], sensor → earth (heading from integrated gyro).
    """

    gravity: np.ndarray
    quat: np.ndarray

    @property
    def up(self) -> np.ndarray:
        """N×3 unit up-vector in sensor coordinates."""
        return self.gravity / np.linalg.norm(self.gravity, axis=1, keepdims=True)


def check_imu(gyr, acc, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Validated contiguous float copies of N×3 gyro (rad/s) and accelerometer (m/s²)."""
    if not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0):
        raise ValueError(f"sample rate fs must be a finite positive number of Hz, got {fs!r}")
    arrays = []
    for name, data in (("gyr", gyr), ("acc", acc)):
        a = np.asarray(data, dtype=float)
        if a.ndim != 2 or a.shape[1] != 3 or a.shape[0] == 0:
            raise ValueError(f"{name} must have shape (N, 3) with N ≥ 1, got {a.shape}")
        bad = ~np.isfinite(a)
        if bad.any():
            row = int(np.argwhere(bad)[0][0])
            raise ValueError(f"{name} has {int(bad.sum())} non-finite values (first at sample {row})")
        arrays.append(np.ascontiguousarray(a))
    if arrays[0].shape != arrays[1].shape:
        raise ValueError(f"gyr and acc differ in length: {arrays[0].shape[0]} vs {arrays[1].shape[0]}")
    return arrays[0], arrays[1]


def estimate(
    gyr, acc, fs: float, method: str = "wiener", params: Mapping[str, float] | None = None,
    initial_gravity=None,
) -> AttitudeEstimate:
    """Estimate attitude over a recording: gyr N×3 rad/s, acc N×3 m/s², fs in Hz.

    params are the method's documented parameters (see blocks.methods), defaults
    otherwise. The filter starts at rest on initial_gravity (m/s², sensor coordinates),
    by default the first accelerometer sample.
    """
    gyr, acc = check_imu(gyr, acc, fs)
    step = stepper(method, tuple(sorted((params or {}).items())), 1.0 / fs)
    state = step.initial_state(acc[0] if initial_gravity is None else initial_gravity)
    gravity = np.empty_like(acc)
    quat = np.empty((acc.shape[0], 4))
    step.run(state, gyr, acc, gravity, quat)
    return AttitudeEstimate(gravity, quat)
