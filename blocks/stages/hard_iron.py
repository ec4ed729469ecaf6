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

The fit runs per field sample in the C core (blocks/core/stages/hard_iron.c), as part of the
heading stage (blocks.stages.heading); its parameters are blocks.tuning.HARD_IRON.
"""
from __future__ import annotations

import numpy as np


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
