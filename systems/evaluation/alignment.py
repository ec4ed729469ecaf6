"""A reference orientation brought into the IMU's frames (`attitude evaluate --align`): the time
lag between the two, the constant rotation between the IMU and the reference's body (its
markers), the reference's up axis and the heading offset between the reference's earth frame
and the estimate's.

What each is found from:
- lag: the angular rate's magnitude, which no rotation changes: the gyro's against the rate
  the reference's consecutive orientations imply, cross-correlated over ±MAX_LAG_S, the peak
  refined to a fraction of a sample (a parabola through its neighbours);
- mounting: the gyro's rates against the reference's, in their own frames, at the lag found
  (Wahba's problem, scipy's Rotation.align_vectors), with the gyro's offset fitted beside it;
- up: the mean specific force turned into the reference's earth frame, taken as the axis of
  that frame it lies within UP_SNAP_DEG of (a motion capture's up is one of its axes);
- heading offset: the circular mean, over the movement, of the turn about the vertical from
  the aligned reference to the estimate.
A reference whose rates do not match the gyro's at any lag is refused with the misfit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import correlate, correlation_lags
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.recordings.recording import Recording, RecordingError

MAX_LAG_S = 10.0  # the lag is looked for within ± this (s), and within a quarter of the recording
MAX_MISFIT = 0.35  # refused above this RMS of (gyro − rotated reference rate) over the gyro's RMS rate
UP_SNAP_DEG = 10.0  # the reference's up is the axis of its earth frame within this of the mean specific force
MIN_MOVING_RATE = 0.2  # rad/s: samples turning at least this fast enter the mounting fit
OFFSET_ITERATIONS = 3  # mounting and gyro offset fitted in turn this often
UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class Alignment:
    """lag_s (s): the reference lags the IMU by it (its sample at t + lag_s is the IMU's at t);
    mounting_quat [w, x, y, z]: the IMU's frame → the reference's body frame, so that the
    reference's orientation ⊗ mounting_quat is the IMU's; up_axis: the reference's earth
    frame's up, in its coordinates; heading_offset_deg: the turn about the vertical from the
    reference's earth frame (up aligned) to the estimate's; misfit: RMS of the gyro's rate
    less the reference's rate turned into the IMU's frame, over the gyro's RMS rate."""

    lag_s: float
    mounting_quat: tuple[float, float, float, float]
    up_axis: tuple[float, float, float]
    heading_offset_deg: float
    misfit: float

    def to_json(self) -> dict:
        """The JSON key `alignment` of a recording: lag_s, mounting_quat, up_axis, heading_offset_deg, misfit."""
        return {"lag_s": self.lag_s, "mounting_quat": list(self.mounting_quat), "up_axis": list(self.up_axis),
                "heading_offset_deg": self.heading_offset_deg, "misfit": self.misfit}


def reference_rates(quat_ref, fs: float) -> np.ndarray:
    """N×3 (rad/s, the reference's body frame): row k the mean rate over (t_k−1, t_k] the
    reference's orientations k−1 and k imply (the gyro's convention); NaN where either is missing."""
    ok = np.isfinite(quat_ref).all(axis=1)
    rot = Rotation.from_quat(np.where(ok[:, None], quat_ref, [1.0, 0.0, 0.0, 0.0]), scalar_first=True)
    rate = np.full((len(quat_ref), 3), np.nan)
    rate[1:] = (rot[:-1].inv() * rot[1:]).as_rotvec() * fs
    rate[~(ok & np.roll(ok, 1))] = np.nan
    rate[0] = np.nan
    return rate


def _neighbours(n: int, shift: float):
    """For every k of n rows, the rows around the fractional index k + shift: (k0, k1, frac, inside),
    k1 = k0 where it falls on a row; inside False where a neighbour lies outside the rows."""
    at = np.arange(n) + shift
    k0 = np.floor(at).astype(np.int64)
    frac = at - k0
    k1 = np.where(frac > 0.0, k0 + 1, k0)
    inside = (k0 >= 0) & (k1 < n)
    return np.clip(k0, 0, n - 1), np.clip(k1, 0, n - 1), frac, inside


def shifted(values, shift: float) -> np.ndarray:
    """Rows of values (N×d) at the fractional index k + shift for every k, linearly interpolated;
    NaN outside the rows or where a neighbour is NaN."""
    values = np.asarray(values, dtype=float)
    k0, k1, frac, inside = _neighbours(len(values), shift)
    out = values[k0] * (1.0 - frac[:, None]) + values[k1] * frac[:, None]
    out[~inside] = np.nan
    return out


def shifted_quaternions(quat_ref, shift: float) -> np.ndarray:
    """The reference's orientations (N×4, w first) at k + shift, interpolated on the sphere
    between neighbours (a constant rate between samples); NaN where a neighbour is missing."""
    quat_ref = np.asarray(quat_ref, dtype=float)
    k0c, k1c, frac, inside = _neighbours(len(quat_ref), shift)
    n = len(quat_ref)
    ok = inside & np.isfinite(quat_ref[k0c]).all(axis=1) & np.isfinite(quat_ref[k1c]).all(axis=1)
    out = np.full((n, 4), np.nan)
    if ok.any():
        r0 = Rotation.from_quat(quat_ref[k0c[ok]], scalar_first=True)
        r1 = Rotation.from_quat(quat_ref[k1c[ok]], scalar_first=True)
        turn = Rotation.from_rotvec((r0.inv() * r1).as_rotvec() * frac[ok, None])
        out[ok] = (r0 * turn).as_quat(scalar_first=True)
    return out


def rate_lag(gyr, rate_ref, fs: float, max_lag_s: float = MAX_LAG_S) -> float:
    """The reference's lag behind the gyro (samples, fractional): the peak of the cross-
    correlation of the rates' magnitudes within ±max_lag_s and a quarter of the recording."""
    a = np.linalg.norm(gyr, axis=1)
    b = np.linalg.norm(rate_ref, axis=1)
    valid_a, valid_b = np.isfinite(a), np.isfinite(b)
    if valid_a.sum() < fs or valid_b.sum() < fs:
        raise RecordingError("aligning the reference needs at least a second of gyro rates and reference "
                             "orientations")
    a = np.where(valid_a, a - np.mean(a[valid_a]), 0.0)
    b = np.where(valid_b, b - np.mean(b[valid_b]), 0.0)
    c = correlate(b, a, mode="full", method="fft")  # c[L] = Σ_k a[k]·b[k + L]
    lags = correlation_lags(len(b), len(a), mode="full")
    reach = min(max_lag_s * fs, len(a) / 4.0)
    window = np.abs(lags) <= reach
    c, lags = c[window], lags[window]
    best = int(np.argmax(c))
    if 0 < best < len(c) - 1:  # a parabola through the peak and its neighbours
        left, mid, right = c[best - 1], c[best], c[best + 1]
        curvature = left - 2.0 * mid + right
        return float(lags[best] + (0.5 * (left - right) / curvature if curvature < 0.0 else 0.0))
    return float(lags[best])


def mounting(gyr, rate_ref, use) -> tuple[Rotation, np.ndarray, float]:
    """(rotation of the reference's body frame into the IMU's, gyro offset (rad/s), misfit) from
    the rows use of the gyro and the reference's rates (same times), with the offset fitted in turn."""
    a, b = gyr[use], rate_ref[use]
    offset = np.zeros(3)
    for _ in range(OFFSET_ITERATIONS):
        rotation, _ = Rotation.align_vectors(a - offset, b)
        offset = np.mean(a - rotation.apply(b), axis=0)
    residual = a - offset - rotation.apply(b)
    misfit = math.sqrt(np.mean(np.sum(residual**2, axis=1)) / np.mean(np.sum((a - offset) ** 2, axis=1)))
    return rotation, offset, misfit


def up_axis(sensor_to_ref_earth: Rotation, acc) -> np.ndarray:
    """The reference's earth frame's up: the mean specific force turned into that frame,
    snapped to the nearest of its axes where within UP_SNAP_DEG."""
    mean = np.mean(sensor_to_ref_earth.apply(acc), axis=0)
    mean = mean / np.linalg.norm(mean)
    axes = np.vstack([np.eye(3), -np.eye(3)])
    nearest = axes[int(np.argmax(axes @ mean))]
    return nearest if math.degrees(math.acos(min(1.0, float(nearest @ mean)))) <= UP_SNAP_DEG else mean


def heading_offset(quat_est, quat_ref) -> float:
    """The circular mean (rad) of the turn about the vertical from quat_ref to quat_est (N×4
    each, sensor → earth, finite rows): the twist about z of q_est ⊗ q_ref⁻¹."""
    err = (Rotation.from_quat(quat_est, scalar_first=True)
           * Rotation.from_quat(quat_ref, scalar_first=True).inv()).as_quat(scalar_first=True)
    twist = 2.0 * np.arctan2(err[:, 3], err[:, 0])
    return float(np.arctan2(np.mean(np.sin(twist)), np.mean(np.cos(twist))))


def without_heading_offset(quat_ref, offset_rad: float) -> np.ndarray:
    """The reference (N×4, sensor → earth) turned about the vertical by offset_rad."""
    ok = np.isfinite(quat_ref).all(axis=1)
    out = np.full_like(quat_ref, np.nan, dtype=float)
    turn = Rotation.from_rotvec(offset_rad * UP)
    out[ok] = (turn * Rotation.from_quat(quat_ref[ok], scalar_first=True)).as_quat(scalar_first=True)
    return out


def align(rec: Recording, quat_est) -> tuple[Alignment, np.ndarray]:
    """The alignment of rec's reference with its IMU and the estimate quat_est (N×4, sensor →
    earth), and the reference aligned in time, mounting and up (N×4, the IMU's frame → the
    reference's earth frame turned up; NaN where missing), its heading offset left to the caller
    (without_heading_offset). Raises RecordingError where the reference's rates match the
    gyro's at no lag and rotation."""
    ok = rec.evaluated()
    rate_ref = reference_rates(rec.quat_ref, rec.fs)
    lag = rate_lag(rec.gyr, rate_ref, rec.fs)
    rate_at = shifted(rate_ref, lag)
    moving = np.isfinite(rate_at).all(axis=1) & np.isfinite(rec.gyr).all(axis=1)
    moving &= np.linalg.norm(np.where(moving[:, None], rec.gyr, 0.0), axis=1) >= MIN_MOVING_RATE
    if moving.sum() < rec.fs:
        raise RecordingError(f"{rec.name}: the reference cannot be aligned: less than a second of samples turning "
                             f"faster than {MIN_MOVING_RATE:g} rad/s")
    body_to_sensor, _, misfit = mounting(rec.gyr, rate_at, moving)
    if misfit > MAX_MISFIT:
        raise RecordingError(
            f"{rec.name}: the reference cannot be aligned: its angular rates do not match the gyro's (misfit "
            f"{misfit:.2f} of the gyro's RMS rate at the best lag, {lag / rec.fs:+.3f} s, and rotation; at most "
            f"{MAX_MISFIT:g} is taken): is it the same body's, at the same rate?")
    ref_at = shifted_quaternions(rec.quat_ref, lag)
    valid = np.isfinite(ref_at).all(axis=1)
    sensor_to_body = body_to_sensor.inv()
    sensor_ref = np.full_like(ref_at, np.nan)
    sensor_ref[valid] = (Rotation.from_quat(ref_at[valid], scalar_first=True)
                         * sensor_to_body).as_quat(scalar_first=True)
    use = valid & np.isfinite(rec.acc).all(axis=1)
    up = up_axis(Rotation.from_quat(sensor_ref[use], scalar_first=True), rec.acc[use])
    tilt, _ = Rotation.align_vectors(UP[None, :], up[None, :])
    aligned = np.full_like(ref_at, np.nan)
    aligned[valid] = (tilt * Rotation.from_quat(sensor_ref[valid], scalar_first=True)).as_quat(scalar_first=True)
    scored = ok & valid & np.isfinite(quat_est).all(axis=1)
    offset = heading_offset(quat_est[scored], aligned[scored])
    alignment = Alignment(lag_s=lag / rec.fs, mounting_quat=tuple(map(float, sensor_to_body.as_quat(scalar_first=True))),
                          up_axis=tuple(map(float, up)), heading_offset_deg=math.degrees(offset), misfit=misfit)
    return alignment, aligned
