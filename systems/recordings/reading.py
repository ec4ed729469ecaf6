"""Reading IMU recordings (CSV or BROAD .mat) into a Recording: units, columns, time stamps
and gaps, axes; the checks of systems.recordings.checks."""
from __future__ import annotations

import csv
import io
import itertools
import math
import re
import shlex
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from attitude_fmu.systems.recordings.axes import axes_notes, parse_axes
from attitude_fmu.systems.recordings.checks import (
    any_of_row,
    check_rate,
    check_shapes,
    check_values,
    fill_invalid,
    hold_until_gravity,
    mark_held,
    pile_up_notes,
    saturation_notes,
)
from attitude_fmu.systems.recordings.header import (
    check_units,
    numbered,
    positions,
    shown,
    without_units,
    written_units,
)
from attitude_fmu.systems.recordings.recording import (
    ACC_UNITS,
    GYR_UNITS,
    IMU_COLUMNS,
    KNOWN_COLUMNS,
    MAG_COLUMNS,
    MAG_UNITS,
    MAT_VARIABLES,
    MOVEMENT_COLUMN,
    PARQUET_SUFFIX,
    REF_COLUMNS,
    T_UNITS,
    Recording,
    RecordingError,
)
from attitude_fmu.systems.recordings.stamps import timing
from attitude_fmu.systems.recordings.tables import Source, csv_numbers, decimal_points, parquet_header, parquet_numbers

DELIMITERS = (",", ";", "\t")  # the header's most frequent one; with ";" or a tab, "," is a decimal comma
MAX_GAP_S = 1.0  # longest run of missing samples filled in by default (s)
MAX_HEADER_CHARS = 4 * 2**20  # a CSV's first line is read up to this: its header (100 000 named columns fit)
MAX_LABEL_ROWS = 3  # rows without a number after the header that are skipped (units); more: refused
DEFAULT_UNITS = {"gyr": "rad/s", "acc": "m/s2", "mag": "uT", "t": "s"}  # a unit flag not given


