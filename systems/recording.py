"""Reading IMU recordings (CSV or BROAD .mat) and writing estimates as CSV."""
from __future__ import annotations

import csv
import itertools
import math
import re
import shlex
import sys
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from .axes import axes_notes, parse_axes

DELIMITERS = (",", ";", "\t")  # the header's most frequent one; with ";" or a tab, "," is a decimal comma
IMU_COLUMNS = ("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
MAG_COLUMNS = ("mag_x", "mag_y", "mag_z")
REF_COLUMNS = ("ref_q_w", "ref_q_x", "ref_q_y", "ref_q_z")  # optional reference orientation, sensor → earth
MOVEMENT_COLUMN = "movement"  # optional: 1 in the phase the errors are measured over, else 0
KNOWN_COLUMNS = ("t", *IMU_COLUMNS, *MAG_COLUMNS, *REF_COLUMNS, MOVEMENT_COLUMN)  # the names a CSV's header may use
MAT_VARIABLES = ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement", "sampling_rate")  # a .mat's (BROAD's)
OUTPUT_COLUMNS = ("t", "q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z")
EULER_COLUMNS = ("roll_deg", "pitch_deg", "yaw_deg")  # with --euler
GYR_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "mdeg/s": math.pi / 180e3}
G_N = 9.80665  # m/s², standard gravity: the unit g of accelerometers (not the local gravity of the filters)
ACC_UNITS = {"m/s2": 1.0, "g": G_N, "mg": G_N / 1e3}
MAG_UNITS = {"uT": 1.0, "nT": 1e-3, "G": 100.0, "mG": 0.1}  # to µT
T_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}  # to s
RATE_RANGE_HZ = (1.0, 1e5)  # sample rates an IMU recording can have; outside, the time unit is wrong
EARTH_FIELD_RANGE_UT = (20.0, 70.0)  # the geomagnetic field's norm anywhere on earth, about 22–67 µT
MAX_GYRO_RAD_S = math.radians(4000.0)  # beyond the widest range of MEMS gyros (±4000 °/s): such values are not rad/s
MAX_GAP_S = 1.0  # longest run of missing samples filled in by default (s)
UNIT_TOLERANCE = 0.1  # largest departure of a reference quaternion's norm from 1 (rounded columns pass)
SATURATION_S = 0.02  # s: a run this long at exactly a column's largest magnitude is the sensor's range
SATURATION_LEAST = {"gyr": 2.0, "acc": 15.0}  # rad/s, m/s²: below every MEMS range (±125 °/s, ±2 g)
MAX_LABEL_ROWS = 3  # rows without a number after the header that are skipped (units); more: refused
JITTER_NOTE = 0.1  # time stamps off the uniform grid by more than this share of a step are noted


class RecordingError(ValueError):
    """A recording that cannot be used as it is; the message says why and what to do."""


