"""Checks of a recording's values: sample rate, shapes, non-finite rows, units, ranges,
saturation and the magnetometer's norm; what they refuse or note."""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.pipeline.causal import MAX_GYR_RAD_S
from attitude_fmu.systems.recordings.recording import (
    ACC_UNITS,
    GYR_UNITS,
    MAG_UNITS,
    T_UNITS,
    Recording,
    RecordingError,
)

RATE_RANGE_HZ = (1.0, 1e5)  # sample rates an IMU recording can have; outside, the time unit is wrong
EARTH_FIELD_RANGE_UT = (20.0, 70.0)  # the geomagnetic field's norm anywhere on earth, about 22–67 µT
UNIT_TOLERANCE = 0.1  # largest departure of a reference quaternion's norm from 1 (rounded columns pass)
SATURATION_S = 0.02  # s: a run this long at exactly a column's largest magnitude is the sensor's range
SATURATION_LEAST = {"gyr": 2.0, "acc": 15.0}  # rad/s, m/s²: below every MEMS range (±125 °/s, ±2 g)


def field_norm_note(rec: Recording) -> str | None:
    """A note when the magnetometer's median norm (µT after the unit conversion) is far
    from the earth's field: a unit not given, or a sensor that reports raw counts. The
    heading and hard-iron estimators use directions and relative norms only, so they work
    in any unit; only the hard-iron offset is then reported in the input's unit."""
    if rec.mag is None:
        return None
    rows = rec.mag[np.isfinite(rec.mag).all(axis=1)]  # read_recording leaves no magnetometer without a sample
    norm = float(np.median(np.linalg.norm(rows, axis=1)))
    low, high = EARTH_FIELD_RANGE_UT
    if low / 2 <= norm <= 2 * high:
        return None
    return (f"{rec.name}: the magnetometer's median norm is {norm:.3g} µT, far from the earth's "
            f"{low:g}–{high:g} µT; if it is not in µT pass --mag-unit ({', '.join(MAG_UNITS)}). The heading "
            "works in any unit; the hard-iron offset is reported in the input's")


def check_rate(name, fs: float) -> None:
    low, high = RATE_RANGE_HZ
    if not (math.isfinite(fs) and low <= fs <= high):
        raise RecordingError(f"{name}: a sample rate of {fs:.6g} Hz is outside the {low:g}–{high:g} Hz of IMUs; "
                             f"are the time stamps in seconds? If not, pass --t-unit ({', '.join(T_UNITS)})")


def other_unit(units: dict, given: str, value: float, plausible) -> str | None:
    """The unit of `units` that would make value (read in `given`) plausible, if any."""
    return next((u for u, factor in units.items() if u != given and plausible(value / units[given] * factor)), None)


def check_shapes(rec: Recording) -> None:
    for name in ("gyr", "acc"):
        a = getattr(rec, name)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) != len(rec.gyr) or len(a) == 0:
            hint = "; stored as 3×N? transpose it" if a.ndim == 2 and a.shape[0] == 3 else ""
            raise RecordingError(f"{rec.name}: {name} must be N×3 with N ≥ 1, got {a.shape}{hint}")


def fill_non_finite(rec: Recording, max_gap: float) -> None:
    """Gyro and accelerometer values that are not finite (a logger's dropouts) in runs of
    rows up to max_gap seconds, between finite rows, interpolated linearly in place, and
    noted; at the first or last row, or in a longer run, refused."""
    bad_rows = ~(np.isfinite(rec.gyr).all(axis=1) & np.isfinite(rec.acc).all(axis=1))
    if not bad_rows.any():
        return
    rows = np.flatnonzero(bad_rows)
    starts = rows[np.concatenate([[True], np.diff(rows) > 1])]
    ends = rows[np.concatenate([np.diff(rows) > 1, [True]])]
    longest = int(np.argmax(ends - starts))
    if bad_rows[0] or bad_rows[-1]:
        edge = "first" if bad_rows[0] else "last"
        raise RecordingError(f"{rec.name}: gyro or accelerometer values that are not finite in the {edge} row; "
                             "cut the rows before the first or after the last finite one")
    if (ends[longest] - starts[longest] + 1) / rec.fs > max_gap:
        raise RecordingError(f"{rec.name}: gyro or accelerometer values that are not finite in rows "
                             f"{starts[longest] + 1}–{ends[longest] + 1}, longer than --max-gap {max_gap:g} s; "
                             "split the recording there or raise --max-gap")
    index = np.arange(len(bad_rows))
    for a in (rec.gyr, rec.acc):
        for c in range(3):
            good = np.isfinite(a[:, c])
            a[~good, c] = np.interp(index[~good], index[good], a[good, c])
    rec.notes.append(f"{rec.name}: {len(rows)} rows with gyro or accelerometer values that are not finite, in "
                     f"{len(starts)} run{'s' * (len(starts) > 1)} (the longest "
                     f"{(ends[longest] - starts[longest] + 1) / rec.fs:g} s), interpolated linearly")