def read_recording(path, fs: float | None = None, gyr_unit: str | None = None, acc_unit: str | None = None,
                   mag_unit: str | None = None, max_gap: float = MAX_GAP_S, t_unit: str | None = None,
                   columns: Mapping[str, str] | None = None, gyr_axes: str | None = None,
                   acc_axes: str | None = None, mag_axes: str | None = None) -> Recording:
    """Read a CSV (header `t,gyr_x..z,acc_x..z[,mag_x..z][,ref_q_w..z][,movement]`; t may be
    replaced by fs) or a BROAD .mat, in the units given (GYR_UNITS, ACC_UNITS, MAG_UNITS,
    T_UNITS; None: not given, DEFAULT_UNITS, and a unit the CSV's header writes that differs
    is refused, systems.recordings.header.check_units), into rad/s, m/s², µT and s (values no
    IMU gives: check_values). columns ({our name: the CSV's, or "#N" its N-th column from 1})
    reads a header with other names (a logger's export) without editing the file. fs
    overrides a CSV's time stamps (systems.recordings.stamps). A magnetometer held between
    its updates is read as no sample on the rows that repeat (mark_held). gyr_axes, acc_axes,
    mag_axes: signed axis maps into the output's frame (systems.recordings.axes.parse_axes); an
    accelerometer or magnetometer that does not turn as the gyro says is noted
    (systems.recordings.axes.axes_notes). A CSV's time stamps may jitter and skip samples:
    runs of missing samples up to max_gap seconds are filled in (_fill_gaps), longer ones
    refused; so are runs of gyro or accelerometer values that are not finite
    (fill_invalid), and samples beyond every IMU's range."""
    given = {"gyr": gyr_unit, "acc": acc_unit, "mag": mag_unit, "t": t_unit}
    used = {kind: (unit or DEFAULT_UNITS[kind], unit is not None) for kind, unit in given.items()}
    gyr_unit, acc_unit, mag_unit, t_unit = (used[kind][0] for kind in ("gyr", "acc", "mag", "t"))
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
    source = Source.of(path)
    path = source.path
    mat = source.suffix == ".mat"
    known = MAT_VARIABLES if mat else KNOWN_COLUMNS
    unknown = [name for name in columns if name not in known]
    if unknown:
        raise RecordingError(f"--column names {', '.join(unknown)}; a {'.mat' if mat else 'CSV'}'s names read are "
                             f"{', '.join(known)}")
    shared = sorted({c for c in columns.values() if list(columns.values()).count(c) > 1})
    if shared:
        raise RecordingError(f"--column gives the file's column {', '.join(shared)} more than one name")
    if mat:
        numbered_ = [c for c in columns.values() if c.startswith("#")]
        if numbered_:
            raise RecordingError(f"--column {', '.join(numbered_)}: a .mat's variables are named, not numbered")
        rec = _read_mat(source, fs, columns)
    else:
        try:
            rec = _read_table(source, fs, max_gap, used, columns)
        except UnicodeDecodeError as exc:
            raise source.not_text(exc) from None
    if fs is not None and abs(rec.fs - fs) > 0.01 * fs:
        raise RecordingError(f"{source.label}: --fs {fs:g} Hz disagrees with the recording's {rec.fs:g} Hz")
    rec.gyr *= GYR_UNITS[gyr_unit]  # in place: the recording's arrays are its own
    rec.acc *= ACC_UNITS[acc_unit]
    mark_held(rec)
    if rec.mag is not None and any_of_row(np.isnan(rec.mag)).all():
        rec.mag = None
        rec.notes.append(f"{rec.name}: the magnetometer has no sample (NaN throughout); heading from the gyro")
    if rec.mag is not None:
        rec.mag *= MAG_UNITS[mag_unit]
    check_shapes(rec)
    check_rate(rec.name, rec.fs)
    check_values(rec, gyr_unit, acc_unit)
    fill_invalid(rec, max_gap)
    hold_until_gravity(rec)
    clipped = saturation_notes(rec)
    rec.notes += [*clipped.values(), *pile_up_notes(rec, skip=clipped)]
    for name, matrix in maps.items():
        if getattr(rec, name) is not None:
            setattr(rec, name, getattr(rec, name) @ matrix.T)
    rec.notes += axes_notes(rec.name, rec.gyr, rec.acc, rec.mag, rec.fs, gyr_unit)
    return rec