@dataclass
class Recording:
    """An IMU recording: gyr (rad/s), acc (m/s²), mag (µT) N×3 in sensor coordinates, fs (Hz).

    quat_ref (N×4, sensor → earth, NaN where lost) and movement (N, bool) come with
    reference recordings such as BROAD's. filled (N, bool) marks the rows put into gaps of
    a CSV's time stamps (not in the input; see _fill_gaps); notes say how the input was
    read where a user should know it.
    """

    name: str
    fs: float
    gyr: np.ndarray
    acc: np.ndarray
    t: np.ndarray
    mag: np.ndarray | None = None
    quat_ref: np.ndarray | None = None
    movement: np.ndarray | None = None
    filled: np.ndarray | None = None
    notes: list[str] = field(default_factory=list)

    def evaluated(self) -> np.ndarray:
        """(N, bool) the samples errors are measured on: the movement phase (every sample
        when the recording has no movement flag) where the reference is finite."""
        if self.quat_ref is None:
            raise RecordingError(f"{self.name}: no optical reference (opt_quat, or the CSV columns "
                                 f"{','.join(REF_COLUMNS)}); cannot evaluate")
        phase = np.ones(len(self.gyr), dtype=bool) if self.movement is None else self.movement
        if not phase.any():
            raise RecordingError(f"{self.name}: the movement flag is 0 throughout: no movement phase to measure")
        ok = phase & np.isfinite(self.quat_ref).all(axis=1)
        if not ok.any():
            raise RecordingError(f"{self.name}: the reference has no valid sample"
                                 f"{'' if self.movement is None else ' during movement'}")
        return ok

    def into_movement(self, seconds: float) -> Recording:
        """The recording from `seconds` (≥ 0) after its movement phase begins: no rest
        before it and a first sample in motion."""
        if self.movement is None or not self.movement.any():
            raise RecordingError(f"{self.name}: no movement phase to start in")
        if not (math.isfinite(seconds) and seconds >= 0):
            raise RecordingError(f"start in the movement phase must be a finite non-negative time, got {seconds!r}")
        k = int(np.argmax(self.movement)) + int(round(seconds * self.fs))
        if k >= len(self.gyr):
            raise RecordingError(f"{self.name}: the recording ends before {seconds:g} s into its movement phase")
        cut = lambda a: None if a is None else a[k:]
        return replace(self, gyr=self.gyr[k:], acc=self.acc[k:], t=self.t[k:], mag=cut(self.mag),
                       quat_ref=cut(self.quat_ref), movement=cut(self.movement), filled=cut(self.filled))


def read_recording(path, fs: float | None = None, gyr_unit: str = "rad/s", acc_unit: str = "m/s2",
                   mag_unit: str = "uT", max_gap: float = MAX_GAP_S, t_unit: str = "s",
                   columns: Mapping[str, str] | None = None, gyr_axes: str | None = None,
                   acc_axes: str | None = None, mag_axes: str | None = None) -> Recording:
    """Read a CSV (header t,gyr_x..z,acc_x..z[,mag_x..z][,ref_q_w..z][,movement]; t may be
    replaced by fs) or a BROAD .mat, in the units given (GYR_UNITS, ACC_UNITS, MAG_UNITS,
    T_UNITS), into rad/s, m/s², µT and s (values no IMU gives: _check_values). columns
    ({our name: the CSV's}) reads a header
    with other names (a logger's export) without editing the file. gyr_axes, acc_axes,
    mag_axes: signed axis maps into the output's frame (systems.axes.parse_axes); an
    accelerometer or magnetometer that does not turn as the gyro says is noted
    (systems.axes.axes_notes). A CSV's time stamps may jitter and skip samples:
    runs of missing samples up to max_gap seconds are filled in (_fill_gaps), longer ones
    refused; so are runs of gyro or accelerometer values that are not finite
    (_fill_non_finite)."""
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"{path}: no such file")
    units = ((gyr_unit, GYR_UNITS), (acc_unit, ACC_UNITS), (mag_unit, MAG_UNITS), (t_unit, T_UNITS))
    if any(unit not in known for unit, known in units):
        raise RecordingError(f"units must be one of {', '.join(str(list(known)) for _, known in units)}")
    if fs is not None and not (math.isfinite(fs) and fs > 0):
        raise RecordingError(f"the sample rate must be a finite positive number of Hz, got {fs!r}")
    if not (math.isfinite(max_gap) and max_gap >= 0):
        raise RecordingError(f"the longest gap to fill must be a finite number of seconds ≥ 0, got {max_gap!r}")
    maps = {name: parse_axes(text) for name, text in (("gyr", gyr_axes), ("acc", acc_axes), ("mag", mag_axes))
            if text is not None}
    columns = dict(columns or {})
    mat = path.suffix.lower() == ".mat"
    known = MAT_VARIABLES if mat else KNOWN_COLUMNS
    unknown = [name for name in columns if name not in known]
    if unknown:
        raise RecordingError(f"--column names {', '.join(unknown)}; a {'.mat' if mat else 'CSV'}'s names read are "
                             f"{', '.join(known)}")
    shared = sorted({c for c in columns.values() if list(columns.values()).count(c) > 1})
    if shared:
        raise RecordingError(f"--column gives the file's column {', '.join(shared)} more than one name")
    rec = _read_mat(path, fs, columns) if mat else _read_csv(path, fs, max_gap, T_UNITS[t_unit], columns)
    if fs is not None and abs(rec.fs - fs) > 0.01 * fs:
        raise RecordingError(f"{path}: --fs {fs:g} Hz disagrees with the recording's {rec.fs:g} Hz")
    rec.gyr = rec.gyr * GYR_UNITS[gyr_unit]
    rec.acc = rec.acc * ACC_UNITS[acc_unit]
    if rec.mag is not None and np.isnan(rec.mag).any(axis=1).all():
        rec.mag = None
        rec.notes.append(f"{rec.name}: the magnetometer has no sample (NaN throughout); heading from the gyro")
    if rec.mag is not None:
        rec.mag = rec.mag * MAG_UNITS[mag_unit]
    _check_shapes(rec)
    _check_rate(rec.name, rec.fs)
    _fill_non_finite(rec, max_gap)
    _check_values(rec, gyr_unit, acc_unit)
    rec.notes += _saturation_notes(rec)
    for name, matrix in maps.items():
        if getattr(rec, name) is not None:
            setattr(rec, name, getattr(rec, name) @ matrix.T)
    rec.notes += axes_notes(rec.name, rec.gyr, rec.acc, rec.mag, rec.fs)
    return rec


