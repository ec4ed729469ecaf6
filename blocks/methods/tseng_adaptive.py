"""Tseng's adaptive complementary filter: the complementary filter while the accelerometer
norm stays within tol of g, Mahony's filter (gyro-dominated, with bias estimate) while it
does not. On leaving Mahony's filter the complementary filter restarts at rest on its
estimate. One compiled step: the sensor-frame step of blocks.filters.sensor_frame and the step
of blocks.methods.mahony.

State [X (3·n, the complementary filter's states row by row), q (4), b̂ (3)];
coefficients [n, Ts, tol, g, k_P, k_I, D, Ad (n²), Bd (n), C (n), x_rest (n)], x_rest the
filter's state per unit of constant input.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from attitude_fmu.blocks.filters import tseng
from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter, sensor_frame_step
from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.methods.mahony import check_gains, mahony_step


def coefficients(params, Ts: float) -> np.ndarray:
    check_gains(params["k_P"], params["k_I"], Ts)  # its Mahony mode's
    disc = DiscreteFilter.from_lti(tseng.earth_filter(), Ts)
    unit_rest = disc.rest_state([1.0, 0.0, 0.0])[:, 0]
    return np.concatenate([[disc.order, Ts, params["tol"], params["g"], params["k_P"], params["k_I"], disc.D],
                           disc.Ad.ravel(), disc.Bd, disc.C, unit_rest])


def initial_state(coef, acc0) -> np.ndarray:
    n = int(coef[0])
    x_rest = coef[7 + n * n + 2 * n: 7 + n * n + 3 * n]
    return np.concatenate([np.outer(x_rest, acc0).ravel(), [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


@kernel()
def run(state, coef, gyr, acc, gravity, quat):
    """Run over N samples: gravity (N×3, m/s²) and quat (N×4) written per sample."""
    n = int(coef[0])
    Ts, tol, g, k_P, k_I, D = coef[1], coef[2], coef[3], coef[4], coef[5], coef[6]
    Ad = coef[7: 7 + n * n].reshape((n, n))
    Bd = coef[7 + n * n: 7 + n * n + n]
    C = coef[7 + n * n + n: 7 + n * n + 2 * n]
    x_rest = coef[7 + n * n + 2 * n: 7 + n * n + 3 * n]
    X = state[: 3 * n].reshape((n, 3))
    q = state[3 * n: 3 * n + 4]
    mahony_state = state[3 * n: 3 * n + 7]  # q then b̂, as blocks.methods.mahony keeps them
    Xr = np.empty((n, 3))
    for k in range(gyr.shape[0]):
        norm = np.sqrt(acc[k, 0] ** 2 + acc[k, 1] ** 2 + acc[k, 2] ** 2)
        if abs(norm - g) <= tol:
            sensor_frame_step(X, q, gyr, acc, k, Ad, Bd, C, D, Ts, Xr, gravity)
        else:
            up = mahony_step(mahony_state, k_P, k_I, Ts, gyr, acc, k)
            for j in range(n):
                for i in range(3):
                    X[j, i] = x_rest[j] * g * up[i]
            gravity[k, 0], gravity[k, 1], gravity[k, 2] = g * up[0], g * up[1], g * up[2]
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q[0], q[1], q[2], q[3]


@lru_cache(maxsize=1)
def _state_names():
    order = DiscreteFilter.from_lti(tseng.earth_filter(), 0.01).order
    return tuple(f"x{j}_{a}" for j in range(order) for a in "xyz") + (
        "q_w", "q_x", "q_y", "q_z", "b_x", "b_y", "b_z")


def __getattr__(name: str):
    """STATE_NAMES, made on first use: designing the filter imports python-control, which
    the other methods' paths do without."""
    if name == "STATE_NAMES":
        return _state_names()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
