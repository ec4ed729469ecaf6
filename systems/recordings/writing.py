"""Estimates and recordings out: the writer (CSV, or Parquet by the file name's suffix) and its columns."""
from __future__ import annotations

from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu.systems.recordings.output import replaced
from attitude_fmu.systems.recordings.recording import (
    IMU_COLUMNS,
    MAG_COLUMNS,
    MOVEMENT_COLUMN,
    PARQUET_SUFFIX,
    REF_COLUMNS,
)

OUTPUT_COLUMNS = ("t", "q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z")
EULER_COLUMNS = ("roll_deg", "pitch_deg", "yaw_deg")  # with --euler
CSV_DIGITS = 10  # significant digits of the CSV's estimates (t and Parquet keep every bit)
ROWS_PER_BATCH = 1 << 16  # rows converted and written at a time: memory stays small whatever the length
CSV_THREADS = 2  # threads that turn a CSV's batches into text at once


def euler_degrees(quat) -> np.ndarray:
    """Roll, pitch, yaw (N×3, degrees) of quaternions (N×4, w first, sensor → earth): the
    Z-Y-X sequence, as the AttitudeEstimator FMU's outputs roll, pitch, yaw."""
    return Rotation.from_quat(quat, scalar_first=True).as_euler("ZYX", degrees=True)[:, ::-1]


def output_name(source) -> str:
    """The name of the output of input source in an output folder: NAME.csv for NAME.csv
    or NAME.mat, NAME.parquet for NAME.parquet."""
    source = Path(source)
    return source.stem + (PARQUET_SUFFIX if source.suffix.lower() == PARQUET_SUFFIX else ".csv")


def significant(x, digits: int = CSV_DIGITS) -> np.ndarray:
    """x rounded to `digits` significant digits, each value the double nearest to its
    rounded decimal (so that the shortest text that reads it back, as the CSV writer
    gives, has at most that many digits); zeros, non-finite values and magnitudes beyond
    1e±(22 − digits) are left as they are."""
    x = np.asarray(x, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = digits - 1 - np.floor(np.log10(np.abs(x)))
        exact = np.abs(k) <= 22  # False where k is not finite
        power = _POWERS_OF_TEN[np.where(exact, np.abs(k), 0).astype(np.intp)]  # exact; IEEE × and ÷ round correctly
        rounded = np.where(k >= 0, np.rint(x * power) / power, np.rint(x / power) * power)
    return np.where(exact, rounded, x)


_POWERS_OF_TEN = np.array([float(10 ** k) for k in range(23)])


def _arrow(values: np.ndarray):
    """A contiguous float64 numpy array as a pyarrow array on its memory (pyarrow's own
    conversion imports pandas, a good part of a second at every start)."""
    import pyarrow as pa

    return pa.Array.from_buffers(pa.float64(), len(values), [None, pa.py_buffer(values)])


def write_estimate(path, t, quat, up, euler: bool = False, extra=None) -> None:
    """Columns t,q_w,q_x,q_y,q_z,g_x,g_y,g_z (g the unit up-vector, sensor coordinates);
    euler adds roll, pitch and yaw in degrees (EULER_COLUMNS, euler_degrees); extra
    ({name: N×3 or N}) adds name_x,name_y,name_z, or the column name, after them. Written as
    write_table writes."""
    blocks = [(("t",), np.asarray(t)[:, None]), (OUTPUT_COLUMNS[1:5], quat), (OUTPUT_COLUMNS[5:], up)]
    if euler:
        blocks.append((EULER_COLUMNS, lambda rows: euler_degrees(quat[rows])))
    for name, values in (extra or {}).items():
        values = np.asarray(values)
        blocks.append(((name,), values[:, None]) if values.ndim == 1 else (tuple(f"{name}_{a}" for a in "xyz"), values))
    write_table(path, blocks)


def write_table(path, blocks) -> None:
    """Columns of floats, t first: blocks is a list of (names, values), values N×len(names) or a
    function of a slice of rows that gives them for those rows. A path ending in
    PARQUET_SUFFIX gets a Parquet file (float64, every bit), any other a CSV (the first
    column with the digits that read back to its every bit, up to 17: epoch time stamps
    keep their steps; the others CSV_DIGITS significant digits); "-" the CSV on standard
    output. Written by systems.recordings.output.replaced: complete, or not at all; in batches
    of ROWS_PER_BATCH rows, each made (and a CSV's turned into text, on CSV_THREADS threads) while
    the ones before are written."""
    import pyarrow as pa

    names = [n for columns, _ in blocks for n in columns]
    n_rows = len(blocks[0][1])
    parquet = Path(str(path)).suffix.lower() == PARQUET_SUFFIX
    schema = pa.schema([(n, pa.float64()) for n in names])

    def rows_batch(start: int):
        rows = slice(start, start + ROWS_PER_BATCH)
        columns = []
        for _, values in blocks:
            values = values(rows) if callable(values) else values[rows]
            columns += [np.ascontiguousarray(c, dtype=float) for c in values.T]
        return pa.RecordBatch.from_arrays([_arrow(c if parquet or j == 0 else significant(c))  # 0: t
                                           for j, c in enumerate(columns)], schema=schema)

    with replaced(path) as fh:
        if parquet:
            import pyarrow.parquet as pq

            with pq.ParquetWriter(fh, schema, use_dictionary=False) as writer:  # measurements do not repeat
                for batch in _in_order(rows_batch, range(0, n_rows, ROWS_PER_BATCH), 1):
                    writer.write_batch(batch)
            return
        import pyarrow.csv as pc

        options = pc.WriteOptions(include_header=False, quoting_style="none")

        def text(start: int):
            sink = pa.BufferOutputStream()
            pc.write_csv(rows_batch(start), sink, write_options=options)
            return sink.getvalue()

        fh.write((",".join(names) + "\n").encode())  # the header unquoted, as the columns are
        for part in _in_order(text, range(0, n_rows, ROWS_PER_BATCH), CSV_THREADS):
            fh.write(part)


def _in_order(make, starts, threads: int):
    """make(start) for each of starts, in their order, made on up to `threads` threads (pyarrow
    and numpy run without Python's lock) while the ones before are written: at most two per
    thread at a time, so that memory stays small whatever the length."""
    with ThreadPoolExecutor(max_workers=threads) as pool:
        pending = deque()
        for start in starts:
            pending.append(pool.submit(make, start))
            if len(pending) > 2 * threads:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()


def write_recording(path, rec) -> None:
    """A recording (systems.recordings.recording.Recording) as the reader reads it back: t,
    the gyro (rad/s) and accelerometer (m/s²), then where it has them the magnetometer (µT),
    the reference (REF_COLUMNS) and the movement flag (0 or 1); written as write_table writes."""
    blocks = [(("t",), np.asarray(rec.t, dtype=float)[:, None]), (IMU_COLUMNS[:3], rec.gyr), (IMU_COLUMNS[3:], rec.acc)]
    for columns, values in ((MAG_COLUMNS, rec.mag), (REF_COLUMNS, rec.quat_ref), ((MOVEMENT_COLUMN,), rec.movement)):
        if values is not None:
            blocks.append((columns, np.asarray(values, dtype=float).reshape(len(rec.t), len(columns))))
    write_table(path, blocks)