def print_notes(notes) -> None:
    """Notes on how a recording was read (None entries skipped), on standard error."""
    for note in notes:
        if note:
            print(f"attitude: note: {note}", file=sys.stderr)


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


def _read_csv(path: Path, fs: float | None, max_gap: float, t_scale: float, columns: dict) -> Recording:
    with path.open(newline="", encoding="utf-8-sig") as fh:  # a spreadsheet's byte-order mark is not a name
        first = fh.readline()
        following = list(itertools.islice(fh, MAX_LABEL_ROWS + 1))
    delimiter = max(DELIMITERS, key=first.count)
    header = next(csv.reader([first], delimiter=delimiter), None)
    if not header:
        raise RecordingError(f"{path}: empty file; expected a header t,{','.join(IMU_COLUMNS)}")
    header = [h.strip() for h in header]
    header[0] = header[0].lstrip("#").strip()  # a header marked as a comment (numpy.savetxt's default)
    header = _renamed(path, header, columns)
    missing = [c for c in IMU_COLUMNS if c not in header]
    if missing:
        raise RecordingError(f"{path}: missing columns {', '.join(missing)} (header: {','.join(header)})"
                             f"{_column_hint(missing, header)}")
    for group, what in ((MAG_COLUMNS, "the magnetometer"), (REF_COLUMNS, "the reference")):
        given = [c for c in group if c in header]
        if given and len(given) < len(group):
            raise RecordingError(f"{path}: {what} needs all of {','.join(group)}, "
                                 f"the header has only {','.join(given)}")
    if "t" not in header and fs is None:
        raise RecordingError(f"{path}: no 't' column; give the sample rate with --fs HZ{_column_hint(['t'], header)}")
    labels = _label_rows(following, delimiter)
    try:
        with warnings.catch_warnings():  # no rows: said below, not as numpy's warning
            warnings.simplefilter("ignore", UserWarning)
            with path.open(encoding="utf-8-sig") as fh:
                rows = fh if delimiter == "," else (_decimal_points(line, delimiter) for line in fh)
                data = np.loadtxt(rows, delimiter=delimiter, skiprows=1 + len(labels), ndmin=2, dtype=float)
    except ValueError:
        raise RecordingError(f"{path}: {_first_bad_line(path, delimiter, header, 1 + len(labels))}") from None
    if data.shape[0] == 0 or data.shape[1] != len(header):
        raise RecordingError(f"{path}: expected {len(header)} columns of numbers and at least one row")
    col = {name: data[:, i] for i, name in enumerate(header)}
    columns = lambda names: np.column_stack([col[c] for c in names]) if all(c in col for c in names) else None
    movement = col.get(MOVEMENT_COLUMN)
    rec = Recording(path.stem, 0.0, columns(IMU_COLUMNS[:3]), columns(IMU_COLUMNS[3:]),
                    None if "t" not in col else col["t"] * t_scale,
                    columns(MAG_COLUMNS), columns(REF_COLUMNS),
                    None if movement is None else _flag(path, MOVEMENT_COLUMN, movement))
    if labels:
        rec.notes.append(f"{rec.name}: {len(labels)} row{'s' * (len(labels) > 1)} after the header without a number "
                         f"skipped (units?): {' / '.join(labels)}")
    unknown = [c for c in header if c not in KNOWN_COLUMNS]
    if unknown:
        absent = [c for c in KNOWN_COLUMNS if c not in header]
        rec.notes.append(f"{rec.name}: columns not read: {', '.join(unknown)}{_column_hint(absent, unknown)}")
    if rec.t is None:
        rec.fs, rec.t = float(fs), np.arange(1, data.shape[0] + 1) / fs
        return rec
    if not np.isfinite(rec.t).all():
        raise RecordingError(f"{path}: column t has non-finite values")
    if len(rec.t) == 1 and fs is not None:  # one time stamp gives no rate; --fs does
        rec.fs = float(fs)
        return rec
    index, rec.fs, off_grid = _sample_grid(path, rec.t, max_gap)
    if off_grid > JITTER_NOTE:
        rec.notes.append(f"{rec.name}: time stamps up to {off_grid:.0%} of a step off a uniform grid; "
                         f"the samples are taken as uniform at {rec.fs:.6g} Hz")
    if index[-1] + 1 > len(index):
        rec = _fill_gaps(rec, index)
    return rec


