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


def quaternion_errors(quat_est, quat_ref):
    """Total, heading and inclination error (rad) per sample, as BROAD defines them:
    q_err = q_est ⊗ q_ref⁻¹ (earth frame); total 2·acos|w|, heading 2·atan|z/w|,
    inclination 2·acos√(w² + z²)."""
    err = (Rotation.from_quat(quat_est, scalar_first=True)
           * Rotation.from_quat(quat_ref, scalar_first=True).inv()).as_quat(scalar_first=True)
    w, z = np.abs(err[:, 0]), err[:, 3]
    total = 2 * np.arccos(np.clip(w, 0.0, 1.0))
    heading = 2 * np.arctan2(np.abs(z), w)
    inclination = 2 * np.arccos(np.clip(np.sqrt(w * w + z * z), 0.0, 1.0))
    return total, heading, inclination
