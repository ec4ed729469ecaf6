"""Luinge's tilt Kalman filter (Luinge, Veltink, Baten; Fig. 1 of the seed paper).

(1) integrate the gyro to an orientation q; (2) the accelerometer's up-vector; (3) the
tilt difference between the two, split from the rotation α about the vertical; (5) a
linear 2-state Kalman filter on that difference with prediction ΔT = 0; (4) rebuild the
orientation from the corrected tilt and the unchanged α.

The paper writes tilt as T = (acos Z_s,x, acos Z_s,y), which degenerates when a sensor
axis is vertical. Here the tilt difference is the horizontal earth-frame rotation vector
taking the measured up (seen through q) onto earth up: equal to first order, free of
singularities, and its correction (a rotation about a horizontal axis) leaves α alone.
Per axis: P⁻ = P + Q with Q = δn²/2·Ts (eq. 10 of Rizun), K = P⁻/(P⁻ + σ_T²), P = (1−K)·P⁻.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.quaternion import (
    quat_multiply,
    quat_normalized,
    quat_rotate,
    rotvec_quat,
    up_in_sensor,
    write_sample,
)

STATE_NAMES = ("q_w", "q_x", "q_y", "q_z", "P_x", "P_y")  # orientation; KF variances (rad²)


def coefficients(params, Ts: float) -> np.ndarray:
    """[Q (rad² per sample), R = tilt_sd² (rad²), Ts (s), g (m/s²)]."""
    return np.array([params["delta_n"] ** 2 / 2.0 * Ts, params["tilt_sd"] ** 2, Ts, params["g"]])


def initial_state(coef, acc0) -> np.ndarray:
    """Level on acc0 (heading 0), tilt variance R (the accelerometer's own)."""
    from attitude_fmu.blocks.methods.mahony import level_on

    return np.concatenate([level_on(acc0), [coef[1], coef[1]]])


@kernel(inline=True)
def luinge_step(state, Q, R, Ts, gyr, acc, k):
    """One sample on state [q, P_x, P_y] in place; returns the unit up estimate."""
    q = quat_multiply((state[0], state[1], state[2], state[3]),
                      rotvec_quat(gyr[k, 0] * Ts, gyr[k, 1] * Ts, gyr[k, 2] * Ts))
    a0, a1, a2 = acc[k, 0], acc[k, 1], acc[k, 2]
    norm = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    if norm > 0.0:
        v = quat_rotate(q, (a0 / norm, a1 / norm, a2 / norm))  # measured up, earth frame
        horizontal = math.sqrt(v[0] * v[0] + v[1] * v[1])
        scale = math.atan2(horizontal, v[2]) / horizontal if horizontal > 1e-15 else 1.0
        z0, z1 = v[1] * scale, -v[0] * scale  # tilt difference about earth x and y, rad
        p0, p1 = state[4] + Q, state[5] + Q
        k0, k1 = p0 / (p0 + R), p1 / (p1 + R)
        state[4], state[5] = (1.0 - k0) * p0, (1.0 - k1) * p1
        q = quat_multiply(rotvec_quat(k0 * z0, k1 * z1, 0.0), q)
    q = quat_normalized(q)
    state[0], state[1], state[2], state[3] = q
    return up_in_sensor(q)


@kernel()
def run(state, coef, gyr, acc, gravity, quat):
    """Run over N samples: gravity (N×3, g·up, m/s²) and quat (N×4) written per sample."""
    Q, R, Ts, g = coef[0], coef[1], coef[2], coef[3]
    for k in range(gyr.shape[0]):
        write_sample(gravity, quat, k, g, luinge_step(state, Q, R, Ts, gyr, acc, k), state)