def _decimal_points(line: str, delimiter: str) -> str:
    """line with its decimal commas as points, where the separator is not the comma."""
    return line if delimiter == "," else line.replace(",", ".")


def _label_rows(lines, delimiter: str) -> list[str]:
    """Of the lines right after the header, the first ones (at most MAX_LABEL_ROWS) in
    which no field is a number: a units row ("s,rad/s,…") or a second header line, as
    loggers write them."""
    labels = []
    for line in lines:
        fields = _decimal_points(line, delimiter).strip().split(delimiter)
        if not line.strip() or any(_is_number(f) for f in fields):
            break
        labels.append(line.strip())
    return labels if len(labels) <= MAX_LABEL_ROWS else []


def _first_bad_line(path: Path, delimiter: str, header: list[str], skip: int) -> str:
    """Where the rows after the first `skip` lines stop being numbers under the header, said
    with the file's line number and the column's name."""
    with path.open(encoding="utf-8-sig") as fh:
        for number, line in enumerate(fh, start=1):
            text = line.strip()
            if number <= skip or not text or text.startswith("#"):
                continue
            fields = _decimal_points(text, delimiter).split(delimiter)
            if len(fields) != len(header):
                return f"line {number} has {len(fields)} fields, the header {len(header)}: {text[:80]!r}"
            for name, field in zip(header, fields):
                if not _is_number(field):
                    return f"unreadable number in line {number}, column {name}: {field.strip()[:40]!r}"
    return "unreadable numbers"


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _renamed(path: Path, header: list[str], columns: dict) -> list[str]:
    """header with the names columns maps ({ours: the file's}) replaced by ours; a column
    of the file that has one of those names already is left unread. Names read twice are
    refused."""
    absent = [theirs for theirs in columns.values() if theirs not in header]
    if absent:
        raise RecordingError(f"{path}: --column names {', '.join(absent)}, not in the header ({','.join(header)})")
    ours = {theirs: name for name, theirs in columns.items()}
    header = [ours.get(h, f"{h} (replaced by --column)" if h in columns else h) for h in header]
    twice = sorted({h for h in header if h in KNOWN_COLUMNS and header.count(h) > 1})
    if twice:
        raise RecordingError(f"{path}: the header has {', '.join(twice)} more than once")
    return header