def _read_table(source: Source, fs: float | None, max_gap: float, used: dict, columns: dict) -> Recording:
    """A CSV or (by its suffix) a Parquet file: header t,gyr_x..z,acc_x..z and the optional
    columns, checked before the numbers are read, with the units the header writes against
    those used ({quantity: (unit, given?)}); its time stamps read as systems.recordings.stamps
    says."""
    path, parquet = source.label, source.suffix == PARQUET_SUFFIX
    labels, delimiter = [], ","
    if parquet:
        header = parquet_header(source)
    else:
        source.refuse_padding()
        with source.text(newline="") as fh:
            first = fh.readline(MAX_HEADER_CHARS + 1)
            if len(first) > MAX_HEADER_CHARS:
                raise RecordingError(f"{path}: its first line, the header, runs past {MAX_HEADER_CHARS} characters; "
                                     f"expected a header t,{','.join(IMU_COLUMNS)} (is it a CSV?)")
            following = list(itertools.islice(fh, MAX_LABEL_ROWS + 1))
        delimiter = max(DELIMITERS, key=first.count)
        header = next(csv.reader([first], delimiter=delimiter), None)
        if not header:
            raise RecordingError(f"{path}: empty file; expected a header t,{','.join(IMU_COLUMNS)}")
        header = [h.strip() for h in header]
        header[0] = header[0].lstrip("#").strip()  # a header marked as a comment (numpy.savetxt's default)
        labels = _label_rows(following, delimiter)
    original = header
    header = _renamed(path, header, columns)
    header, with_units = without_units(header, [c for c in KNOWN_COLUMNS if c not in columns])
    unit_notes = check_units(path, source.path.stem, written_units(header, original, [
        next(csv.reader([line], delimiter=delimiter)) for line in labels]), used)
    missing = [c for c in IMU_COLUMNS if c not in header]
    if missing:
        unclear = "" in header or len(set(header)) < len(header)  # select by position
        raise RecordingError(f"{path}: missing columns {', '.join(missing)} (header: {shown(header)})"
                             f"{'; name them by position, --column NAME=#N: ' + numbered(header) if unclear else ''}"
                             f"{_column_hint(missing, header)}")
    for group, what in ((MAG_COLUMNS, "the magnetometer"), (REF_COLUMNS, "the reference")):
        given = [c for c in group if c in header]
        if given and len(given) < len(group):
            raise RecordingError(f"{path}: {what} needs all of {','.join(group)}, "
                                 f"the header has only {','.join(given)}")
    if "t" not in header and fs is None:  # after the units: "t (ms)" says --t-unit
        raise RecordingError(f"{path}: no 't' column; give the sample rate with --fs HZ{_column_hint(['t'], header)}")
    wanted = [k for k, name in enumerate(header) if name in KNOWN_COLUMNS]  # the others are not read
    if parquet:
        data = parquet_numbers(source, header, wanted, flags=(MOVEMENT_COLUMN,))
    else:
        skip = 1 + len(labels)
        data = csv_numbers(source, delimiter, len(header), skip, wanted,
                           lambda: _first_bad_line(source, delimiter, header, skip, wanted))
    if len(data) == 0:
        raise RecordingError(f"{path}: expected {len(header)} columns of numbers and at least one row")
    index = {name: i for i, name in enumerate(header)}
    stack = lambda names: data.stack([index[c] for c in names]) if all(c in index for c in names) else None
    movement = data.column(index[MOVEMENT_COLUMN]) if MOVEMENT_COLUMN in index else None
    rec = Recording(source.path.stem, 0.0, stack(IMU_COLUMNS[:3]), stack(IMU_COLUMNS[3:]),
                    None if "t" not in index else data.column(index["t"]) * T_UNITS[used["t"][0]],
                    stack(MAG_COLUMNS), stack(REF_COLUMNS),
                    None if movement is None else _flag(path, MOVEMENT_COLUMN, movement))
    del data
    rec.notes += unit_notes
    if with_units:
        rec.notes.append(f"{rec.name}: read {', '.join(f'{original[k]!r} as {header[k]}' for k in with_units)}")
    if labels:
        rec.notes.append(f"{rec.name}: {len(labels)} row{'s' * (len(labels) > 1)} after the header without a number "
                         f"skipped (units?): {' / '.join(labels)}")
    unknown = [c for c in header if c not in KNOWN_COLUMNS]
    if unknown:
        absent = [c for c in KNOWN_COLUMNS if c not in header]
        rec.notes.append(f"{rec.name}: columns not read: {', '.join(c or '(unnamed)' for c in unknown)}"
                         f"{_column_hint(absent, unknown)}")
    if rec.t is None:
        rec.fs, rec.t = float(fs), np.arange(1, len(rec.gyr) + 1) / fs
        return rec
    if not np.isfinite(rec.t).all():
        raise RecordingError(f"{path}: column t has non-finite values")
    if len(rec.t) == 1:  # one time stamp gives no rate; --fs does
        if fs is None:
            raise RecordingError(f"{path}: one sample cannot give a sample rate; give --fs HZ")
        rec.fs = float(fs)
        return rec
    index, rec.fs, notes = timing(path, rec.name, rec.t, fs, max_gap)
    rec.notes += notes
    if index is not None and index[-1] + 1 > len(index):
        rec = _fill_gaps(rec, index)
    return rec


