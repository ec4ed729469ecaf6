"""Hard-iron offset of the magnetometer: a field fixed to the sensor (its own magnetised
parts, a magnet carried along), estimated so that the heading stage sees the earth's field.

A homogeneous field h seen by a sensor that turns lies on a sphere: |m − b| = r. Over
the recent samples (sums forgotten in mag_cal_time) the algebraic sphere fit
|m|² = 2·m·b + c, c = r² − |b|², is a linear least-squares problem in (b, c), solved
from running sums each field sample. Its residual, as a distance from the sphere, is
set against that of the field as it is (b = 0: the spread of |m|). The offset is used
only when the fit explains the field and the field as it is does not, for as long as a
new reference field must stay steady (blocks.stages.heading's mag_new_time):
- the samples cover every direction: the field's s.d. across its smallest axis is at
  least mag_cal_spread of the radius (a sensor turning about one axis draws a circle,
  which leaves b along that axis open);
- the fit's rms distance from the sphere is below mag_cal_tol of its radius and below
  half that of the field as it is;
- the offset is larger than the guard's norm tolerance (mag_norm_tol of the radius):
  smaller ones are the guard's business, and a calibrated magnetometer in a lab whose
  field is not quite homogeneous is left alone.
Then b follows the fit; it is reset to 0 once the field as it is, covering every
direction, stays within mag_cal_tol of a sphere about 0 for the same time, and kept
otherwise (a disturbance passing by, or a long rest, does not undo a calibration). When
b is taken or dropped, the field it leaves is proven homogeneous, and the heading stage
starts afresh from it.

The field can change for good within the window (a magnet put on or taken off). The sums
start afresh from the latest sample, so that the fit proves the new field within about a
minute instead of mixing it with the old one for several, once the window is at least
mag_new_time old and
- the latest samples (mean square distance low-passed over mag_cal_recent) lie more than
  mag_cal_tol off a sphere the window fits: the one about b, where it covers every
  direction, or the one about 0 unless b explains the field better (half the distance,
  as above). The sphere about 0 needs no directions: a field that leaves the norm it
  held has changed, at rest too (a magnet put on a resting sensor); or
- the window covers every direction and fits neither sphere: it holds a change (a magnet
  brought up passes through stronger fields on its way) or a field that varies.
(A younger window's fit is not yet sure enough to be left: its error where the sensor
turns next alone exceeds the tolerance.)
Soft iron (a scaled, skewed sphere) is not modelled. mag_cal_time = 0 switches the
estimate off. Offline, back_dated moves each offset taken or dropped back to where the
field changed.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.params import FRACTION, TIME_S, Param

PARAMS = (
    Param("mag_cal_time", 60.0, "s", "time over which the hard-iron fit forgets its samples (0: no hard-iron estimate)",
          True, high=1e6),
    Param("mag_cal_spread", 0.1, "1", "least s.d. of the field across its smallest axis, relative to the fit's radius",
          **FRACTION),
    Param("mag_cal_tol", 0.05, "1", "largest rms distance of the field from the fitted sphere, relative to its radius",
          **FRACTION),
    Param("mag_cal_recent", 2.0, "s", "time constant over which the latest field samples are held against the sphere "
          "the window fits; when they leave it, the fit starts afresh", **TIME_S),
)
EXPLAINED = 0.5  # the fit's residual must be below this share of the field's own
STATE_NAMES = (
    "s_1", "s_mx", "s_my", "s_mz", "s_mxx", "s_mxy", "s_mxz", "s_myy", "s_myz", "s_mzz",  # Σ1, Σm, Σm·mᵀ
    "s_mx_n2", "s_my_n2", "s_mz_n2", "s_n2", "s_n4",  # Σm·|m|², Σ|m|², Σ|m|⁴ (forgetting sums)
    "b_x", "b_y", "b_z",  # the offset in use
    "fit_steps", "raw_steps",  # steps the fit, or the field as it is, has held steady
    "recent_fit", "recent_raw",  # the latest samples' mean square distance from either sphere, relative to its radius
    "age",  # steps since the sums started afresh
)
SUMS, OFFSET, FIT_STEPS, RAW_STEPS, RECENT_FIT, RECENT_RAW, AGE = slice(0, 15), slice(15, 18), 18, 19, 20, 21, 22
STATE_SIZE = len(STATE_NAMES)
COEF_SIZE = 6  # see coefficients


def coefficients(params, Ts: float) -> np.ndarray:
    """[mag_cal_time/Ts (steps; 0: off), mag_cal_spread, mag_cal_tol, mag_cal_recent/Ts
    (steps), 1 − exp(−Ts/mag_cal_time) (0 when off), 1 − exp(−Ts/mag_cal_recent)]."""
    cal_steps, recent_steps = params["mag_cal_time"] / Ts, params["mag_cal_recent"] / Ts
    return np.array([cal_steps, params["mag_cal_spread"], params["mag_cal_tol"], recent_steps,
                     1.0 - math.exp(-1.0 / cal_steps) if cal_steps > 0.0 else 0.0, 1.0 - math.exp(-1.0 / recent_steps)])


@kernel(inline=True)
def pull(gap, rate, one_step):
    """1 − exp(−gap·rate), the weight of a first-order low-pass over gap steps (rate per
    step); one_step is its value for one step, the usual gap."""
    return one_step if gap == 1.0 else 1.0 - math.exp(-gap * rate)


@kernel(inline=True)
def _accumulate(s, m, forget):
    """The running sums s (see STATE_NAMES) after the field sample m, the old sums scaled by forget."""
    n2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2]
    terms = (1.0, m[0], m[1], m[2], m[0] * m[0], m[0] * m[1], m[0] * m[2], m[1] * m[1], m[1] * m[2],
             m[2] * m[2], m[0] * n2, m[1] * n2, m[2] * n2, n2, n2 * n2)
    for i in range(15):
        s[i] = forget * s[i] + terms[i]


@kernel(inline=True)
def _covariance(s):
    """The field's mean (3-tuple) and covariance (xx, xy, xz, yy, yz, zz) from the sums s."""
    w = 1.0 / s[0]
    mx, my, mz = s[1] * w, s[2] * w, s[3] * w
    return (mx, my, mz), (s[4] * w - mx * mx, s[5] * w - mx * my, s[6] * w - mx * mz,
                          s[7] * w - my * my, s[8] * w - my * mz, s[9] * w - mz * mz)


