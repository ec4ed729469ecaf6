"""Attitude error measures shared by experiments, comparisons and evaluation."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def inclination_error(up_est, up_true) -> np.ndarray:
    """Angle (rad) between estimated and true up-vectors (N×3, any length), per sample."""
    up_est = np.asarray(up_est, dtype=float)
    up_true = np.asarray(up_true, dtype=float)
    cross = np.linalg.norm(np.cross(up_est, up_true), axis=-1)
    return np.arctan2(cross, np.einsum("...i,...i->...", up_est, up_true))


def earth_frame_error(gravity, quat_true, g: float) -> np.ndarray:
    """Gravity-estimate error in true earth coordinates, R_true·ĝ − g·ẑ (N×3, m/s²)."""
    return Rotation.from_quat(quat_true, scalar_first=True).apply(gravity) - [0.0, 0.0, g]


def bias_angle(up_est, quat_true) -> float:
    """Mean error (rad): tilt of the time-averaged estimated up, expressed in the true earth frame."""
    up = np.asarray(up_est, dtype=float)
    up = up / np.linalg.norm(up, axis=1, keepdims=True)
    mean_up = Rotation.from_quat(quat_true, scalar_first=True).apply(up).mean(axis=0)
    return float(np.arctan2(np.hypot(mean_up[0], mean_up[1]), mean_up[2]))


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))