def saturation_notes(rec: Recording) -> list[str]:
    """A note per sensor with an axis held at exactly its largest magnitude (at least
    SATURATION_LEAST) for SATURATION_S or longer: its range, beyond which it misses the
    motion. A smooth peak within the range holds one value for a few ms at most, however
    fine the sampling. An axis that repeats its values half the time elsewhere (a
    noise-free simulation: exact zeros at rest, a turntable's constant rate throughout) is
    not taken for a clipped one."""
    notes = []
    for name, what, unit in (("gyr", "gyro", "rad/s"), ("acc", "accelerometer", "m/s²")):
        clipped = []
        for axis, column in zip("xyz", np.abs(getattr(rec, name)).T):
            peak = float(column.max())
            held = column == peak
            edges = np.diff(np.concatenate([[0], held.astype(np.int8), [0]]))
            longest = int((np.flatnonzero(edges < 0) - np.flatnonzero(edges > 0)).max())
            others = column[~held]
            repeats = np.mean(others[1:] == others[:-1]) if len(others) > 1 else 1.0
            if peak >= SATURATION_LEAST[name] and longest >= max(3, SATURATION_S * rec.fs) and repeats < 0.5:
                clipped.append(f"{axis} at ±{peak:.4g} {unit} for up to {1e3 * longest / rec.fs:.0f} ms "
                               f"({int(held.sum())} samples)")
        if clipped:
            notes.append(f"{rec.name}: the {what} stays at its largest value on {'; '.join(clipped)}: its range? "
                         "Where it saturates the estimate misses the motion beyond it; record with a wider range")
    return notes


def check_values(rec: Recording, gyr_unit: str, acc_unit: str) -> None:
    """The gyro's peak and the accelerometer's median norm against what IMUs give: values
    that another unit would make plausible are a unit mistake, refused with the flag that
    fixes it; values no unit explains (a sensor shaken far harder than a person moves) are
    noted, and read as they are."""
    peak = float(np.max(np.abs(rec.gyr)))
    norm = float(np.median(np.linalg.norm(rec.acc, axis=1)))
    for flag, units, given, value, plausible, what in (
        ("--gyr-unit", GYR_UNITS, gyr_unit, peak, lambda p: p <= MAX_GYR_RAD_S,
         f"gyro reaches {peak:.1f} rad/s read as {gyr_unit}, beyond any MEMS gyro"),
        ("--acc-unit", ACC_UNITS, acc_unit, norm, lambda n: 4.0 < n < 20.0,  # m/s², gravity and a person's motion
         f"median accelerometer norm is {norm:.3g} m/s² read as {acc_unit}, far from gravity"),
    ):
        if plausible(value):
            continue
        other = other_unit(units, given, value, plausible)
        if other is not None:
            raise RecordingError(f"{rec.name}: {what}; looks like {other}: pass {flag} {other}")
        rec.notes.append(f"{rec.name}: {what}, and no other unit ({', '.join(units)}) explains it; read as it is")
    if rec.quat_ref is not None:
        norm = np.linalg.norm(rec.quat_ref, axis=1)
        bad = np.isfinite(norm) & (np.abs(norm - 1.0) > UNIT_TOLERANCE)
        if bad.any():
            row = int(np.argmax(bad))
            raise RecordingError(f"{rec.name}: the reference quaternion in row {row + 1} has the norm "
                                 f"{norm[row]:.3g}; expected unit quaternions w,x,y,z (NaN where lost)")