@kernel(inline=True)
def _spread(s):
    """The s.d. of the field across its smallest axis (the field's unit): the square root
    of the covariance's least eigenvalue, in the closed form of a symmetric 3×3 matrix."""
    xx, xy, xz, yy, yz, zz = _covariance(s)[1]
    mean = (xx + yy + zz) / 3.0
    off2 = xy * xy + xz * xz + yz * yz
    p = math.sqrt(((xx - mean) ** 2 + (yy - mean) ** 2 + (zz - mean) ** 2 + 2.0 * off2) / 6.0)
    if p == 0.0:
        return math.sqrt(max(mean, 0.0))
    a, d, f = (xx - mean) / p, (yy - mean) / p, (zz - mean) / p
    b, c, e = xy / p, xz / p, yz / p
    half_det = 0.5 * (a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d))
    angle = math.acos(min(max(half_det, -1.0), 1.0)) / 3.0
    return math.sqrt(max(mean + 2.0 * p * math.cos(angle + 2.0 * math.pi / 3.0), 0.0))


@kernel(inline=True)
def _fit(s):
    """(b (3-tuple), radius, rms distance from the fitted sphere, the same for the sphere
    about 0), all in the field's unit; radius 0: no fit. With c eliminated, the fit is
    2·C·b = E[m·|m|²] − μ·E|m|² (C the field's covariance, μ its mean), c = E|m|² − 2μ·b."""
    mu, (xx, xy, xz, yy, yz, zz) = _covariance(s)
    n2, n4 = s[13] / s[0], s[14] / s[0]
    raw_radius = math.sqrt(n2)
    raw_distance = math.sqrt(max(n4 - n2 * n2, 0.0)) / (2.0 * raw_radius)
    # the adjugate of C and its determinant
    a0, a1, a2 = yy * zz - yz * yz, xz * yz - xy * zz, xy * yz - xz * yy
    a4, a5, a8 = xx * zz - xz * xz, xy * xz - xx * yz, xx * yy - xy * xy
    det = xx * a0 + xy * a1 + xz * a2
    if abs(det) < 1e-12 * n2 ** 3:  # too few directions for a sphere
        return (0.0, 0.0, 0.0), 0.0, 0.0, raw_radius, raw_distance
    w = 0.5 / s[0]  # the right-hand side halved, over det
    v0 = (s[10] * w - 0.5 * mu[0] * n2) / det
    v1 = (s[11] * w - 0.5 * mu[1] * n2) / det
    v2 = (s[12] * w - 0.5 * mu[2] * n2) / det
    b = (a0 * v0 + a1 * v1 + a2 * v2, a1 * v0 + a4 * v1 + a5 * v2, a2 * v0 + a5 * v1 + a8 * v2)
    c = n2 - 2.0 * (mu[0] * b[0] + mu[1] * b[1] + mu[2] * b[2])
    r2 = c + b[0] * b[0] + b[1] * b[1] + b[2] * b[2]
    if r2 <= 0.0:
        return (0.0, 0.0, 0.0), 0.0, 0.0, raw_radius, raw_distance
    radius = math.sqrt(r2)
    # mean of (|m|² − 2m·b − c)² at the solution: E|m|⁴ − 2b·E[m·|m|²] − c·E|m|²
    residual2 = n4 - 4.0 * w * (b[0] * s[10] + b[1] * s[11] + b[2] * s[12]) - c * n2
    return b, radius, math.sqrt(max(residual2, 0.0)) / (2.0 * radius), raw_radius, raw_distance