def _column_hint(wanted, header) -> str:
    """The --column flags that would read header names equal to wanted ones but for case,
    spaces and punctuation (Gyr_X, GyrX, "gyr x" for gyr_x), as a hint."""
    key = lambda name: re.sub(r"[^a-z0-9]", "", name.lower())
    found = {key(h): h for h in header}
    flags = [f"--column {shlex.quote(f'{c}={found[key(c)]}')}" for c in wanted if key(c) in found]
    return f"; to read them pass {' '.join(flags)}" if flags else ""


def _sample_grid(path: Path, t: np.ndarray, max_gap: float) -> tuple[np.ndarray, float, float]:
    """(index of each row on a uniform grid, its rate in Hz, largest distance of a time
    stamp from the grid in steps). Each time step counts as the whole number of median
    steps nearest to it, so jitter below half a step is tolerated and a longer step is a
    run of missing samples; the rate comes from the whole span, so rounded time stamps
    do not bias it."""
    if len(t) < 2:
        raise RecordingError(f"{path}: one sample cannot give a sample rate; give --fs HZ")
    dt = np.diff(t)
    if np.any(dt <= 0):
        r = int(np.argmax(dt <= 0))
        raise RecordingError(f"{path}: column t must increase strictly (row {r + 2}: {t[r + 1]:g} s after {t[r]:g} s)")
    step = float(np.median(dt))
    count = np.rint(dt / step)
    if np.any(count < 1):
        r = int(np.argmax(count < 1))
        raise RecordingError(f"{path}: column t is irregular: the step to row {r + 2} is {dt[r]:g} s, "
                             f"less than half the usual {step:g} s")
    index = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
    fs = float(index[-1] / (t[-1] - t[0]))
    _check_rate(path, fs)  # before the gaps, which a wrong time unit makes look long
    off_grid = float(np.max(np.abs(t - t[0] - index / fs)) * fs)
    if off_grid > 0.5:
        raise RecordingError(f"{path}: column t is irregular: time stamps up to {off_grid:.1f} steps off "
                             f"a uniform grid at {fs:.6g} Hz (does the sample rate change?)")
    r = int(np.argmax(count))
    if (count[r] - 1) / fs > max_gap:
        raise RecordingError(f"{path}: {int(count[r]) - 1} samples missing after row {r + 1} (t = {t[r]:g} s), "
                             f"a gap of {(count[r] - 1) / fs:g} s, longer than --max-gap {max_gap:g} s; "
                             "split the recording there or raise --max-gap")
    return index, fs, off_grid


def _fill_gaps(rec: Recording, index: np.ndarray) -> Recording:
    """rec on its whole uniform grid (rows at index, ascending from 0): the rows put into
    the gaps have gyro, accelerometer and time interpolated linearly between the rows
    either side, no magnetometer or reference sample (NaN) and the movement flag of the
    row before; filled marks them."""
    grid = np.arange(index[-1] + 1)
    filled = np.ones(len(grid), dtype=bool)
    filled[index] = False
    interpolated = lambda a: np.column_stack([np.interp(grid, index, c) for c in a.T])

    def absent(a):
        if a is None:
            return None
        out = np.full((len(grid), a.shape[1]), np.nan)
        out[index] = a
        return out

    gaps = np.diff(index) - 1
    count = int((gaps > 0).sum())
    rec.notes.append(f"{rec.name}: {int(gaps.sum())} missing samples in {count} gap{'s' * (count > 1)} "
                     f"(the longest {gaps.max() / rec.fs:g} s) filled in: gyro and accelerometer interpolated "
                     "linearly, no magnetometer or reference sample there; estimates are written for the "
                     "input's rows only")
    return replace(rec, gyr=interpolated(rec.gyr), acc=interpolated(rec.acc),
                   t=np.interp(grid, index, rec.t), mag=absent(rec.mag), quat_ref=absent(rec.quat_ref),
                   movement=None if rec.movement is None else rec.movement[np.searchsorted(index, grid, "right") - 1],
                   filled=filled)


