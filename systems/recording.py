"""Reading IMU recordings (CSV or BROAD .mat) and writing estimates as CSV."""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from blocks.earth_filters import STANDARD_GRAVITY

IMU_COLUMNS = ("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
MAG_COLUMNS = ("mag_x", "mag_y", "mag_z")
OUTPUT_COLUMNS = ("t", "q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z")
GYR_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0}
ACC_UNITS = {"m/s2": 1.0, "g": STANDARD_GRAVITY}
MAG_UNITS = {"uT": 1.0, "nT": 1e-3, "G": 100.0, "mG": 0.1}  # to µT
EARTH_FIELD_RANGE_UT = (20.0, 70.0)  # the geomagnetic field's norm anywhere on earth, about 22–67 µT
MAX_GYRO_RAD_S = 40.0  # beyond the ±2000 °/s range of MEMS gyros: such values are not rad/s


class RecordingError(ValueError):
    """A recording that cannot be used as it is; the message says why and what to do."""


@dataclass
class Recording:
    """An IMU recording: gyr (rad/s), acc (m/s²), mag (µT) N×3 in sensor coordinates, fs (Hz).

    quat_ref (N×4, sensor → earth, NaN where lost) and movement (N, bool) come with
    reference recordings such as BROAD's.
    """

    name: str
    fs: float
    gyr: np.ndarray
    acc: np.ndarray
    t: np.ndarray
    mag: np.ndarray | None = None
    quat_ref: np.ndarray | None = None
    movement: np.ndarray | None = None

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
                       quat_ref=cut(self.quat_ref), movement=cut(self.movement))


def read_recording(path, fs: float | None = None, gyr_unit: str = "rad/s", acc_unit: str = "m/s2",
                   mag_unit: str = "uT") -> Recording:
    """Read a CSV (header t,gyr_x..z,acc_x..z[,mag_x..z]; t may be replaced by fs) or a BROAD
    .mat, in the units given (GYR_UNITS, ACC_UNITS, MAG_UNITS), into rad/s, m/s² and µT."""
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"{path}: no such file")
    if gyr_unit not in GYR_UNITS or acc_unit not in ACC_UNITS or mag_unit not in MAG_UNITS:
        raise RecordingError(f"units must be one of {list(GYR_UNITS)}, {list(ACC_UNITS)} and {list(MAG_UNITS)}")
    rec = _read_mat(path) if path.suffix.lower() == ".mat" else _read_csv(path, fs)
    if fs is not None and abs(rec.fs - fs) > 0.01 * fs:
        raise RecordingError(f"{path}: --fs {fs:g} Hz disagrees with the recording's {rec.fs:g} Hz")
    rec.gyr = rec.gyr * GYR_UNITS[gyr_unit]
    rec.acc = rec.acc * ACC_UNITS[acc_unit]
    if rec.mag is not None:
        rec.mag = rec.mag * MAG_UNITS[mag_unit]
    _check_values(rec)
    return rec


def field_norm_note(rec: Recording) -> str | None:
    """A note when the magnetometer's median norm (µT after the unit conversion) is far
    from the earth's field: a unit not given, or a sensor that reports raw counts. The
    heading and hard-iron estimators use directions and relative norms only, so they work
    in any unit; only the hard-iron offset is then reported in the input's unit."""
    if rec.mag is None:
        return None
    rows = rec.mag[np.isfinite(rec.mag).all(axis=1)]
    if not len(rows):
        return None
    norm = float(np.median(np.linalg.norm(rows, axis=1)))
    low, high = EARTH_FIELD_RANGE_UT
    if low / 2 <= norm <= 2 * high:
        return None
    return (f"{rec.name}: the magnetometer's median norm is {norm:.3g} µT, far from the earth's "
            f"{low:g}–{high:g} µT; if it is not in µT pass --mag-unit ({', '.join(MAG_UNITS)}). The heading "
            "works in any unit; the hard-iron offset is reported in the input's")


