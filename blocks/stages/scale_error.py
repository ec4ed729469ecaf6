"""The Wiener filter's gyro scale error chosen from the recording (the batch path, where the
whole recording is at hand; online, the parameter's value holds).

The local densities (blocks.methods.wiener_local) count a gyro error that grows with the
rotation, σ_s·|ω| (scale_error, σ_s; 0.005 a consumer datasheet's figure). A calibrated gyro
has far less, and then the break frequency comes out too high: on a simulated calibrated
sensor (0.05 % scale error) the default gives twice the inclination error of scale_error 0.
Rule: unless scale_error is given, each of SCALE_ERRORS runs the method over the recording
(the gyro freed of its offset as the pipeline frees it), and the one whose estimate of gravity
predicts the accelerometer best PREDICTION_HORIZON_S ahead through the gyro is taken
(blocks/core/stages/prediction.h): with no acceleration but gravity that prediction error is
the estimate's mean-square error plus the gyro's drift over the horizon, the same for every
candidate; the motion's acceleration adds its own power, also the same, and a cross term
where it persists beyond the horizon, which favours a higher break frequency. The candidates
therefore stop at the datasheet's figure: the recording may show a better gyro, never
a worse one. The choice is a statistic of the recording: on 120 s of simulated motion it
takes 0 for a calibrated gyro (0.05 %) and 0.005 for one of 1 %, within 5 % of the best
candidate's error (tests/test_scale_error.py), but for a gyro of 0.5 % it may take 0.002 (up
to 8 % above 0.005's error), and a start-up within the first seconds weighs on it.
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from attitude_fmu import _core

SCALE_ERRORS = (0.0, 0.001, 0.002, 0.005)  # the candidates: the default and below it
PREDICTION_HORIZON_S = 0.5  # s: beyond the white noise's and a tap's correlation, within the filter's memory


def applies(method: str, params) -> bool:
    """Whether the rule chooses for method with its own params (a mapping): the Wiener
    filter with local densities and no scale_error given."""
    return "scale_error" not in params and _core.method_kernel(method, dict(params)) == "wiener_local"


def prediction_error(gyr, acc, gravity, fs: float, horizon: float = PREDICTION_HORIZON_S) -> float:
    """The mean of |a(t + h) − R(t → t + h)ᵀ·ĝ(t)|² over the recording (m²/s⁴): gyr N×3 rad/s,
    acc and the estimate gravity N×3 m/s², fs Hz, horizon h s (blocks/core/stages/prediction.h)."""
    m = max(1, round(horizon * fs))
    return _core.prediction_error(np.ascontiguousarray(gyr, dtype=float), np.ascontiguousarray(acc, dtype=float),
                                  np.ascontiguousarray(gravity, dtype=float), 1.0 / fs, m)


def choose(gyr, acc, fs: float, run, workers: int = 1) -> tuple[float, dict[float, float]] | None:
    """(the chosen scale error, {candidate: prediction error}) for gyr (N×3 rad/s, freed of its
    offset) and acc (N×3 m/s²) at fs Hz; run(scale_error) gives the method's gravity (N×3,
    m/s²) with that value. None where the recording is no longer than the horizon. workers:
    candidates run at once on threads (the C core runs without Python's lock), the result the
    same."""
    if len(gyr) <= max(1, round(PREDICTION_HORIZON_S * fs)):
        return None

    def error(candidate: float) -> float:
        return prediction_error(gyr, acc, run(candidate), fs)

    if workers > 1:
        with ThreadPoolExecutor(max_workers=min(workers, len(SCALE_ERRORS))) as pool:
            errors = dict(zip(SCALE_ERRORS, pool.map(error, SCALE_ERRORS)))
    else:
        errors = {c: error(c) for c in SCALE_ERRORS}
    best = min(errors, key=lambda c: (errors[c], -c))  # a tie keeps the larger, the nearer the default
    return (best, errors) if math.isfinite(errors[best]) else None


def chosen_text(value: float) -> str:
    """The note that says what the rule chose and how to fix it."""
    return (f"scale_error {value:g} chosen from the recording (of {', '.join(f'{c:g}' for c in SCALE_ERRORS)}, the "
            f"one whose estimate predicts the accelerometer best {PREDICTION_HORIZON_S:g} s ahead through the gyro); "
            f"--param scale_error={value:g} holds it, as the FMU's parameter of that name does")
