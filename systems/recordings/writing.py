"""Estimates out: the CSV writer and its columns."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

OUTPUT_COLUMNS = ("t", "q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z")
EULER_COLUMNS = ("roll_deg", "pitch_deg", "yaw_deg")  # with --euler


def euler_degrees(quat) -> np.ndarray:
    """Roll, pitch, yaw (N×3, degrees) of quaternions (N×4, w first, sensor → earth): the
    Z-Y-X sequence, as the AttitudeEstimator FMU's outputs roll, pitch, yaw."""
    return Rotation.from_quat(quat, scalar_first=True).as_euler("ZYX", degrees=True)[:, ::-1]


def write_estimate(path, t, quat, up, euler: bool = False, extra=None) -> None:
    """CSV with columns t,q_w,q_x,q_y,q_z,g_x,g_y,g_z (g the unit up-vector, sensor
    coordinates); euler adds roll, pitch and yaw in degrees (EULER_COLUMNS, euler_degrees);
    extra ({name: N×3 or N}) adds name_x,name_y,name_z, or the column name, after them."""
    columns, table = OUTPUT_COLUMNS, [t, quat, up]
    if euler:
        columns = columns + EULER_COLUMNS
        table.append(euler_degrees(quat))
    for name, values in (extra or {}).items():
        columns = columns + ((name,) if np.ndim(values) == 1 else tuple(f"{name}_{a}" for a in "xyz"))
        table.append(values)
    np.savetxt(path, np.column_stack(table), delimiter=",", header=",".join(columns), comments="", fmt="%.10g")