def _flag(path: Path, name: str, values) -> np.ndarray:
    """A 0/1 column as booleans; anything else is refused."""
    values = np.asarray(values, dtype=float)
    bad = (values != 0) & (values != 1)
    if bad.any():
        r = int(np.argmax(bad))
        raise RecordingError(f"{path}: {name} must be 0 or 1, row {r + 1} has {values[r]:g}")
    return values == 1


def _read_mat(path: Path, fs: float | None, columns: dict) -> Recording:
    """A BROAD recording, its variables (MAT_VARIABLES) renamed from the file's by columns
    ({BROAD's name: the file's}); without a sampling_rate variable, at fs (Hz) if given."""
    from scipy.io import loadmat

    try:
        mat = loadmat(path, squeeze_me=True)
    except NotImplementedError:  # scipy's answer to a v7.3 file
        mat = _read_mat_v73(path)
    except Exception as exc:  # scipy raises several types for damaged files
        raise RecordingError(f"{path}: not a readable MATLAB file ({exc})") from None
    variables = ", ".join(k for k in mat if not k.startswith("__")) or "none"
    absent = [theirs for theirs in columns.values() if theirs not in mat]
    if absent:
        raise RecordingError(f"{path}: --column names {', '.join(absent)}, not a variable of the file ({variables})")
    mat = {**{k: v for k, v in mat.items() if k not in columns},
           **{ours: mat[theirs] for ours, theirs in columns.items()}}
    missing = [k for k in ("imu_gyr", "imu_acc", *(() if fs else ("sampling_rate",))) if k not in mat]
    if missing:
        raise RecordingError(f"{path}: missing variables {', '.join(missing)} (expected a BROAD recording"
                             f"{'; without sampling_rate give --fs HZ' if 'sampling_rate' in missing else ''}; "
                             f"the file has {variables}: name them with --column, e.g. --column imu_gyr=NAME)")
    try:
        fs = float(mat["sampling_rate"]) if "sampling_rate" in mat else fs
    except (TypeError, ValueError):
        raise RecordingError(f"{path}: sampling_rate must be one number (Hz)") from None
    gyr = np.atleast_2d(np.asarray(mat["imu_gyr"], dtype=float))
    acc = np.atleast_2d(np.asarray(mat["imu_acc"], dtype=float))
    n = len(gyr)

    def optional(key, width):
        if key not in mat:
            return None
        value = np.asarray(mat[key], dtype=float)
        if value.size != n * max(width, 1):
            raise RecordingError(f"{path}: {key} has {value.size} values, expected {n}"
                                 f"{f'×{width}' if width else ''} (one per sample of imu_gyr)")
        return value.reshape(n, width) if width else value.reshape(n)

    movement = optional("movement", 0)
    return Recording(
        path.stem, fs, gyr, acc, np.arange(1, n + 1) / fs, optional("imu_mag", 3),
        optional("opt_quat", 4), None if movement is None else _flag(path, "movement", movement),
    )