def _read_csv(path: Path, fs: float | None) -> Recording:
    with path.open(newline="") as fh:
        header = next(csv.reader(fh), None)
    if not header:
        raise RecordingError(f"{path}: empty file; expected a header t,{','.join(IMU_COLUMNS)}")
    header = [h.strip() for h in header]
    missing = [c for c in IMU_COLUMNS if c not in header]
    if missing:
        raise RecordingError(f"{path}: missing columns {', '.join(missing)} (header: {','.join(header)})")
    if "t" not in header and fs is None:
        raise RecordingError(f"{path}: no 't' column; give the sample rate with --fs HZ")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2, dtype=float)
    except ValueError as exc:
        raise RecordingError(f"{path}: unreadable number ({exc})") from None
    if data.shape[0] == 0 or data.shape[1] != len(header):
        raise RecordingError(f"{path}: expected {len(header)} columns of numbers and at least one row")
    col = {name: data[:, i] for i, name in enumerate(header)}
    if "t" in col:
        t = col["t"]
        if not np.isfinite(t).all():
            raise RecordingError(f"{path}: column t has non-finite values")
        fs = _rate_from_times(path, t)
    else:
        t = np.arange(1, data.shape[0] + 1) / fs
    mag = np.column_stack([col[c] for c in MAG_COLUMNS]) if all(c in col for c in MAG_COLUMNS) else None
    return Recording(
        path.stem, float(fs), np.column_stack([col[c] for c in IMU_COLUMNS[:3]]),
        np.column_stack([col[c] for c in IMU_COLUMNS[3:]]), t, mag,
    )


def _rate_from_times(path: Path, t: np.ndarray) -> float:
    if len(t) < 2:
        raise RecordingError(f"{path}: one sample cannot give a sample rate; give --fs HZ")
    dt = np.diff(t)
    step = float(np.median(dt))
    if step <= 0 or np.any(dt <= 0):
        raise RecordingError(f"{path}: column t must increase strictly")
    if np.max(np.abs(dt - step)) > 0.01 * step:
        raise RecordingError(f"{path}: column t is not uniformly sampled (steps {dt.min():g}…{dt.max():g} s)")
    return 1.0 / step


def _read_mat(path: Path) -> Recording:
    from scipy.io import loadmat

    try:
        mat = loadmat(path, squeeze_me=True)
    except Exception as exc:  # scipy raises several types for damaged files
        raise RecordingError(f"{path}: not a readable MATLAB file ({exc})") from None
    missing = [k for k in ("imu_gyr", "imu_acc", "sampling_rate") if k not in mat]
    if missing:
        raise RecordingError(f"{path}: missing variables {', '.join(missing)} (expected a BROAD recording)")
    fs = float(mat["sampling_rate"])
    gyr = np.atleast_2d(np.asarray(mat["imu_gyr"], dtype=float))
    acc = np.atleast_2d(np.asarray(mat["imu_acc"], dtype=float))
    n = len(gyr)

    def optional(key, width):
        if key not in mat:
            return None
        value = np.asarray(mat[key], dtype=float)
        value = value.reshape(n, width) if width else value.reshape(n)
        return value

    movement = optional("movement", 0)
    return Recording(
        path.stem, fs, gyr, acc, np.arange(1, n + 1) / fs, optional("imu_mag", 3),
        optional("opt_quat", 4), None if movement is None else movement.astype(bool),
    )


def _check_values(rec: Recording) -> None:
    for name in ("gyr", "acc"):
        a = getattr(rec, name)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) != len(rec.gyr) or len(a) == 0:
            raise RecordingError(f"{rec.name}: {name} must be N×3 with N ≥ 1, got {a.shape}")
        bad = ~np.isfinite(a)
        if bad.any():
            row = int(np.argwhere(bad)[0][0])
            raise RecordingError(f"{rec.name}: {name} has {int(bad.sum())} non-finite values (first in row {row + 1})")
    if not (math.isfinite(rec.fs) and rec.fs > 0):
        raise RecordingError(f"{rec.name}: sample rate must be positive, got {rec.fs!r}")
    peak = float(np.max(np.abs(rec.gyr)))
    if peak > MAX_GYRO_RAD_S:
        raise RecordingError(
            f"{rec.name}: gyro reaches {peak:.1f} rad/s, beyond any MEMS gyro; "
            "the gyro columns look like deg/s: pass --gyr-unit deg/s"
        )
    norm = float(np.median(np.linalg.norm(rec.acc, axis=1)))
    if 0.5 < norm < 2.0:
        raise RecordingError(f"{rec.name}: median accelerometer norm is {norm:.2f}: looks like g; pass --acc-unit g")
    if not 4.0 < norm < 20.0:
        raise RecordingError(f"{rec.name}: median accelerometer norm is {norm:.3g}, far from gravity; expected m/s²")


def write_estimate(path, t, quat, up) -> None:
    """CSV with columns t,q_w,q_x,q_y,q_z,g_x,g_y,g_z (g the unit up-vector, sensor coordinates)."""
    table = np.column_stack([t, quat, up])
    np.savetxt(path, table, delimiter=",", header=",".join(OUTPUT_COLUMNS), comments="", fmt="%.10g")
