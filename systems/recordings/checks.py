"""Checks of a recording's values: sample rate, shapes, non-finite rows, units, ranges,
saturation and the magnetometer's norm; what they refuse or note."""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.pipeline.causal import MAX_ACC_M_S2, MAX_GYR_RAD_S
from attitude_fmu.systems.recordings.recording import (
    ACC_UNITS,
    G_N,
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
SPIKES = (3, 0.001)  # at most this many samples beyond a sensor's range, or this share of them, are spikes
NO_GRAVITY_M_S2 = 1.0  # an accelerometer norm below this shows no gravity (at rest one reads 9.81 m/s²)
RANGES = "gyro ±4000 °/s, accelerometer ±400 g per axis"  # MAX_GYR_RAD_S, MAX_ACC_M_S2 as the notes say them
PILE_BAND = 0.005  # samples within this share of an axis's extreme value are "at" it
PILE_INSIDE = 10  # ... compared with this many bands of that width just inside it (5 % of the extreme)
PILE_RATIO = 4.0  # a pile-up: the extreme band holds this many times the samples of those (a smooth peak: 0.43)
PILE_LEAST = (10, 0.001)  # ... and at least this many samples and this share of them
RANGE_MATCH = 0.1  # a pile-up within this share of a usual full-scale range is named with it
ACC_RANGES_G = (2, 4, 6, 8, 12, 16, 24, 32, 64, 100, 200, 400)  # usual accelerometer ranges, ±g
GYR_RANGES_DEG_S = (125, 250, 300, 500, 1000, 2000, 4000)  # usual gyro ranges, ±°/s
NORM_ROWS = 100_000  # rows, evenly spread, whose median the field's norm is taken from (a unit's factor of 2)


def field_norm_note(rec: Recording) -> str | None:
    """A note when the magnetometer's median norm (µT after the unit conversion; over at most
    about NORM_ROWS rows, evenly spread) is far from the earth's field: a unit not given, or a
    sensor that reports raw counts. The heading and hard-iron estimators use directions and
    relative norms only, so they work in any unit; only the hard-iron offset is then reported in
    the input's unit."""
    if rec.mag is None:
        return None
    rows = rec.mag[all_of_row(np.isfinite(rec.mag))]  # read_recording leaves no magnetometer without a sample
    rows = rows[::max(1, len(rows) // NORM_ROWS)]
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


def all_of_row(mask: np.ndarray) -> np.ndarray:
    """(N, bool) whether each row of mask (N×3, bool) is all True: mask.all(axis=1), column by column
    (numpy's reduction over a row of 3 takes several times as long on a long recording)."""
    return mask[:, 0] & mask[:, 1] & mask[:, 2]


def any_of_row(mask: np.ndarray) -> np.ndarray:
    """(N, bool) whether any of each row of mask (N×3, bool) is True, column by column (as all_of_row)."""
    return mask[:, 0] | mask[:, 1] | mask[:, 2]


def check_shapes(rec: Recording) -> None:
    for name in ("gyr", "acc"):
        a = getattr(rec, name)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) != len(rec.gyr) or len(a) == 0:
            hint = "; stored as 3×N? transpose it" if a.ndim == 2 and a.shape[0] == 3 else ""
            raise RecordingError(f"{rec.name}: {name} must be N×3 with N ≥ 1, got {a.shape}{hint}")


def beyond_range(a, bound: float) -> np.ndarray:
    """(N, bool) the rows of a (N×3) with a finite value beyond ±bound."""
    with np.errstate(invalid="ignore"):
        return any_of_row(np.isfinite(a) & (np.abs(a) > bound))


def fill_invalid(rec: Recording, max_gap: float) -> None:
    """Gyro and accelerometer samples that are invalid, not finite (a logger's dropouts) or
    beyond every IMU's range (MAX_GYR_RAD_S, MAX_ACC_M_S2 per axis: spikes), in runs of
    rows up to max_gap seconds between valid rows, interpolated linearly in place, and
    noted; at the first or last row, or in a longer run, refused."""
    with np.errstate(invalid="ignore"):  # |v| <= bound: False where v is not finite
        valid = all_of_row(np.abs(rec.gyr) <= MAX_GYR_RAD_S) & all_of_row(np.abs(rec.acc) <= MAX_ACC_M_S2)
    if valid.all():
        return
    beyond = beyond_range(rec.gyr, MAX_GYR_RAD_S) | beyond_range(rec.acc, MAX_ACC_M_S2)
    bad_rows = ~valid
    what = {(False, True): "not finite", (True, False): f"beyond every IMU's range ({RANGES})",
            (True, True): f"not finite or beyond every IMU's range ({RANGES})"}[
        beyond.any(), (bad_rows & ~beyond).any()]
    rows = np.flatnonzero(bad_rows)
    starts = rows[np.concatenate([[True], np.diff(rows) > 1])]
    ends = rows[np.concatenate([np.diff(rows) > 1, [True]])]
    longest = int(np.argmax(ends - starts))
    if bad_rows[0] or bad_rows[-1]:
        edge = "first" if bad_rows[0] else "last"
        raise RecordingError(f"{rec.name}: gyro or accelerometer values that are {what} in the {edge} row; "
                             f"cut the rows before the first or after the last valid one")
    if (ends[longest] - starts[longest] + 1) / rec.fs > max_gap:
        raise RecordingError(f"{rec.name}: gyro or accelerometer values that are {what} in rows "
                             f"{starts[longest] + 1}–{ends[longest] + 1}, longer than --max-gap {max_gap:g} s; "
                             "split the recording there or raise --max-gap")
    index = np.arange(len(bad_rows))
    for a, bound in ((rec.gyr, MAX_GYR_RAD_S), (rec.acc, MAX_ACC_M_S2)):
        with np.errstate(invalid="ignore"):
            good = np.abs(a) <= bound  # False where not finite
        for c in range(3):  # each value that is invalid, the others of its row kept
            bad = ~good[:, c]
            a[bad, c] = np.interp(index[bad], index[~bad], a[~bad, c])
    rec.notes.append(f"{rec.name}: {len(rows)} rows with gyro or accelerometer values that are {what}, in "
                     f"{len(starts)} run{'s' * (len(starts) > 1)} (the longest "
                     f"{(ends[longest] - starts[longest] + 1) / rec.fs:g} s), interpolated linearly")


def hold_until_gravity(rec: Recording) -> None:
    """Where the accelerometer shows no gravity at the start (norm below NO_GRAVITY_M_S2:
    a sensor not yet powered, a logger's zeros), those rows are set to no sample (0), in
    place, which the estimators wait over (blocks.pipeline.batch.estimate, as
    OnlineEstimator): they start at rest on the first sample that shows gravity, never on
    "no gravity" taken as down; a note says so. check_values refuses an accelerometer
    without gravity throughout."""
    shows = np.einsum("ij,ij->i", rec.acc, rec.acc) >= NO_GRAVITY_M_S2**2
    first = int(np.argmax(shows))
    if first == 0 or not shows[first]:
        return
    rec.acc[:first] = 0.0
    rec.notes.append(f"{rec.name}: the accelerometer shows no gravity (norm below {NO_GRAVITY_M_S2:g} m/s²) in the "
                     f"first {first} samples ({first / rec.fs:g} s): the estimate waits for sample {first + 1}, the "
                     "first that shows it, and holds its start over them")


def typical_peak(values) -> float:
    """The largest of values (finite ones) once the few largest are set aside as spikes
    (SPIKES): what the sensor reaches, not what one bad sample says."""
    finite = np.isfinite(values)
    v = values if finite.all() else values[finite]
    k = max(SPIKES[0], int(SPIKES[1] * len(v)))
    if len(v) <= k:
        return float(v.max()) if len(v) else 0.0
    return float(np.partition(v, len(v) - k - 1)[len(v) - k - 1])


def _repeats(values) -> float:
    """The share of values that repeat the one before (1 for fewer than two)."""
    return float(np.mean(values[1:] == values[:-1])) if len(values) > 1 else 1.0


def saturation_notes(rec: Recording) -> dict:
    """{gyr or acc: its note} per sensor with an axis held at exactly its largest magnitude (at least
    SATURATION_LEAST) for SATURATION_S or longer: its range, beyond which it misses the
    motion. A smooth peak within the range holds one value for a few ms at most, however
    fine the sampling. An axis that repeats its values half the time elsewhere (a
    noise-free simulation: exact zeros at rest, a turntable's constant rate throughout) is
    not taken for a clipped one."""
    notes = {}
    for name, what, unit in (("gyr", "gyro", "rad/s"), ("acc", "accelerometer", "m/s²")):
        clipped = []
        for axis, column in zip("xyz", np.abs(getattr(rec, name)).T):
            peak = float(column.max())
            if not peak >= SATURATION_LEAST[name]:
                continue
            held = column == peak
            edges = np.diff(np.concatenate([[0], held.astype(np.int8), [0]]))
            longest = int((np.flatnonzero(edges < 0) - np.flatnonzero(edges > 0)).max())
            if longest >= max(3, SATURATION_S * rec.fs) and _repeats(column[~held]) < 0.5:
                clipped.append(f"{axis} at ±{peak:.4g} {unit} for up to {1e3 * longest / rec.fs:.0f} ms "
                               f"({int(held.sum())} samples)")
        if clipped:
            notes[name] = (f"{rec.name}: the {what} stays at its largest value on {'; '.join(clipped)}: its range? "
                           "Where it saturates the estimate misses the motion beyond it; record with a wider range")
    return notes


def pile_up_notes(rec: Recording, skip=()) -> list[str]:
    """A note per sensor (gyr, acc; not those in skip) with an axis piling up at an extreme:
    the samples within PILE_BAND of its largest value of one sign (at least
    SATURATION_LEAST) are at least PILE_LEAST and PILE_RATIO times those in the
    PILE_INSIDE bands of that width just inside it. A smooth peak, however often reached
    and however coarsely sampled, puts fewer there than inside (a sine's arcsine density:
    0.43 times as many); a sensor clipped at its range puts every sample beyond it there,
    exactly or spread by its calibration. Each is named with its value, its share of the
    samples and the usual range (ACC_RANGES_G, GYR_RANGES_DEG_S) within RANGE_MATCH of it.
    An axis that repeats its values half the time elsewhere (a noise-free simulation) is
    not taken for a clipped one."""
    notes = []
    for name, what in (("gyr", "gyro"), ("acc", "accelerometer")):
        if name in skip:
            continue
        piled = []
        for axis, column in zip("xyz", getattr(rec, name).T):
            finite = np.isfinite(column)
            column = column if finite.all() else column[finite]
            for sign in (1.0, -1.0):
                v = column if sign > 0 else -column
                peak = float(v.max()) if len(v) else 0.0
                if peak < SATURATION_LEAST[name]:
                    continue
                at = v >= peak * (1 - PILE_BAND)
                inside = np.count_nonzero((v >= peak * (1 - (1 + PILE_INSIDE) * PILE_BAND)) & ~at)
                least = max(PILE_LEAST[0], PILE_LEAST[1] * len(v))
                if at.sum() >= max(least, PILE_RATIO * inside) and _repeats(v[~at]) < 0.5:
                    piled.append(f"{axis} at {sign * peak:+.4g} {'rad/s' if name == 'gyr' else 'm/s²'} "
                                 f"({_usual_range(name, peak)}): {int(at.sum())} samples, {at.mean():.1%} of them, "
                                 f"within {PILE_BAND:.1%} of it against {inside} in the "
                                 f"{PILE_INSIDE * PILE_BAND:.0%} below")
        if piled:
            notes.append(f"{rec.name}: the {what} piles up at its extremes, clipped at its range: {'; '.join(piled)}. "
                         "Where it clips the estimate misses the motion beyond it; record with a wider range")
    return notes


def _usual_range(name: str, peak: float) -> str:
    """"1.98 g; likely the ±2 g range": peak (rad/s or m/s²) in °/s or g, with the usual
    range of the sensor within RANGE_MATCH of it."""
    if name == "gyr":
        value, ranges, unit = math.degrees(peak), GYR_RANGES_DEG_S, "°/s"
    else:
        value, ranges, unit = peak / G_N, ACC_RANGES_G, "g"
    near = min(ranges, key=lambda r: abs(value / r - 1))
    likely = f"; likely the ±{near:g} {unit} range" if abs(value / near - 1) <= RANGE_MATCH else ""
    return f"{value:.4g} {unit}{likely}"


def mark_held(rec: Recording) -> None:
    """Magnetometer rows that repeat the previous sample exactly (all three axes), where new
    values come every two rows or more in the median (a magnetometer slower than the gyro,
    its last sample held by the logger), set to no sample (NaN, the estimators' convention),
    in place, and noted with the magnetometer's apparent rate. A magnetometer whose values
    change from one row to the next in the median (repeats at rest, or some rows
    interpolated) is read as it is."""
    if rec.mag is None:
        return
    rows = np.flatnonzero(all_of_row(np.isfinite(rec.mag)))
    if len(rows) < 3:
        return
    every = len(rows) == len(rec.mag)  # (then the rows as slices, not copies)
    same = all_of_row((rec.mag[1:] == rec.mag[:-1]) if every else (rec.mag[rows[1:]] == rec.mag[rows[:-1]]))
    new = np.concatenate([rows[:1], rows[1:][~same]])
    if len(new) < 2 or np.median(np.diff(new)) < 2:
        return
    held = rows[1:][same]
    rec.mag[held] = np.nan
    rate = rec.fs * (len(new) - 1) / (new[-1] - new[0])
    rec.notes.append(f"{rec.name}: the magnetometer repeats its previous sample in {len(held)} of {len(rows)} rows: "
                     f"held between updates at about {rate:.3g} Hz (a new value every {np.median(np.diff(new)):g} "
                     "rows in the median); the repeats are taken as no sample (NaN)")


def check_values(rec: Recording, gyr_unit: str, acc_unit: str) -> None:
    """The gyro's peak (typical_peak: a few spikes aside, they are invalid samples for
    fill_invalid) and the accelerometer's median norm, over the finite rows, against what
    IMUs give: values that another unit would make plausible are a unit mistake, refused
    with the flag that fixes it; an accelerometer without gravity (median norm below
    NO_GRAVITY_M_S2) is refused; other values no unit explains (a sensor shaken far harder
    than a person moves) are noted, and read as they are."""
    finite = all_of_row(np.isfinite(rec.gyr)) & all_of_row(np.isfinite(rec.acc))
    if not finite.any():
        return  # fill_invalid refuses it
    rows = slice(None) if finite.all() else finite  # (no copies where every row is)
    magnitude = np.abs(rec.gyr[rows])
    peak = typical_peak(np.maximum(np.maximum(magnitude[:, 0], magnitude[:, 1]), magnitude[:, 2]))
    with np.errstate(over="ignore"):  # a norm beyond the largest float is inf, as far from gravity
        norm = float(np.median(np.linalg.norm(rec.acc[rows], axis=1)))
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
        if flag == "--acc-unit" and norm < NO_GRAVITY_M_S2:
            raise RecordingError(f"{rec.name}: the accelerometer shows no gravity (median norm {norm:.3g} m/s²; at "
                                 f"rest an IMU reads about {G_N:.2f} m/s² along up): are its columns the "
                                 "accelerometer's, and is it in the unit given?")
        rec.notes.append(f"{rec.name}: {what}, and no other unit ({', '.join(units)}) explains it; read as it is")
    if rec.quat_ref is not None:
        norm = np.linalg.norm(rec.quat_ref, axis=1)
        bad = np.isfinite(norm) & (np.abs(norm - 1.0) > UNIT_TOLERANCE)
        if bad.any():
            row = int(np.argmax(bad))
            raise RecordingError(f"{rec.name}: the reference quaternion in row {row + 1} has the norm "
                                 f"{norm[row]:.3g}; expected unit quaternions w,x,y,z (NaN where lost)")