def _read_mat_v73(path: Path) -> dict:
    """The numeric variables of a MATLAB v7.3 file (HDF5), as loadmat(squeeze_me=True)
    gives them from older versions: HDF5 holds MATLAB's arrays transposed."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return {name: np.squeeze(np.asarray(item).T) for name, item in f.items()
                    if isinstance(item, h5py.Dataset) and item.dtype.kind in "fiub"}
    except OSError as exc:
        raise RecordingError(f"{path}: not a readable MATLAB v7.3 file ({exc})") from None


def _check_rate(name, fs: float) -> None:
    low, high = RATE_RANGE_HZ
    if not (math.isfinite(fs) and low <= fs <= high):
        raise RecordingError(f"{name}: a sample rate of {fs:.6g} Hz is outside the {low:g}–{high:g} Hz of IMUs; "
                             f"are the time stamps in seconds? If not, pass --t-unit ({', '.join(T_UNITS)})")


def _other_unit(units: dict, given: str, value: float, plausible) -> str | None:
    """The unit of `units` that would make value (read in `given`) plausible, if any."""
    return next((u for u, factor in units.items() if u != given and plausible(value / units[given] * factor)), None)


def _check_shapes(rec: Recording) -> None:
    for name in ("gyr", "acc"):
        a = getattr(rec, name)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) != len(rec.gyr) or len(a) == 0:
            hint = "; stored as 3×N? transpose it" if a.ndim == 2 and a.shape[0] == 3 else ""
            raise RecordingError(f"{rec.name}: {name} must be N×3 with N ≥ 1, got {a.shape}{hint}")


def _fill_non_finite(rec: Recording, max_gap: float) -> None:
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


def _saturation_notes(rec: Recording) -> list[str]:
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


def _check_values(rec: Recording, gyr_unit: str, acc_unit: str) -> None:
    """The gyro's peak and the accelerometer's median norm against what IMUs give: values
    that another unit would make plausible are a unit mistake, refused with the flag that
    fixes it; values no unit explains (a sensor shaken far harder than a person moves) are
    noted, and read as they are."""
    peak = float(np.max(np.abs(rec.gyr)))
    norm = float(np.median(np.linalg.norm(rec.acc, axis=1)))
    for flag, units, given, value, plausible, what in (
        ("--gyr-unit", GYR_UNITS, gyr_unit, peak, lambda p: p <= MAX_GYRO_RAD_S,
         f"gyro reaches {peak:.1f} rad/s read as {gyr_unit}, beyond any MEMS gyro"),
        ("--acc-unit", ACC_UNITS, acc_unit, norm, lambda n: 4.0 < n < 20.0,  # m/s², gravity and a person's motion
         f"median accelerometer norm is {norm:.3g} m/s² read as {acc_unit}, far from gravity"),
    ):
        if plausible(value):
            continue
        other = _other_unit(units, given, value, plausible)
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


def euler_degrees(quat) -> np.ndarray:
    """Roll, pitch, yaw (N×3, degrees) of quaternions (N×4, w first, sensor → earth): the
    Z-Y-X sequence, as the AttitudeEstimator FMU's outputs roll, pitch, yaw."""
    return Rotation.from_quat(quat, scalar_first=True).as_euler("ZYX", degrees=True)[:, ::-1]


def write_estimate(path, t, quat, up, euler: bool = False, extra=None) -> None:
    """CSV with columns t,q_w,q_x,q_y,q_z,g_x,g_y,g_z (g the unit up-vector, sensor
    coordinates); euler adds roll, pitch and yaw in degrees (EULER_COLUMNS, euler_degrees);
    extra ({name: N×3 or N}) adds name_x,name_y,name_z, or the column name, after them."""
    columns, table = OUTPUT_COLUMNS, [t, quat, up]
    if euler:
        columns = columns + EULER_COLUMNS
        table.append(euler_degrees(quat))
    for name, values in (extra or {}).items():
        columns = columns + ((name,) if np.ndim(values) == 1 else tuple(f"{name}_{a}" for a in "xyz"))
        table.append(values)
    np.savetxt(path, np.column_stack(table), delimiter=",", header=",".join(columns), comments="", fmt="%.10g")