def _label_rows(lines, delimiter: str) -> list[str]:
    """Of the lines right after the header, the first ones (at most MAX_LABEL_ROWS) in
    which no field is a number: a units row ("s,rad/s,…") or a second header line, as
    loggers write them."""
    labels = []
    for line in lines:
        fields = next(csv.reader([decimal_points(line, delimiter).strip()], delimiter=delimiter), [])
        if not line.strip() or any(_is_number(f) for f in fields):
            break
        labels.append(line.strip())
    return labels if len(labels) <= MAX_LABEL_ROWS else []


def _first_bad_line(source: Source, delimiter: str, header: list[str], skip: int, wanted) -> str:
    """Where the rows after the first `skip` lines stop being numbers in the columns wanted
    (positions in header) or have another number of fields (quoted as the csv module reads
    them), said with the file's line number and the column's name."""
    with source.text(newline="") as fh:
        rows = csv.reader(fh, delimiter=delimiter)
        for fields in rows:
            number, text = rows.line_num, delimiter.join(fields)
            if number <= skip or not text.strip() or text.lstrip().startswith("#"):
                continue
            if len(fields) != len(header):
                return f"line {number} has {len(fields)} fields, the header {len(header)}: {text[:80]!r}"
            for k in wanted:
                if not _is_number(decimal_points(fields[k], delimiter)):
                    return f"unreadable number in line {number}, column {header[k]}: {fields[k].strip()[:40]!r}"
    return "unreadable numbers"


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _renamed(path, header: list[str], columns: dict) -> list[str]:
    """header with the columns that columns maps ({ours: the file's name or "#N"}) named
    ours; a column of the file that has one of those names already is left unread. Names
    read twice are refused."""
    placed = positions(path, header, columns)
    ours = {k: name for name, k in placed.items()}
    header = [ours.get(k, f"{h} (replaced by --column)" if h in columns else h) for k, h in enumerate(header)]
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


def _flag(path, name: str, values) -> np.ndarray:
    """A 0/1 column as booleans; anything else is refused."""
    values = np.asarray(values, dtype=float)
    bad = (values != 0) & (values != 1)
    if bad.any():
        r = int(np.argmax(bad))
        raise RecordingError(f"{path}: {name} must be 0 or 1, row {r + 1} has {values[r]:g}")
    return values == 1