@kernel(inline=True)
def _recent(state, index, m, centre, radius, a):
    """Low-pass (weight a) of the squared distance of m from the sphere (centre, radius),
    relative to the radius, into state[index]; its value."""
    if radius > 0.0:
        d = m[0] - centre[0], m[1] - centre[1], m[2] - centre[2]
        e = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / radius - 1.0
        state[index] += a * (e * e - state[index])
    return state[index]


@kernel(inline=True)
def _less_offset(m, state):
    """The field sample m less the offset in use."""
    b = state[OFFSET]
    return m[0] - b[0], m[1] - b[1], m[2] - b[2]


@kernel(inline=True)
def hard_iron_step(state, coef, m, gap, norm_tol, steady_steps):
    """(the field sample m (3-tuple, finite) less the offset estimate after updating it,
    whether the offset was taken or dropped at this sample); state (STATE_SIZE entries) in
    place, coef from coefficients. gap: steps since the last field sample; norm_tol and
    steady_steps: the heading guard's norm tolerance and mag_new_time in steps."""
    cal_steps, spread_min, tol, recent_steps = coef[0], coef[1], coef[2], coef[3]
    if cal_steps <= 0.0:
        return m, False
    _accumulate(state[SUMS], m, 1.0 - pull(gap, 1.0 / cal_steps, coef[4]))
    state[AGE] += gap
    b, radius, distance, raw_radius, raw_distance = _fit(state[SUMS])
    a = pull(gap, 1.0 / recent_steps, coef[5])
    recent_fit = _recent(state, RECENT_FIT, m, b, radius, a)
    recent_raw = _recent(state, RECENT_RAW, m, (0.0, 0.0, 0.0), raw_radius, a)
    fits = radius > 0.0 and distance < tol * radius
    raw_fits = raw_distance < tol * raw_radius
    offset = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
    better = fits and distance < EXPLAINED * raw_distance  # the sphere about b, not about 0, is the window's
    explained = better and offset > norm_tol * radius
    left_fit = fits and recent_fit > tol * tol
    # the sphere about 0 needs no spread: samples off the field's own norm, even at rest, show it has changed
    left_raw = raw_fits and not better and recent_raw > tol * tol
    was_used = state[OFFSET.start] != 0.0 or state[OFFSET.start + 1] != 0.0 or state[OFFSET.start + 2] != 0.0
    drop = raw_fits and was_used  # only an offset in use can be dropped
    unfit = not (fits or raw_fits)  # the window fits neither sphere: it holds a change, or a field that varies
    covered = spread_min * (radius if fits else raw_radius)  # the least spread that tells a sphere
    if (left_fit or explained or drop or unfit) and _spread(state[SUMS]) < covered:
        left_fit = explained = drop = unfit = False  # too few directions to tell a sphere
    if state[AGE] >= steady_steps and (left_fit or left_raw or unfit):
        # the field has changed (the latest samples have left the window's sphere, or a window covering every
        # direction fits none): the fit starts afresh
        _accumulate(state[SUMS], m, 0.0)
        state[FIT_STEPS] = state[RAW_STEPS] = state[RECENT_FIT] = state[RECENT_RAW] = state[AGE] = 0.0
        return _less_offset(m, state), False
    changed = False
    if explained:
        state[FIT_STEPS] += gap
        state[RAW_STEPS] = 0.0
        if state[FIT_STEPS] >= steady_steps:
            for i in range(3):
                state[OFFSET.start + i] = b[i]
            changed = not was_used
    elif drop:
        state[RAW_STEPS] += gap
        state[FIT_STEPS] = 0.0
        if state[RAW_STEPS] >= steady_steps:
            state[OFFSET] = 0.0
            changed = was_used
    else:
        state[FIT_STEPS] = 0.0
        state[RAW_STEPS] = 0.0
    return _less_offset(m, state), changed


