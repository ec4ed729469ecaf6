"""Motions for the tests, made from closed forms of orientation and velocity with scipy's
Rotation alone (independent of the simulation under test), sampled as docs/conventions.md
says: over (t − h, t], gyr is the rotation vector of R(t−h)ᵀ·R(t) over h (integrating it gives
R exactly) and acc the specific force R(t)ᵀ·((v(t) − v(t−h))/h + g·ẑ)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.simulation.motion import Motion


def still(t) -> np.ndarray:
    """No velocity (m/s): the sensor turns in place."""
    return np.zeros((len(np.atleast_1d(t)), 3))


@dataclass(frozen=True)
class ClosedFormMotion:
    """orientation: t (s, N) → Rotation (sensor → earth, N); velocity: t → N×3 earth-frame velocity (m/s)."""

    orientation: Callable[[np.ndarray], Rotation]
    velocity: Callable[[np.ndarray], np.ndarray] = still
    g: float = 9.81

    def at(self, t, h: float):
        """(gyr N×3, specific force N×3, quat N×4) for the intervals ending at times t."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        now, before = self.orientation(t), self.orientation(t - h)
        gyr = (before.inv() * now).as_rotvec() / h
        acc = (self.velocity(t) - self.velocity(t - h)) / h + [0.0, 0.0, self.g]
        return gyr, now.inv().apply(acc), now.as_quat(scalar_first=True)

    def generate(self, duration: float, fs: float, seed: int = 0) -> Motion:
        """duration (s) sampled at fs (Hz), t = 1/fs, 2/fs, …; seed unused (for the simulation's signature)."""
        gyr, acc, quat = self.at(np.arange(1, int(round(duration * fs)) + 1) / fs, 1.0 / fs)
        return Motion(fs, quat, gyr, acc)


def turning(angles: Callable[[np.ndarray], np.ndarray]) -> ClosedFormMotion:
    """Turning in place through Z-Y-X angles (rad, N×3: yaw, pitch, roll) of t."""
    return ClosedFormMotion(lambda t: Rotation.from_euler("ZYX", angles(np.atleast_1d(t))))
