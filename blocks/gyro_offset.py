"""Gyroscope-offset estimator (the "gyro offset estimator" box of Rizun's Fig. 1).

Rest detection: the gyro and the accelerometer, each low-passed (time constant tau_lp),
must stay close to their low-passed values (rest_gyr, rest_acc) and the low-passed gyro
must stay small (rest_gyr_abs) for rest_time seconds; while at rest the offset estimate
follows the low-passed gyro with time constant tau_bias. The corrected gyro is the
measured one minus the current estimate. Causal, one compiled step per sample.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .methods import Param, resolve_params

PARAMS = (
    Param("rest_gyr", math.radians(2.0), "rad/s", "largest deviation of the gyro from its low-pass at rest"),
    Param("rest_gyr_abs", math.radians(5.0), "rad/s", "largest low-passed gyro norm at rest (offset included)"),
    Param("rest_acc", 0.5, "m/s²", "largest deviation of the accelerometer from its low-pass at rest"),
    Param("rest_time", 1.5, "s", "time the rest conditions must hold"),
    Param("tau_lp", 0.5, "s", "time constant of the low-passes of the rest detection"),
    Param("tau_bias", 10.0, "s", "time constant of the offset estimate's averaging at rest"),
)
STATE_NAMES = ("glp_x", "glp_y", "glp_z", "alp_x", "alp_y", "alp_z", "rest_s", "b_x", "b_y", "b_z")


def resolve(overrides=None) -> dict:
    return resolve_params(PARAMS, overrides, "the gyro-offset estimator")


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts, a_lp, a_bias, rest_gyr, rest_gyr_abs, rest_acc, rest_time]; a_* = 1 − exp(−Ts/τ)."""
    return np.array([Ts, 1.0 - math.exp(-Ts / params["tau_lp"]), 1.0 - math.exp(-Ts / params["tau_bias"]),
                     params["rest_gyr"], params["rest_gyr_abs"], params["rest_acc"], params["rest_time"]])


def initial_state(gyr0, acc0) -> np.ndarray:
    """Low-passes on the first samples, not at rest, no offset."""
    return np.concatenate([gyr0, acc0, [0.0], [0.0, 0.0, 0.0]])


@kernel()
def run(state, coef, gyr, acc, corrected, offset):
    """Over N samples: corrected gyro (N×3, rad/s) and offset estimate (N×3) per sample."""
    Ts, a_lp, a_bias, rest_gyr, rest_gyr_abs, rest_acc, rest_time = (
        coef[0], coef[1], coef[2], coef[3], coef[4], coef[5], coef[6])
    for k in range(gyr.shape[0]):
        dg2 = 0.0
        da2 = 0.0
        g2 = 0.0
        for i in range(3):
            state[i] += a_lp * (gyr[k, i] - state[i])
            state[3 + i] += a_lp * (acc[k, i] - state[3 + i])
            dg2 += (gyr[k, i] - state[i]) ** 2
            da2 += (acc[k, i] - state[3 + i]) ** 2
            g2 += state[i] ** 2
        still = dg2 < rest_gyr * rest_gyr and da2 < rest_acc * rest_acc and g2 < rest_gyr_abs * rest_gyr_abs
        state[6] = state[6] + Ts if still else 0.0
        for i in range(3):
            if state[6] >= rest_time:
                state[7 + i] += a_bias * (state[i] - state[7 + i])
            offset[k, i] = state[7 + i]
            corrected[k, i] = gyr[k, i] - state[7 + i]


def correct(gyr, acc, fs: float, params=None):
    """(corrected gyro, offset estimate), both N×3 rad/s, over a whole recording."""
    gyr = np.ascontiguousarray(gyr, dtype=float)
    acc = np.ascontiguousarray(acc, dtype=float)
    state = initial_state(gyr[0], acc[0])
    corrected, offset = np.empty_like(gyr), np.empty_like(gyr)
    run(state, coefficients(resolve(params), 1.0 / fs), gyr, acc, corrected, offset)
    return corrected, offset
