"""Where a recording's bytes come from (a file, standard input, a pipe) and its columns of
numbers (CSV through pyarrow's reader, numpy's for what that one does not take; Parquet),
with errors that name the source and say what was expected."""
from __future__ import annotations

import errno
import io
import os
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from attitude_fmu.systems.recordings.output import STDIO
from attitude_fmu.systems.recordings.recording import IMU_COLUMNS, PARQUET_SUFFIX, RecordingError

SIGNATURES = {  # how other formats begin, to say what a file that is no text CSV is
    b"MATLAB": "a MATLAB file: name it .mat",
    b"\x89HDF": "an HDF5 file (MATLAB v7.3?): name it .mat",
    b"PAR1": f"a Parquet file: name it {PARQUET_SUFFIX}",
    b"PK\x03\x04": "a zip archive: unpack it",
    b"\x1f\x8b": "gzip-compressed: unpack it",
}


MAX_STREAM_BYTES = 256 * 2**20  # a stream (standard input, a pipe) is read whole into memory up to this; a file is not
CHUNK = 2**20  # bytes read at a time from a stream, and looked at at a time for a file's padding


@dataclass(frozen=True)
class Source:
    """A recording's bytes: a regular file (path), or what a stream gave (data: standard
    input, a pipe, a process substitution), read whole up to MAX_STREAM_BYTES. label names it
    in messages."""

    path: Path
    data: bytes | None = None

    @classmethod
    def of(cls, path) -> "Source":
        """The source of path: "-" is standard input; a path that is not a regular file but
        can be read (/dev/stdin, a named pipe) is read whole; anything else must be a file."""
        if str(path) == STDIO:
            return cls(Path("stdin"), _stream(sys.stdin.buffer, "standard input"))
        path = Path(path)
        if path.is_file():
            return cls(path)
        if path.exists() and not path.is_dir():
            try:
                with path.open("rb") as fh:
                    return cls(path, _stream(fh, str(path)))
            except OSError as exc:
                raise RecordingError(f"{path}: cannot be read ({exc.strerror})") from None
        raise RecordingError(f"{path}: {'a folder, not a file' if path.is_dir() else 'no such file'}")

    @property
    def label(self) -> str:
        return "standard input" if self.data is not None and self.path == Path("stdin") else str(self.path)

    @property
    def suffix(self) -> str:
        return self.path.suffix.lower()

    def text(self, newline=None):
        """The bytes as text (UTF-8, a spreadsheet's byte-order mark dropped)."""
        if self.data is None:
            return self.path.open(newline=newline, encoding="utf-8-sig")
        return io.TextIOWrapper(io.BytesIO(self.data), encoding="utf-8-sig", newline=newline)

    def binary(self):
        """What pyarrow reads: the file's path, or the bytes."""
        import pyarrow as pa

        return str(self.path) if self.data is None else pa.BufferReader(self.data)

    def refuse_padding(self) -> None:
        """RecordingError where the text ends in NUL bytes, as a logger's file preallocated on a card does:
        how many, from which offset, and the command that cuts them (a file's tail is looked at, not read
        whole)."""
        if self.data is not None:
            size, start = len(self.data), len(self.data.rstrip(b"\0"))
        else:
            with self.path.open("rb") as fh:
                size = fh.seek(0, io.SEEK_END)
                start = _data_end(fh.fileno(), size)
                while start > 0:
                    fh.seek(max(0, start - CHUNK))
                    chunk = fh.read(start - max(0, start - CHUNK))
                    kept = len(chunk.rstrip(b"\0"))
                    start -= len(chunk) - kept
                    if kept:
                        break
        if start < size:
            cut = f"; cut them: truncate -s {start} {self.path}" if self.data is None else ""
            raise RecordingError(f"{self.label}: its last {size - start} bytes (from offset {start}) are NUL, not "
                                 f"text: a logger's preallocated space{cut}")

    def not_text(self, exc: UnicodeDecodeError) -> RecordingError:
        """The error for bytes that are no UTF-8 text, with what the file looks like."""
        if self.data is None:
            with self.path.open("rb") as fh:
                head = fh.read(16)
        else:
            head = self.data[:16]
        kind = next((what for sign, what in SIGNATURES.items() if head.startswith(sign)), None)
        return RecordingError(f"{self.label}: not a text CSV (byte 0x{exc.object[exc.start]:02x} at offset "
                              f"{exc.start} of a line is not UTF-8){f'; it looks like {kind}' if kind else ''}; "
                              f"expected a CSV with the header t,{','.join(IMU_COLUMNS)}, a BROAD .mat or a "
                              f"{PARQUET_SUFFIX} file")


class Columns:
    """Columns of numbers by their position in the file, read one at a time (the table they
    come from is kept once, not copied whole): len() rows; column(i) a float array;
    stack(indices) the N×k array of those columns. Only the columns wanted were read:
    column(k) is read(j) for the j-th of them, k = wanted[j]."""

    def __init__(self, rows: int, read, wanted):
        self.rows, self._read, self._place = rows, read, {k: j for j, k in enumerate(wanted)}

    def column(self, k: int) -> np.ndarray:
        return self._read(self._place[k])

    def __len__(self) -> int:
        return self.rows

    def stack(self, indices) -> np.ndarray:
        out = np.empty((self.rows, len(indices)))
        for j, i in enumerate(indices):
            out[:, j] = self.column(i)
        return out


