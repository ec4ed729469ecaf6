"""Mahony's complementary filter on SO(3) with gyro-bias estimation (Mahony, Hamel,
Pflimlin 2008, IEEE TAC 53), the explicit form for the gravity direction:

    e = v × v̂,  ω_c = ω_y − b̂ + k_P·e,  ḃ = −k_I·e,  q̇ = ½·q ⊗ ω_c,

with v the measured up (accelerometer) and v̂ = R(q)ᵀ·ẑ the estimated up, both unit
vectors in sensor coordinates. Discrete time: ω_c held over the sample, integrated as an
exact rotation.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.quaternion import quat_multiply, quat_normalized, rotvec_quat, up_in_sensor, write_sample

STATE_NAMES = ("q_w", "q_x", "q_y", "q_z", "b_x", "b_y", "b_z")  # q, gyro bias b̂ (rad/s)


def coefficients(params, Ts: float) -> np.ndarray:
    """[k_P (1/s), k_I (1/s²), Ts (s), g (m/s²)]; gains unstable at Ts refused (check_gains)."""
    check_gains(params["k_P"], params["k_I"], Ts)
    return np.array([params["k_P"], params["k_I"], Ts, params["g"]])


def check_gains(k_P: float, k_I: float, Ts: float) -> None:
    """Refuse gains k_P (1/s) and k_I (1/s²) with which the step diverges at the sample
    time Ts (s). Linearised about the true attitude (tilt error x, bias error β, both per
    axis), a step is β' = β + k_I·Ts·x, x' = (1 − k_P·Ts)·x − Ts·β', whose poles lie inside
    the unit circle (Jury) for k_P·Ts < 2 and k_I·Ts² < 4 − 2·k_P·Ts."""
    if k_P * Ts >= 2.0:
        raise ValueError(f"parameter k_P = {k_P:g} 1/s is unstable at the sample time {Ts:g} s: Mahony's step "
                         f"needs k_P·Ts < 2, k_P < {2.0 / Ts:g} 1/s at {1.0 / Ts:g} Hz")
    if k_I * Ts * Ts >= 4.0 - 2.0 * k_P * Ts:
        raise ValueError(f"parameter k_I = {k_I:g} 1/s² is unstable with k_P = {k_P:g} 1/s at the sample time "
                         f"{Ts:g} s: Mahony's step needs k_I·Ts² < 4 − 2·k_P·Ts, k_I < "
                         f"{(4.0 - 2.0 * k_P * Ts) / (Ts * Ts):g} 1/s² at {1.0 / Ts:g} Hz")


def initial_state(coef, acc0) -> np.ndarray:
    """Level on acc0 (heading 0), no bias."""
    state = np.zeros(len(STATE_NAMES))
    state[0:4] = level_on(np.asarray(acc0, dtype=float))
    return state


def level_on(acc0) -> np.ndarray:
    """Quaternion (sensor → earth) of the smallest rotation taking acc0 onto up."""
    u = acc0 / np.linalg.norm(acc0)
    w = 1.0 + u[2]
    if w < 1e-12:
        return np.array([0.0, 1.0, 0.0, 0.0])
    q = np.array([w, u[1], -u[0], 0.0])
    return q / np.linalg.norm(q)


@kernel(inline=True)
def mahony_step(state, k_P, k_I, Ts, gyr, acc, k):
    """One sample of the filter on state [q, b̂] in place; returns the unit up estimate."""
    q = (state[0], state[1], state[2], state[3])
    v_hat = up_in_sensor(q)
    a0, a1, a2 = acc[k, 0], acc[k, 1], acc[k, 2]
    norm = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    e0 = e1 = e2 = 0.0
    if norm > 0.0:
        v0, v1, v2 = a0 / norm, a1 / norm, a2 / norm
        e0 = v1 * v_hat[2] - v2 * v_hat[1]
        e1 = v2 * v_hat[0] - v0 * v_hat[2]
        e2 = v0 * v_hat[1] - v1 * v_hat[0]
    state[4] -= k_I * e0 * Ts
    state[5] -= k_I * e1 * Ts
    state[6] -= k_I * e2 * Ts
    w0 = gyr[k, 0] - state[4] + k_P * e0
    w1 = gyr[k, 1] - state[5] + k_P * e1
    w2 = gyr[k, 2] - state[6] + k_P * e2
    q = quat_normalized(quat_multiply(q, rotvec_quat(w0 * Ts, w1 * Ts, w2 * Ts)))
    state[0], state[1], state[2], state[3] = q
    return up_in_sensor(q)


@kernel()
def run(state, coef, gyr, acc, gravity, quat):
    """Run over N samples: gravity (N×3, g·up, m/s²) and quat (N×4) written per sample."""
    k_P, k_I, Ts, g = coef[0], coef[1], coef[2], coef[3]
    for k in range(gyr.shape[0]):
        write_sample(gravity, quat, k, g, mahony_step(state, k_P, k_I, Ts, gyr, acc, k), state)
