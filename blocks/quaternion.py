"""Scalar quaternion kernels ([w, x, y, z], scalar first), compiled with numba.

They sit in the estimators' per-sample steps, where scipy's Rotation would cost
microseconds per call; quaternions pass as 4-tuples of floats and vectors as 3-tuples.
Tests check every kernel against scipy.spatial.transform.Rotation.
"""
from __future__ import annotations

import math

from attitude_fmu.blocks.jit import kernel

SERIES_ANGLE2 = 1e-2  # (rad)²: below it the half-angle series to θ⁸ is exact to double precision


@kernel(inline=True)
def rotvec_quat(rx, ry, rz):
    """Quaternion of the rotation vector (rx, ry, rz), rad."""
    angle2 = rx * rx + ry * ry + rz * rz
    if angle2 < SERIES_ANGLE2:
        # cos(θ/2) and sin(θ/2)/θ by their Taylor series; the first term left out is
        # below 3e-20 for θ < 0.1 rad
        c = 1.0 - angle2 / 8.0 * (1.0 - angle2 / 48.0 * (1.0 - angle2 / 120.0 * (1.0 - angle2 / 224.0)))
        s = 0.5 * (1.0 - angle2 / 24.0 * (1.0 - angle2 / 80.0 * (1.0 - angle2 / 168.0 * (1.0 - angle2 / 288.0))))
    else:
        angle = math.sqrt(angle2)
        c = math.cos(0.5 * angle)
        s = math.sin(0.5 * angle) / angle
    return c, rx * s, ry * s, rz * s


@kernel(inline=True)
def quat_multiply(p, q):
    """Hamilton product p ⊗ q."""
    return (
        p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
        p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
        p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
        p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0],
    )


@kernel(inline=True)
def quat_rotate(q, v):
    """Vector v rotated by the unit quaternion q (sensor coordinates → earth for q sensor → earth)."""
    w, x, y, z = q
    tx = 2.0 * (y * v[2] - z * v[1])
    ty = 2.0 * (z * v[0] - x * v[2])
    tz = 2.0 * (x * v[1] - y * v[0])
    return (
        v[0] + w * tx + y * tz - z * ty,
        v[1] + w * ty + z * tx - x * tz,
        v[2] + w * tz + x * ty - y * tx,
    )


@kernel(inline=True)
def quat_matrix(q):
    """The rotation matrix of the unit quaternion q, row-major (9-tuple)."""
    w, x, y, z = q
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


@kernel(inline=True)
def quat_normalized(q):
    """q scaled to unit norm."""
    inv = 1.0 / math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv


@kernel(inline=True)
def level_quat(u, norm):
    """Smallest rotation taking the vector u (length norm > 0) onto +z (earth up).

    Returned with an arbitrary positive scale: normalise the product it enters. For u
    along −z (upside down, no horizontal part) it is the half turn about x.
    """
    horizontal2 = u[0] * u[0] + u[1] * u[1]
    if u[2] >= 0.0:
        w = norm + u[2]
    elif horizontal2 < 1e-30 * norm * norm:
        return 0.0, 1.0, 0.0, 0.0
    else:
        w = horizontal2 / (norm - u[2])  # = norm + u[2], without cancellation
    return w, u[1], -u[0], 0.0


@kernel(inline=True)
def quat_euler_zyx(q):
    """Roll, pitch, yaw (rad) of the Z-Y-X (yaw, then pitch, then roll) sequence of unit q."""
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(min(1.0, max(-1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


@kernel(inline=True)
def up_in_sensor(q):
    """Earth up (+z) in sensor coordinates for the unit quaternion q (sensor → earth): R(q)ᵀ·ẑ."""
    return quat_rotate((q[0], -q[1], -q[2], -q[3]), (0.0, 0.0, 1.0))


@kernel(inline=True)
def write_sample(gravity, quat, k, g, up, q):
    """Row k of a kernel method's output: gravity g·up (m/s²) and the orientation q."""
    gravity[k, 0], gravity[k, 1], gravity[k, 2] = g * up[0], g * up[1], g * up[2]
    quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q[0], q[1], q[2], q[3]


@kernel()
def integrate_rates(gyr, Ts, quat):
    """quat[k] (N×4): the orientation after gyro sample k (N×3 mean rates, rad/s, over Ts
    seconds each) from the identity before the first, q ← q ⊗ exp(ω·Ts)."""
    q = (1.0, 0.0, 0.0, 0.0)
    for k in range(gyr.shape[0]):
        q = quat_normalized(quat_multiply(q, rotvec_quat(gyr[k, 0] * Ts, gyr[k, 1] * Ts, gyr[k, 2] * Ts)))
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q[0], q[1], q[2], q[3]