def back_dated(mag, offset, fs: float, params) -> np.ndarray:
    """The offset a forward pass used (N×3, field unit; blocks.stages.heading.with_magnetometer)
    with each change moved back to where the field changed, for a whole recording
    offline. The pass proves an offset (taken, dropped: 0, or replaced: a step of more than
    mag_cal_tol of the field's radius) only after the field has fitted it for the heading's
    mag_new_time (s). Between the previous change and this one, the field
    is split where the samples before fit the sphere about the old offset and those after
    the sphere about the new one best (least squares of the distances relative to the
    radius, which hard iron does not change: the median distance from the new offset over
    the mag_new_time that proved it). mag N×3 (rows with a NaN: no sample), params the
    heading stage's, resolved (blocks.stages.heading.resolve)."""
    offset = np.array(offset, dtype=float)
    rows = np.flatnonzero(np.isfinite(mag).all(axis=1))
    used = offset.any(axis=1)
    radius = np.median(np.linalg.norm(mag[rows] - offset[rows], axis=1)) if len(rows) else 0.0
    steps = np.linalg.norm(np.diff(offset, axis=0), axis=1)
    previous = 0
    for k in np.flatnonzero((used[1:] != used[:-1]) | (steps > params["mag_cal_tol"] * radius)) + 1:
        span = rows[(rows >= previous) & (rows < k)]
        if len(span):
            old, new = offset[k - 1], offset[k]
            to_new = np.linalg.norm(mag[span] - new, axis=1)
            proof = span >= k - params["mag_new_time"] * fs
            r = np.median(to_new[proof] if proof.any() else to_new)
            misfit_old = np.concatenate([[0.0], np.cumsum((np.linalg.norm(mag[span] - old, axis=1) / r - 1.0) ** 2)])
            misfit_new = np.concatenate([np.cumsum(((to_new / r - 1.0) ** 2)[::-1])[::-1], [0.0]])
            split = int(np.argmin(misfit_old + misfit_new))  # span[:split] keep the old offset
            offset[span[split] if split < len(span) else k:k] = new
        previous = k
    return offset
