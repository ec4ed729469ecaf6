"""Delays between streams, measured from the data: the shift of one stream against another
that fits best, found on a grid and refined by a bounded search. Used for the IMU's delay
behind an optical reference (systems.evaluation.evaluate.imu_latency) and the magnetometer's delay
behind the gyro (mag_delay)."""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from attitude_fmu import _core
from attitude_fmu._core import MAG_DELAY_REACH_S, MAG_DELAY_SIGMAS, MAG_SPAN_S

MAX_GRID = 100  # by default at most this many grid steps either way (steps of a sample or more)
MAG_TURN = 0.05  # rad: spans over which the sensor turns less carry no delay
MAG_MIN_TURNING_S = 5.0  # s of turning spans below which no delay is measured
MAG_MAX_SPANS = 2_000  # at most this many spans, evenly spread, enter the fit
MAG_CURVATURE_S = 1e-3  # s: the step over which the fit's curvature in the delay is taken
MAG_GRID = 10  # grid steps either way (10 ms for MAG_DELAY_REACH_S): the fit's mismatch is smooth in the shift
MAG_OUTLIER = 5.0  # spans whose residual at no delay exceeds this many times the median are left out


def best_shift(mismatch, reach: float, steps: int = MAX_GRID) -> float | None:
    """The shift (samples, within ±reach) that minimises mismatch(shift): a grid of at most
    2·steps + 1 shifts (a sample apart or more), then a bounded search between the best
    one's neighbours. None where the best shift lies at the grid's edge (the delay is
    beyond reach, or there is none to find)."""
    grid = np.linspace(-reach, reach, 2 * int(min(reach, steps)) + 1)
    best = int(np.argmin([mismatch(shift) for shift in grid]))
    if best in (0, len(grid) - 1):
        return None
    step = grid[1] - grid[0]
    return float(minimize_scalar(mismatch, bounds=(grid[best] - step, grid[best] + step), method="bounded",
                                 options={"xatol": 1e-3}).x)


def mag_delay(gyr, mag, fs: float) -> float | None:
    """The magnetometer's delay behind the gyro (s), from the IMU's own data: a homogeneous
    field seen by a turning sensor is carried from one sample to the next by the gyro's
    rotation, m₁ − b = R_Δᵀ·(m₀ − b), b a hard-iron offset. Over spans of about MAG_SPAN_S
    between the field's own samples (a row with a NaN is a missing sample; at most
    MAG_MAX_SPANS spans, evenly spread over the recording) that carry is
    compared with the field, the gyro's rotation taken over the span shifted by the delay
    and b fitted by least squares at each shift. Spans over which the sensor turns less
    than MAG_TURN, and those a disturbance passes (residual above MAG_OUTLIER times the
    median at no delay), are left out. gyr N×3 rad/s (sample k the mean rate before it),
    mag N×3 in any unit. None where fewer than MAG_MIN_TURNING_S seconds of turning spans
    remain (or the recording is shorter than a span), where the best delay lies beyond
    ±MAG_DELAY_REACH_S, or where it lies within MAG_DELAY_SIGMAS standard errors (from the
    fit's curvature) of 0: a delay the data do not show (a sensor that turns too little for
    the field's noise, or none)."""
    gyr, mag = np.ascontiguousarray(gyr, dtype=float), np.asarray(mag, dtype=float)
    sampled = np.flatnonzero(np.isfinite(mag).all(axis=1))
    if len(sampled) < 2:
        return None
    spacing = float(np.median(np.diff(sampled)))
    stride = max(1, int(round(MAG_SPAN_S * fs / spacing)))
    k0, k1 = sampled[:-stride], sampled[stride:]
    if len(k0) == 0:  # shorter than a span
        return None
    spread = -(-len(k0) // MAG_MAX_SPANS)
    k0, k1 = k0[::spread], k1[::spread]
    quat = np.empty((len(gyr), 4))
    _core.integrate_rates(gyr, 1.0 / fs, quat)  # quat[k]: the sensor at t_k

    def carried(shift, keep):
        """R_Δᵀ over each span of keep, the gyro shifted by shift samples (the C core's
        carry_spans: between samples k and k + 1 the sensor turns at gyro sample k + 1's rate)."""
        matrices = np.empty((len(keep), 3, 3))
        _core.carry_spans(quat, gyr, 1.0 / fs, k0[keep] - shift, k1[keep] - shift, matrices)
        return matrices

    def residuals(shift, keep):
        matrices = carried(shift, keep)
        y = mag[k1[keep]] - np.einsum("nij,nj->ni", matrices, mag[k0[keep]])  # = (I − R_Δᵀ)·b
        A = np.eye(3) - matrices
        b = np.linalg.solve(np.einsum("nij,nik->jk", A, A), np.einsum("nij,ni->j", A, y))  # normal equations
        return y - A @ b

    # the angle turned over a span, from the trace of R_Δᵀ
    turn = np.arccos(np.clip((np.trace(carried(0.0, np.arange(len(k0))), axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))
    keep = np.flatnonzero(turn >= MAG_TURN)
    if len(keep) * spread * spacing / fs < MAG_MIN_TURNING_S:
        return None
    error = np.sum(residuals(0.0, keep) ** 2, axis=1)
    keep = keep[error <= MAG_OUTLIER * np.median(error)]

    def mismatch(shift):
        return float(np.mean(np.sum(residuals(shift, keep) ** 2, axis=1)))

    shift = best_shift(mismatch, MAG_DELAY_REACH_S * fs, MAG_GRID)
    if shift is None:
        return None
    # its standard error: mismatch ≈ M₀ + c·(s − ŝ)² with c the mean square of the residuals'
    # derivative in s, whose 3·N components (N spans, fewer where they overlap) each carry
    # noise of variance M₀/3
    h = MAG_CURVATURE_S * fs
    m0 = mismatch(shift)
    c = (mismatch(shift + h) + mismatch(shift - h) - 2.0 * m0) / (2.0 * h * h)
    independent = len(keep) * min(1.0, spread / stride)
    if c <= 0.0 or shift * shift < MAG_DELAY_SIGMAS**2 * m0 / (3.0 * independent * c):
        return None
    return shift / fs