def csv_numbers(source: Source, delimiter: str, width: int, skip: int, wanted, bad_line) -> Columns:
    """The numbers of the columns wanted (positions) of a CSV after its first skip lines,
    width columns separated by delimiter (with ";" or a tab, "," is a decimal comma), fields
    quoted as RFC 4180 says (the csv module's dialect: "a,b" one field, "" a quote, line
    breaks in quotes); lines starting with "#" and empty ones skipped. The other columns are
    split off but never read as numbers: text, empty fields pass. pyarrow's reader takes them;
    what it refuses (a comment after the numbers, ...) numpy's loadtxt tries; what neither
    reads, bad_line() says."""
    import pyarrow as pa
    import pyarrow.csv as pc

    names = [f"c{i}" for i in range(width)]
    read = [names[k] for k in wanted]
    try:
        table = pc.read_csv(
            source.binary(),
            read_options=pc.ReadOptions(skip_rows=skip, column_names=names),
            parse_options=pc.ParseOptions(delimiter=delimiter, invalid_row_handler=_comment_row,
                                          newlines_in_values=True),
            convert_options=pc.ConvertOptions(include_columns=read, column_types={n: pa.float64() for n in read},
                                              null_values=[], strings_can_be_null=False,
                                              decimal_point="." if delimiter == "," else ","))
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        return _loadtxt(source, delimiter, width, skip, wanted, bad_line)
    return Columns(table.num_rows, lambda j: floats(table.column(j)), wanted)


def floats(column) -> np.ndarray:
    """A pyarrow float64 column (chunked; nulls as NaN) as a numpy array, read from its
    buffers: pyarrow's to_numpy imports pandas, a good part of a second at every start."""
    out, at = np.empty(len(column)), 0
    for chunk in column.chunks:
        if chunk.null_count:
            import pyarrow.compute

            chunk = pyarrow.compute.fill_null(chunk, np.nan)
        out[at:at + len(chunk)] = np.frombuffer(chunk.buffers()[1], dtype=np.float64, count=len(chunk),
                                                offset=8 * chunk.offset)
        at += len(chunk)
    return out


def _comment_row(row) -> str:
    return "skip" if row.text is not None and row.text.lstrip().startswith("#") else "error"


def _loadtxt(source: Source, delimiter: str, width: int, skip: int, wanted, bad_line) -> Columns:
    try:
        with warnings.catch_warnings():  # no rows: said by the caller, not as numpy's warning
            warnings.simplefilter("ignore", UserWarning)
            with source.text() as fh:
                rows = fh if delimiter == "," else (decimal_points(line, delimiter) for line in fh)
                data = np.loadtxt(rows, delimiter=delimiter, skiprows=skip, ndmin=2, dtype=float, usecols=wanted,
                                  quotechar='"')
    except ValueError:
        raise RecordingError(f"{source.label}: {bad_line()}") from None
    return Columns(len(data), lambda j: data[:, j], wanted)


def decimal_points(line: str, delimiter: str) -> str:
    """line with its decimal commas as points, where the separator is not the comma."""
    return line if delimiter == "," else line.replace(",", ".")


def parquet_header(source: Source) -> list[str]:
    """The column names of a Parquet file."""
    import pyarrow.parquet as pq

    try:
        return list(pq.read_schema(source.binary()).names)
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise RecordingError(f"{source.label}: not a readable Parquet file ({exc}); expected the columns "
                             f"t,{','.join(IMU_COLUMNS)}") from None


def parquet_numbers(source: Source, header: list[str], wanted, flags=()) -> Columns:
    """The columns wanted (positions) of a Parquet file, numbers of any type read as float64
    (booleans only in the columns named in flags); header names them in messages. The
    other columns are not read."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        file = pq.ParquetFile(source.binary())
        names = file.schema_arrow.names
        table = file.read(columns=[names[k] for k in wanted])
    except Exception as exc:
        raise RecordingError(f"{source.label}: not a readable Parquet file ({exc})") from None
    for k, field in zip(wanted, table.schema):
        boolean = pa.types.is_boolean(field.type)
        if not (pa.types.is_floating(field.type) or pa.types.is_integer(field.type) or boolean) \
                or boolean and header[k] not in flags:
            raise RecordingError(f"{source.label}: column {header[k]} holds {field.type}, expected numbers"
                                 f"{' (booleans only in ' + ', '.join(flags) + ')' if boolean and flags else ''}")
    return Columns(table.num_rows, lambda j: floats(table.column(j).cast(pa.float64())), wanted)


def _stream(fh, label: str) -> bytes:
    """A stream's bytes (fh, binary) read whole, refused (RecordingError) beyond MAX_STREAM_BYTES: an endless
    or very long stream is not read until memory runs out."""
    chunks, size = [], 0
    while chunk := fh.read(CHUNK):
        size += len(chunk)
        if size > MAX_STREAM_BYTES:
            raise RecordingError(f"{label}: a stream of more than {MAX_STREAM_BYTES // 2**20} MiB (or one that does "
                                 "not end); a stream is read whole into memory: write the recording to a file and "
                                 "give the file")
        chunks.append(chunk)
    return b"".join(chunks)


def _data_end(fd: int, size: int) -> int:
    """Where a file of size bytes ends but for its last hole (a sparse file's unwritten space, NUL when read):
    found by SEEK_DATA and SEEK_HOLE where the system has them, else size."""
    if not hasattr(os, "SEEK_DATA"):
        return size
    end, position = 0, 0
    try:
        while position < size:
            position = os.lseek(fd, position, os.SEEK_DATA)
            end = position = os.lseek(fd, position, os.SEEK_HOLE)
    except OSError as exc:  # ENXIO: no data after position; another error: the system cannot say
        return end if exc.errno == errno.ENXIO else size
    return end
