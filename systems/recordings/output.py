"""Output files that lose nothing: checked before any work (their folder, that it takes a
file, that none is an input: the same file by device and inode, hard links and symbolic
links included), written to a temporary file beside the target and renamed over it only
when complete, so a failed or interrupted write (a full disk, SIGTERM, SIGHUP, SIGINT)
leaves the previous file as it was. What the output names decides how it is written: a
regular file (or none yet) is replaced so; a symbolic link has its target written (a
dangling one's target made); a character device (/dev/null) or a named pipe is opened and
written as standard output is; a folder, a socket or a block device is refused, and so is
a name ending in a separator. "-" is standard output (the Unix convention)."""
from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import socket
import stat
import sys
import tempfile
import threading
import time
from pathlib import Path

STDIO = "-"  # an input read from standard input, an output written to standard output
PARTIAL_SUFFIX = ".partial"  # the temporary file's name: .NAME.HOST.PID.RANDOM.partial beside NAME
STALE_AFTER_S = 60.0  # a temporary file untouched this long whose writer has ended is removed at the next write
INTERRUPTING = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP", "SIGINT") if hasattr(signal, name))


class OutputError(ValueError):
    """An output that cannot be written; the message says why and what to do."""


class Interrupted(KeyboardInterrupt):
    """SIGTERM, SIGHUP or SIGINT (signum) during a write: the temporary file is removed,
    the output left as it was."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def same_file(a, b) -> bool:
    """Whether the paths a and b name one file (device and inode), not merely one name."""
    try:
        first, second = os.stat(a), os.stat(b)
    except (OSError, ValueError):
        return False
    return (first.st_dev, first.st_ino) == (second.st_dev, second.st_ino)


def written(path) -> tuple[Path, bool]:
    """(the file a write to path changes, whether it is a stream): path's target if it is a
    symbolic link (a dangling one's too), replaced when complete; a character device or a
    named pipe (a stream) opened and written in place. A name ending in a separator, a
    folder, a socket, a block device and a link that loops are refused (OutputError)."""
    text = str(path)
    if text.endswith(os.sep) or (os.altsep and text.endswith(os.altsep)):
        raise OutputError(f"cannot write {path}: a name ending in {os.sep} names a folder"
                          f"{'' if os.path.isdir(text) else ', and there is none'}; give a file name")
    path = Path(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:  # a link that loops, a folder on the way that cannot be searched
        raise OutputError(f"cannot write {path}: {exc.strerror}") from None
    if mode is None or stat.S_ISREG(mode):
        return (Path(os.path.realpath(path)) if path.is_symlink() else path), False
    if stat.S_ISCHR(mode) or stat.S_ISFIFO(mode):
        return path, True
    kind = ("a folder; give a file name" if stat.S_ISDIR(mode) else "a socket" if stat.S_ISSOCK(mode)
            else "a block device" if stat.S_ISBLK(mode) else "no file")
    raise OutputError(f"cannot write {path}: it is {kind} (--out writes a file, a character device such as "
                      "/dev/null, a named pipe, or - for standard output)")


def check_output(path, inputs=(), what: str = "an output") -> None:
    """Refuse, before any work, an output (what says which) that written() refuses, that is
    one of the inputs (writing it would lose the recording), or a file whose folder does
    not exist or cannot take a file, or that cannot be replaced. "-" (standard output)
    passes, and so do a character device or a named pipe this process may write."""
    if str(path) == STDIO:
        return
    target, stream = written(path)
    path = Path(path)
    for source in inputs:
        if str(source) != STDIO and (same_file(path, source) or path.absolute() == Path(source).absolute()):
            raise OutputError(f"cannot write {path}: it is the input; choose another --out (it is the file {source})")
    if stream:
        if not os.access(path, os.W_OK):
            raise OutputError(f"cannot write {path}: permission denied")
        return
    folder = target.absolute().parent
    if not folder.is_dir():
        raise OutputError(f"cannot write {path}: there is no folder {folder}")
    try:  # the one proof that the folder takes a file: making one
        fd, trial = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".trial", dir=folder)
        os.close(fd)
        os.unlink(trial)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: the folder {folder} takes no new file ({exc.strerror})") from None
    if target.exists() and not (os.access(target, os.W_OK) and os.stat(target).st_mode & 0o222):  # root too keeps it
        raise OutputError(f"cannot write {path}: the file is read-only; choose another --out or make it writable")


@contextlib.contextmanager
def replaced(path, mode: int | None = None):
    """A binary file to write path's new contents into (see written()): for a file, a
    temporary file in its folder, flushed to disk and renamed over it when the block ends
    without an exception, removed (the file untouched) when it raises or SIGTERM, SIGHUP or
    SIGINT arrives (Interrupted); a character device or a named pipe itself; path "-":
    standard output. This program's temporary files for the same file that an ended writer
    left (killed by SIGKILL, a power cut) are removed first (remove_stale). mode: the file's
    permissions (default: those it has, or a new file's, 0o666 less the umask)."""
    if str(path) == STDIO:
        yield sys.stdout.buffer
        sys.stdout.buffer.flush()
        return
    target, stream = written(path)
    path = Path(path)
    if stream:
        try:
            with open(path, "wb") as fh:  # neither truncates nor replaces a device or a pipe
                yield fh
        except OSError as exc:
            raise OutputError(f"cannot write {path}: {exc.strerror or exc}") from None
        return
    remove_stale(target)
    try:
        fd, temporary = tempfile.mkstemp(prefix=partial_prefix(target), suffix=PARTIAL_SUFFIX, dir=target.parent)
    except OSError as exc:
        raise OutputError(f"cannot write {path}: {exc.strerror}") from None
    try:
        with interrupting(), os.fdopen(fd, "wb") as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
            os.chmod(temporary, _mode(target) if mode is None else mode)
            os.replace(temporary, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        if isinstance(exc, OSError):  # a full disk, a quota, an I/O error: said, and what it left
            kept = "is as it was" if target.exists() else "was not made"
            raise OutputError(f"cannot write {path}: {exc.strerror or exc}; {path} {kept}") from None
        raise


def partial_prefix(target: Path, pid: int | None = None) -> str:
    """The start of the temporary file's name for target written by process pid (this one
    by default): .NAME.HOST.PID. (the random part and PARTIAL_SUFFIX follow)."""
    return f".{target.name}.{_host()}.{os.getpid() if pid is None else pid}."


def remove_stale(target: Path) -> list[Path]:
    """Remove, and return, the temporary files beside target that a write of target by this
    program on this host left when its process ended without removing them: a name of
    partial_prefix's pattern, a regular file of this user, its writer's process gone and
    the file untouched for STALE_AFTER_S. Any other file is left alone."""
    pattern = re.compile(rf"\.{re.escape(target.name)}\.{re.escape(_host())}\.([1-9][0-9]{{0,9}})\.[a-z0-9_]+"
                         + re.escape(PARTIAL_SUFFIX))
    removed = []
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return removed
    for entry in entries:
        match = pattern.fullmatch(entry.name)
        if match is None or _running(int(match[1])):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
            if (stat.S_ISREG(info.st_mode) and info.st_uid == os.getuid()
                    and time.time() - info.st_mtime > STALE_AFTER_S):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            continue
    return removed


def _host() -> str:
    """This host's name as a file name may hold it (letters, digits, -)."""
    return re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:32] or "host"


def _running(pid: int) -> bool:
    """Whether process pid may be running here (True where that cannot be known)."""
    if os.name != "posix" or pid > 2**31 - 1:  # os.kill on Windows ends the process
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's process
        return True
    return True


@contextlib.contextmanager
def interrupting():
    """Within the block, SIGTERM, SIGHUP and SIGINT raise Interrupted (a KeyboardInterrupt), so
    the block's own cleanup runs (finally clauses, temporary files and folders, child processes
    that subprocess.run started); the previous handlers are restored after it. A signal ignored
    (nohup) stays ignored; outside the main thread, where handlers cannot be set, nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise Interrupted(signum)

    previous = {}
    try:
        for signum in INTERRUPTING:
            before = signal.getsignal(signum)
            if before is not None and before is not signal.SIG_IGN:  # None: set outside Python, kept
                previous[signum] = signal.signal(signum, handler)
        yield
    finally:
        for signum, before in previous.items():
            signal.signal(signum, before)


def _mode(path: Path) -> int:
    """The permissions path has, or a new file's (0o666 less the umask)."""
    try:
        return os.stat(path).st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def copy_file(source, path) -> Path:
    """The file source copied into path by replaced() (a file replaced whole with source's permissions, a
    stream written); returns path."""
    with open(source, "rb") as src, replaced(path, os.stat(source).st_mode & 0o7777) as fh:
        shutil.copyfileobj(src, fh)
    return Path(path)


def save_figure(fig, path, **options) -> None:
    """fig (matplotlib) saved into path by replaced(): its format from the file name's suffix."""
    with replaced(path) as fh:
        fig.savefig(fh, format=Path(path).suffix.lstrip(".").lower() or None, **options)