def _read_mat(source: Source, fs: float | None, columns: dict) -> Recording:
    """A BROAD recording, its variables (MAT_VARIABLES) renamed from the file's by columns
    ({BROAD's name: the file's}); without a sampling_rate variable, at fs (Hz) if given. The
    file's other variables are listed, not read; logical ones are read as booleans."""
    from scipy.io import loadmat, whosmat

    path = source.label
    file = source.path if source.data is None else io.BytesIO(source.data)
    read = [columns.get(name, name) for name in MAT_VARIABLES]
    try:
        listed = {name: kind for name, _, kind in whosmat(file)}  # each variable's class, its data unread
        if source.data is not None:
            file.seek(0)
        mat = loadmat(file, squeeze_me=True, variable_names=[name for name in read if name in listed])
        mat = {name: np.asarray(value, dtype=bool) if listed[name] == "logical" else value
               for name, value in mat.items() if not name.startswith("__")}
    except NotImplementedError:  # scipy's answer to a v7.3 file
        listed, mat = _read_mat_v73(path, file, read)
    except Exception as exc:  # scipy raises several types for damaged files
        raise RecordingError(f"{path}: not a readable MATLAB file ({exc})") from None
    variables = ", ".join(listed) or "none"
    absent = [theirs for theirs in columns.values() if theirs not in listed]
    if absent:
        raise RecordingError(f"{path}: --column names {', '.join(absent)}, not a variable of the file ({variables})")
    mat = {**{k: v for k, v in mat.items() if k not in columns},
           **{ours: mat[theirs] for ours, theirs in columns.items()}}
    missing = [k for k in ("imu_gyr", "imu_acc", *(() if fs else ("sampling_rate",))) if k not in mat]
    if missing:
        raise RecordingError(f"{path}: missing variables {', '.join(missing)} (expected a BROAD recording"
                             f"{'; without sampling_rate give --fs HZ' if 'sampling_rate' in missing else ''}; "
                             f"the file has {variables}: name them with --column, e.g. --column imu_gyr=NAME)")
    if "sampling_rate" in mat:
        rate = _numbers(path, mat, "sampling_rate")
        if rate.size != 1:
            raise RecordingError(f"{path}: sampling_rate must be one number (Hz), it has {rate.size}")
        fs = float(rate.reshape(()))
    check_rate(path, fs)
    gyr, acc = (np.atleast_2d(_numbers(path, mat, key)) for key in ("imu_gyr", "imu_acc"))
    n = len(gyr)
    if gyr.ndim == acc.ndim == 2 and gyr.shape[1] == acc.shape[1] == 3 and len(acc) != n:
        raise RecordingError(f"{path}: imu_acc has {len(acc)} samples, imu_gyr {n}: expected one accelerometer "
                             "sample per gyro sample (both N×3, at one rate)")

    def optional(key, width):
        if key not in mat:
            return None
        value = _numbers(path, mat, key)
        if value.size != n * max(width, 1):
            raise RecordingError(f"{path}: {key} has {value.size} values, expected {n}"
                                 f"{f'×{width}' if width else ''} (one per sample of imu_gyr)")
        return value.reshape(n, width) if width else value.reshape(n)

    movement = optional("movement", 0)
    return Recording(
        source.path.stem, fs, gyr, acc, np.arange(1, n + 1) / fs, optional("imu_mag", 3),
        optional("opt_quat", 4), None if movement is None else _flag(path, "movement", movement),
    )


def _numbers(path: str, mat: dict, key: str) -> np.ndarray:
    """The variable key of a MATLAB file as an array of floats, or an error saying what it
    holds: complex numbers (their imaginary part would be lost) and logical values are
    refused, but for the movement flag, which may be logical."""
    value = np.asarray(mat[key])
    kind = value.dtype.kind
    if kind == "c" or kind == "b" and key != MOVEMENT_COLUMN:
        raise RecordingError(f"{path}: {key} holds {'complex numbers' if kind == 'c' else 'logical values'}, "
                             "expected real numbers")
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise RecordingError(f"{path}: {key} holds {type(mat[key]).__name__} "
                             f"{getattr(mat[key], 'dtype', '')}, expected a numeric array") from None


def _read_mat_v73(path: str, file, read) -> tuple[list[str], dict]:
    """(the names of the variables, those of read as loadmat(squeeze_me=True) gives them
    from older versions) of a MATLAB v7.3 file (HDF5) at file: HDF5 holds MATLAB's arrays
    transposed, complex ones as pairs (real, imag), logical ones as uint8 marked so."""
    import h5py

    try:
        with h5py.File(file, "r") as f:
            listed = [name for name in f if not name.startswith("#")]  # "#refs#": MATLAB's own
            mat = {name: _v73_array(f[name]) for name in read if name in f and isinstance(f[name], h5py.Dataset)}
    except OSError as exc:
        raise RecordingError(f"{path}: not a readable MATLAB v7.3 file ({exc})") from None
    return listed, mat


def _v73_array(item) -> np.ndarray:
    """A v7.3 dataset as the array MATLAB holds (see _read_mat_v73)."""
    value = np.asarray(item)
    if value.dtype.names == ("real", "imag"):
        value = value["real"] + 1j * value["imag"]
    elif item.attrs.get("MATLAB_class") in (b"logical", "logical"):
        value = value.astype(bool)
    return np.squeeze(value.T)
