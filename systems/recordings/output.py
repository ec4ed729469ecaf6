"""Output files that lose nothing: checked before any work (their folder, that it takes a
file, that none is an input: the same file by device and inode, hard links and symbolic
links included), written to a temporary file beside the target and renamed over it only
when complete, so a failed write (a full disk) leaves the previous file as it was. "-" is
standard output (the Unix convention)."""
from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from pathlib import Path

STDIO = "-"  # an input read from standard input, an output written to standard output


class OutputError(ValueError):
    """An output that cannot be written; the message says why and what to do."""


def same_file(a, b) -> bool:
    """Whether the paths a and b name one file (device and inode), not merely one name."""
    try:
        first, second = os.stat(a), os.stat(b)
    except (OSError, ValueError):
        return False
    return (first.st_dev, first.st_ino) == (second.st_dev, second.st_ino)


def check_output(path, inputs=(), what: str = "an output") -> None:
    """Refuse, before any work, an output file (what says which) whose folder does not
    exist or cannot take a file, that is a folder, that cannot be replaced, or that is one
    of the inputs (writing it would lose the recording). "-" (standard output) passes."""
    if str(path) == STDIO:
        return
    path = Path(path)
    folder = path.absolute().parent
    if not folder.is_dir():
        raise OutputError(f"cannot write {path}: there is no folder {folder}")
    if path.is_dir():
        raise OutputError(f"cannot write {path}: it is a folder; give a file name")
    for source in inputs:
        if str(source) != STDIO and (same_file(path, source) or path.absolute() == Path(source).absolute()):
            raise OutputError(f"cannot write {path}: it is the input; choose another --out (it is the file {source})")
    try:  # the one proof that the folder takes a file: making one
        fd, trial = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".trial", dir=folder)
        os.close(fd)
        os.unlink(trial)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: the folder {folder} takes no new file ({exc.strerror})") from None
    if path.exists() and not (os.access(path, os.W_OK) and os.stat(path).st_mode & 0o222):  # root too keeps it
        raise OutputError(f"cannot write {path}: the file is read-only; choose another --out or make it writable")


@contextlib.contextmanager
def replaced(path):
    """A binary file to write path's new contents into: a temporary file in path's folder,
    flushed to disk and renamed over path when the block ends without an exception, removed
    (path untouched) when it raises. path "-": standard output itself."""
    if str(path) == STDIO:
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    path = Path(path)
    try:
        fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.absolute().parent)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {exc.strerror}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(temporary, _mode(path))
        os.replace(temporary, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        if isinstance(exc, OSError):  # a full disk, a quota, an I/O error: said, and what it left
            kept = "is as it was" if path.exists() else "was not made"
            raise OutputError(f"cannot write {path}: {exc.strerror or exc}; {path} {kept}") from None
        raise


def _mode(path: Path) -> int:
    """The permissions path has, or a new file's (0o666 less the umask)."""
    try:
        return os.stat(path).st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def save_figure(fig, path, **options) -> None:
    """fig (matplotlib) saved into path by replaced(): its format from the file name's suffix."""
    with replaced(path) as fh:
        fig.savefig(fh, format=Path(path).suffix.lstrip(".").lower() or None, **options)
