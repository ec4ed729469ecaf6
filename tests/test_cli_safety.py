"""The command line as an adversarial but realistic user drives it: --out naming a link, a
pipe, a device, a socket or a folder; signals during a write and the temporary files they
would leave; epoch time stamps; --scheduler at an address where no Dask scheduler
listens; numeric flags out of range; columns nobody asked for; .mat variables of the wrong
kind. Each case ends in the output it should or in one line and a non-zero exit, losing
nothing. No test touches the system's special files: the FIFOs, sockets and device nodes
are made in tmp_path."""
import argparse
import contextlib
import math
import os
import signal
import socket
import stat
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from scipy.io import savemat

from attitude_fmu.systems.cli.commands import build_parser, main
from attitude_fmu.systems.recordings import output
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0
HEADER = "t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z"
CLI = [sys.executable, "-m", "attitude_fmu.systems.cli.commands"]


@pytest.fixture(scope="module")
def imu():
    """60 s of human motion at 100 Hz: gyr, acc (6000 rows)."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(60.0, FS, seed=41)
    return ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=42)


@pytest.fixture(scope="module")
def source(tmp_path_factory, imu):
    """The recording as a CSV and the estimate attitude writes for it into a regular file."""
    folder = tmp_path_factory.mktemp("source")
    path, reference = folder / "in.csv", folder / "reference.csv"
    _write_csv(path, *imu)
    assert main(["estimate", str(path), "--out", str(reference)]) == 0
    return path, reference.read_bytes()


def _write_csv(path, gyr, acc, t=None):
    t = np.arange(1, len(gyr) + 1) / FS if t is None else t
    np.savetxt(path, np.column_stack([t, gyr, acc]), delimiter=",", header=HEADER, comments="", fmt="%.17g")


def _status(argv) -> int:
    """main's exit status, a flag refused as the command line is parsed (SystemExit) included."""
    try:
        return main(argv)
    except SystemExit as refused:
        return refused.code


def _through_pipe(path, argv) -> bytes:
    """What attitude argv writes into the named pipe path, read by a thread as it writes;
    the pipe must stay one."""
    received = []

    def read():
        with open(path, "rb") as fh:
            received.append(fh.read())

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    assert main(argv) == 0
    reader.join(timeout=60)
    assert stat.S_ISFIFO(os.lstat(path).st_mode)
    return received[0]


# --out: what the path names decides how it is written


def test_out_through_a_symbolic_link_writes_its_target(tmp_path, source, capsys):
    """A link to a file: the file gets the estimate, the link stays a link to it; a dangling
    link: its target is made, in another folder, and the link then leads to it."""
    path, expected = source
    target, link = tmp_path / "target.csv", tmp_path / "link.csv"
    target.write_text("previous\n")
    os.symlink(target, link)
    assert main(["estimate", str(path), "--out", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(target) and target.read_bytes() == expected

    (tmp_path / "elsewhere").mkdir()
    dangling = tmp_path / "dangling.csv"
    os.symlink(os.path.join("elsewhere", "made.csv"), dangling)  # relative, as ln -s makes them
    assert not dangling.exists()
    assert main(["estimate", str(path), "--out", str(dangling)]) == 0
    assert dangling.is_symlink() and (tmp_path / "elsewhere" / "made.csv").read_bytes() == expected
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith((".partial", ".trial"))]
    capsys.readouterr()


def test_a_link_that_loops_is_refused(tmp_path, source, capsys):
    path, _ = source
    os.symlink(tmp_path / "b.csv", tmp_path / "a.csv")
    os.symlink(tmp_path / "a.csv", tmp_path / "b.csv")
    assert main(["estimate", str(path), "--out", str(tmp_path / "a.csv")]) == 2
    err = capsys.readouterr().err
    assert "Too many levels of symbolic links" in err and "attitude: read" not in err, err
    assert (tmp_path / "a.csv").is_symlink() and (tmp_path / "b.csv").is_symlink()


def test_out_a_named_pipe_is_written_as_standard_output_is(tmp_path, source, capsys):
    """A FIFO gets the bytes a file would, and stays a FIFO; a .parquet one gets a Parquet
    file's bytes, read back by pyarrow."""
    path, expected = source
    csv, parquet = tmp_path / "pipe.csv", tmp_path / "pipe.parquet"
    for fifo in (csv, parquet):
        os.mkfifo(fifo)
    assert _through_pipe(csv, ["estimate", str(path), "--out", str(csv)]) == expected
    table = pq.read_table(pa.BufferReader(_through_pipe(parquet, ["estimate", str(path), "--out", str(parquet)])))
    assert table.num_rows == expected.count(b"\n") - 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.csv", "pipe.parquet"]  # no temporary file
    capsys.readouterr()


def _null_device(path):
    """A character device node at path with the numbers of the null device (root only)."""
    if os.geteuid() != 0:
        pytest.skip("making a device node needs root")
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("this system refuses device nodes (no CAP_MKNOD)")


def test_out_a_character_device_discards_as_dev_null_does(tmp_path, source, capsys):
    """A node made here with the null device's numbers: the estimate is written into it, the
    node stays a character device and nothing else appears; the same through a link to it."""
    path, _ = source
    node = tmp_path / "null"
    _null_device(node)
    os.symlink(node, tmp_path / "to-null")
    for out in (node, tmp_path / "to-null"):
        assert main(["estimate", str(path), "--out", str(out)]) == 0
        assert stat.S_ISCHR(os.stat(node).st_mode) and os.stat(node).st_rdev == os.makedev(1, 3)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["null", "to-null"]
    capsys.readouterr()


def test_a_socket_and_a_name_ending_in_a_separator_are_refused_before_any_work(tmp_path, source, capsys):
    """A socket stays a socket; "newdir/" (no such folder) makes neither a file nor a folder;
    "file.csv/" leaves the file as it was: one line each, exit 2, nothing read."""
    path, _ = source
    listening = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listening.bind(str(tmp_path / "s.sock"))
    (tmp_path / "file.csv").write_text("kept\n")
    cases = ((tmp_path / "s.sock", "it is a socket"),
             (f"{tmp_path / 'newdir'}{os.sep}", "names a folder, and there is none"),
             (f"{tmp_path / 'file.csv'}{os.sep}", "names a folder, and there is none"))
    with listening:
        for out, message in cases:
            for command in (["estimate", str(path)], ["plot", str(path)]):
                assert main([*command, "--out", str(out)]) == 2
                err = capsys.readouterr().err
                assert message in err and err.count("\n") == 1 and "attitude: read" not in err, err
        assert stat.S_ISSOCK(os.lstat(tmp_path / "s.sock").st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.csv", "s.sock"]
    assert (tmp_path / "file.csv").read_text() == "kept\n"


# signals: the temporary file never outlives its write


STALLED_WRITE = """
import contextlib, signal, sys, time
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings import output, writing

for name in ("SIGTERM", "SIGHUP"):  # as a user's shell leaves them, whatever the test runner's
    signal.signal(getattr(signal, name), signal.SIG_DFL)
signal.signal(signal.SIGINT, signal.default_int_handler)


@contextlib.contextmanager
def stalled(path):
    with output.replaced(path) as fh:
        yield fh
        fh.flush()
        print("written", flush=True)  # every row is in the temporary file; the rename never comes
        time.sleep(120)


writing.replaced = stalled
sys.exit(main(sys.argv[1:]))
"""


def _stalled_writer(tmp_path, source_path, out) -> subprocess.Popen:
    """attitude estimate in a process whose write stops before the rename: returned once
    the temporary file holds every row."""
    script = tmp_path / "stalled.py"
    script.write_text(STALLED_WRITE)
    child = subprocess.Popen([sys.executable, str(script), "estimate", str(source_path), "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline() == "written\n", child.communicate(timeout=60)
    return child


def _partials(folder) -> list:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(output.PARTIAL_SUFFIX))


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT], ids=lambda s: s.name)
def test_a_signal_during_the_write_removes_the_temporary_file(tmp_path, source, signum):
    """SIGTERM, SIGHUP or SIGINT while the temporary file holds the estimate: it is removed,
    the previous output keeps its bytes, and the last line of standard error says which
    signal ended the run (exit 128 + its number, no traceback)."""
    out = tmp_path / "out.csv"
    out.write_text("previous\n")
    child = _stalled_writer(tmp_path, source[0], out)
    assert len(_partials(tmp_path)) == 1 and os.path.getsize(tmp_path / _partials(tmp_path)[0]) > 100_000
    child.send_signal(signum)
    _, err = child.communicate(timeout=60)
    assert child.returncode == 128 + signum, err
    assert err.splitlines()[-1].startswith(f"attitude: interrupted by {signal.Signals(signum).name}"), err
    assert "Traceback" not in err and _partials(tmp_path) == [] and out.read_text() == "previous\n"


def test_sigint_while_the_command_loads_ends_with_one_line_and_exit_130():
    """SIGINT while the console script (systems.cli.entry) loads the command's modules, which take
    about a second and a half: one line, exit 130, no traceback. The signal is sent at the import
    of the command's module, the moment a user's Ctrl-C after typing the command lands in."""
    script = ("import builtins, os, signal, sys\n"
              "sys.argv = ['attitude', '--help']\n"
              "from attitude_fmu.systems.cli import entry\n"
              "real_import = builtins.__import__\n"
              "def importing(name, *args, **kwargs):\n"
              "    if name == 'attitude_fmu.systems.cli.commands':\n"
              "        os.kill(os.getpid(), signal.SIGINT)\n"
              "    return real_import(name, *args, **kwargs)\n"
              "builtins.__import__ = importing\n"
              "entry.entry_point()\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 130, done.stderr
    assert done.stderr.splitlines() == ["attitude: interrupted by SIGINT; nothing was written"], done.stderr
    assert done.stdout == ""  # the command never ran: no help printed


def test_sigint_while_reading_ends_with_one_line_and_exit_130(tmp_path):
    """SIGINT while the input (a named pipe its writer holds open) is being read: no output,
    no traceback, one line, exit 130."""
    fifo = tmp_path / "in.csv"
    os.mkfifo(fifo)
    child = subprocess.Popen([sys.executable, "-c", "import signal, sys; "
                              "signal.signal(signal.SIGINT, signal.default_int_handler); "
                              "from attitude_fmu.systems.cli.commands import main; sys.exit(main(sys.argv[1:]))",
                              "estimate", str(fifo), "--out", str(tmp_path / "out.csv")],
                             stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while True:  # the pipe opens for writing once the command has opened it to read
        try:
            writer = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
            break
        except OSError:
            assert time.monotonic() < deadline and child.poll() is None, "the command never read its input"
            time.sleep(0.05)
    try:
        os.write(writer, f"{HEADER}\n".encode())
        time.sleep(0.2)  # the command waits for more
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=60)
    finally:
        os.close(writer)
    assert child.returncode == 130 and err.splitlines() == ["attitude: interrupted by SIGINT; no output was left "
                                                             "half-written"], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_killed_writers_temporary_file_is_swept_at_the_next_write(tmp_path, source, capsys):
    """SIGKILL (no handler runs) leaves the temporary file; once it is older than a write can
    leave it untouched, the next write of the same output removes it."""
    out = tmp_path / "out.csv"
    child = _stalled_writer(tmp_path, source[0], out)
    child.kill()
    child.communicate(timeout=60)
    left = _partials(tmp_path)
    assert len(left) == 1
    assert main(["estimate", str(source[0]), "--out", str(out)]) == 0  # too fresh to be judged stale: kept
    assert _partials(tmp_path) == left
    old = time.time() - 2 * output.STALE_AFTER_S
    os.utime(tmp_path / left[0], (old, old))
    assert main(["estimate", str(source[0]), "--out", str(out)]) == 0
    assert _partials(tmp_path) == [] and out.read_bytes() == source[1]
    capsys.readouterr()


def test_the_sweep_removes_only_this_programs_stale_files(tmp_path):
    """Of files beside the output, only a temporary file of this output's name and host
    whose writer has ended and that is old is removed: not one whose writer runs, a fresh
    one, another host's, another output's, nor another program's."""
    target = tmp_path / "out.csv"
    dead, alive = _dead_pid(), os.getpid()
    names = {
        "stale": output.partial_prefix(target, dead) + "ab12_xyz" + output.PARTIAL_SUFFIX,
        "running": output.partial_prefix(target, alive) + "ab12_xyz" + output.PARTIAL_SUFFIX,
        "fresh": output.partial_prefix(target, dead) + "cd34_xyz" + output.PARTIAL_SUFFIX,
        "other host": f".out.csv.another-host.{dead}.ab12_xyz{output.PARTIAL_SUFFIX}",
        "other output": output.partial_prefix(tmp_path / "other.csv", dead) + "ab12_xyz" + output.PARTIAL_SUFFIX,
        "other program": f".out.csv.{dead}{output.PARTIAL_SUFFIX}",
    }
    old = time.time() - 2 * output.STALE_AFTER_S
    for what, name in names.items():
        (tmp_path / name).write_text(what)
        if what != "fresh":
            os.utime(tmp_path / name, (old, old))
    assert output.remove_stale(target) == [tmp_path / names["stale"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(n for w, n in names.items() if w != "stale")


def test_the_write_restores_the_signal_handlers_and_keeps_an_ignored_signal_ignored(tmp_path):
    """During a write SIGTERM has the write's handler, SIGHUP ignored (nohup) stays ignored;
    after it every handler is the one before."""
    def mine(signum, frame):
        pass

    before = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        signal.signal(signal.SIGTERM, mine)
        signal.signal(signal.SIGHUP, signal.SIG_IGN)
        with output.replaced(tmp_path / "out.csv") as fh:
            fh.write(b"x\n")
            during = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGHUP)
        assert during[0] not in (mine, signal.SIG_DFL) and during[1] is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) is mine and signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
        with pytest.raises(RuntimeError), output.replaced(tmp_path / "out.csv") as fh:  # a write that fails too
            raise RuntimeError
        assert signal.getsignal(signal.SIGTERM) is mine
    finally:
        for signum, handler in before.items():
            signal.signal(signum, handler)
    assert (tmp_path / "out.csv").read_bytes() == b"x\n" and _partials(tmp_path) == []


# time stamps


def _t_column(path) -> list[str]:
    return [line.split(",", 1)[0] for line in path.read_text().splitlines()[1:]]


def test_epoch_time_stamps_keep_every_step(tmp_path, imu, capsys):
    """Seconds since 1970 (1.7e9 s) at 100 Hz, 6000 rows: the CSV's t reads back to the
    input's doubles, every one distinct; the Parquet output holds the same bits."""
    t = 1.7e9 + np.arange(len(imu[0])) / FS
    _write_csv(tmp_path / "in.csv", *imu, t=t)
    for name in ("out.csv", "out.parquet"):
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / name)]) == 0
    written = np.array([float(text) for text in _t_column(tmp_path / "out.csv")])
    assert len(np.unique(written)) == len(t) == 6000 and np.array_equal(written, t)
    assert np.array_equal(pq.read_table(tmp_path / "out.parquet").column("t").to_numpy(), t)
    capsys.readouterr()


def test_epoch_nanoseconds_keep_every_step(tmp_path, imu, capsys):
    """Integer nanoseconds since 1970 (--t-unit ns, as EuRoC's logs): 6000 distinct times
    in seconds, each within a microsecond of its stamp (a double's step there is 0.24 µs)."""
    stamps = 1_700_000_000_000_000_000 + 10_000_000 * np.arange(len(imu[0]), dtype=np.int64)
    lines = [HEADER] + [f"{s}," + ",".join(f"{v:.17g}" for v in row) for s, row in zip(stamps, np.hstack(imu))]
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv"), "--t-unit", "ns"]) == 0
    written = _t_column(tmp_path / "out.csv")
    assert len(set(written)) == 6000
    assert max(abs(float(text) - int(s) / 1e9) for text, s in zip(written, stamps)) < 1e-6
    capsys.readouterr()


# --scheduler


@contextlib.contextmanager
def _server(greeting: bytes | None):
    """A TCP server on the loopback interface: an HTTP server (greeting None), or one that
    sends greeting to every connection and then reads, saying nothing more, until the other
    side hangs up; yields its port."""
    if greeting is None:
        import http.server

        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.BaseHTTPRequestHandler)
    else:
        import socketserver

        class Greeter(socketserver.BaseRequestHandler):
            def handle(self):
                with contextlib.suppress(OSError):  # the command hangs up without a word
                    self.request.sendall(greeting)
                    while self.request.recv(1024):
                        pass

        server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), Greeter)
    server.daemon_threads = True
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield server.server_address[1]
    finally:
        server.shutdown()
        server.server_close()


@pytest.mark.parametrize("greeting", [None, b"HTTP/1.1 400 Bad Request\r\n\r\n"], ids=["silent HTTP", "greets"])
def test_a_scheduler_address_where_no_scheduler_listens_is_refused_in_seconds(greeting, capsys):
    """An HTTP server (Dask's dashboard, say) waits to be asked; another server greets with
    text: either is named no Dask scheduler, in one line, within seconds, exit 2."""
    with _server(greeting) as port:
        start = time.monotonic()
        assert main(["table1", "--duration", "10", "--scheduler", f"tcp://127.0.0.1:{port}"]) == 2
        took = time.monotonic() - start
    err = capsys.readouterr().err
    assert f"tcp://127.0.0.1:{port} is no Dask scheduler" in err and err.count("\n") == 1, err
    assert took < 10.0 if greeting is None else took < 3.0


def test_a_scheduler_that_greets_and_then_says_nothing_is_given_up_on_within_30_s(capsys):
    """A server that sends a plausible frame length (a Dask scheduler's greeting starts so) and then
    nothing: the client's handshake is given up on (HANDSHAKE_DEADLINE_S), one line, exit 2."""
    from attitude_fmu.systems.cluster.jobs import HANDSHAKE_DEADLINE_S

    with _server(struct.pack("<Q", 200)) as port:
        start = time.monotonic()
        assert main(["table1", "--duration", "10", "--scheduler", f"tcp://127.0.0.1:{port}"]) == 2
        took = time.monotonic() - start
    err = capsys.readouterr().err
    assert err == (f"attitude: error: the Dask scheduler at tcp://127.0.0.1:{port} did not finish its handshake in "
                   f"{HANDSHAKE_DEADLINE_S:g} s\n"), err
    assert HANDSHAKE_DEADLINE_S <= took < 30.0


def test_a_real_scheduler_passes_the_check_and_its_dashboard_does_not():
    """The check against a Dask scheduler (in this process, on the loopback interface):
    its address passes at once; its dashboard's port is refused."""
    from distributed import LocalCluster

    from attitude_fmu.systems.cluster.jobs import check_scheduler

    with LocalCluster(n_workers=0, processes=False, protocol="tcp://", host="127.0.0.1",
                      dashboard_address="127.0.0.1:0") as cluster:
        start = time.monotonic()
        check_scheduler(cluster.scheduler_address)
        assert time.monotonic() - start < 1.0
        dashboard = f"tcp://127.0.0.1:{cluster.scheduler.http_server.port}"
        with pytest.raises(RuntimeError, match=f"{dashboard} is no Dask scheduler: it sent nothing"):
            check_scheduler(dashboard)


def test_scheduler_schemes_are_used_or_refused_by_name(capsys):
    """inproc:// and a scheme Dask has not are refused before any work, by name; nothing
    listening on the port: cannot reach it."""
    with socket.socket() as unused:
        unused.bind(("127.0.0.1", 0))
        port = unused.getsockname()[1]  # closed when the command runs: nothing listens
    cases = (("inproc://x", "inproc:// names a scheduler inside one Python process"),
             ("foo://host:8786", "the scheme foo:// is not one to reach a Dask scheduler through"),
             (f"tcp://127.0.0.1:{port}", "cannot reach the Dask scheduler"))
    for address, message in cases:
        assert main(["table1", "--duration", "10", "--scheduler", address]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err


# numeric flags


def _numeric_flags():
    """(command, flag, type) of every flag of every command whose value has a type."""
    commands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return [(name, action.option_strings[-1], action.type) for name, parser in commands.choices.items()
            for action in parser._actions if action.option_strings and action.type is not None]


def test_every_numeric_flag_is_range_checked():
    """No flag takes a bare float or int: each numeric one refuses inf and nan."""
    flags = _numeric_flags()
    assert not [(c, f) for c, f, kind in flags if kind in (float, int)]
    numeric = [(c, f, kind) for c, f, kind in flags if getattr(kind, "__name__", "") == "number"]
    assert len(numeric) >= 15
    for command, flag, kind in numeric:
        for text in ("inf", "nan", "1e400"):
            with pytest.raises(argparse.ArgumentTypeError, match="plausible"):
                kind(text)


@pytest.mark.parametrize("argv, message", [
    (["table1", "--duration", "inf"], "argument --duration: inf is outside the plausible (0, 1e+12] s"),
    (["table1", "--duration", "-5"], "argument --duration: -5 is outside the plausible (0, 1e+12] s"),
    (["table1", "--fs", "1e9"], "argument --fs: 1e9 is outside the plausible [1, 100000] Hz"),
    (["table1", "--fs", "nan"], "argument --fs: nan is outside the plausible [1, 100000] Hz"),
    (["bench", "--samples", "0"], "argument --samples: 0 is outside the plausible [1000, 1e+08]"),
    (["bench", "--samples", "1e5"], "argument --samples: '1e5' is not a whole number"),
    (["compare", "--gyro-scale-error", "0.5"], "argument --gyro-scale-error: 0.5 is outside the plausible [0, 0.5)"),
    (["estimate", "in.csv", "--out", "o.csv", "--latency", "nan"], "argument --latency: nan is outside"),
])
def test_numeric_flags_out_of_range_are_refused_with_the_range(argv, message, capsys):
    assert _status(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err, err


def test_a_table1_cell_too_large_for_memory_is_refused(capsys):
    """Each flag in range, their product not: --duration 1e7 s at 100 Hz is 1e9 samples a
    cell; --duration 1 s at 100 Hz too few."""
    for duration, samples in (("1e7", "1e+09"), ("1", "100")):
        assert main(["table1", "--duration", duration]) == 2
        err = capsys.readouterr().err
        assert f"gives {samples} samples per table1 cell; the plausible range is [1000, 1e+08]" in err, err


# columns nobody asked for, RFC 4180 fields, .mat and Parquet variables of the wrong kind


def _csv_lines(imu, delimiter=",", decimal=".") -> list[str]:
    t = np.arange(1, len(imu[0]) + 1) / FS
    rows = np.column_stack([t, *imu])
    return [delimiter.join(f"{v:.17g}".replace(".", decimal) for v in row) for row in rows]


def test_columns_not_asked_for_are_not_parsed(tmp_path, source, capsys):
    """Text, a quoted "a,b", doubled quotes, a quoted line break, an empty column and a
    trailing separator beside the columns read: the estimate of the plain file, the
    columns named; the same with semicolons and decimal commas."""
    _, expected = source
    imu = np.loadtxt(source[0], delimiter=",", skiprows=1)[:, 1:]
    imu = (imu[:, :3], imu[:, 3:])
    for delimiter, decimal in ((",", "."), (";", ",")):
        extra = ['"a{0}b"', 'text', '"say ""hi"""', '"two\nlines"']
        header = delimiter.join(HEADER.split(",") + ["note", "empty", ""])
        lines = [header] + [f"{line}{delimiter}{extra[k % 4].format(delimiter)}{delimiter}{delimiter}"
                            for k, line in enumerate(_csv_lines(imu, delimiter, decimal))]
        path = tmp_path / f"extra{len(delimiter)}{decimal}.csv"
        path.write_text("\n".join(lines) + "\n")
        assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 0
        err = capsys.readouterr().err
        assert "columns not read: note, empty, (unnamed)" in err, err
        if delimiter == ",":
            assert (tmp_path / "out.csv").read_bytes() == expected


def test_quoted_numbers_and_a_bad_row_are_read_as_rfc_4180_says(tmp_path, imu, capsys):
    """Quoted numbers are numbers; a row whose unasked quoted field holds the separator has
    as many fields as the header; a text in an asked column is named by line and column."""
    lines = [HEADER + ",note"] + [f'"{line.replace(",", chr(34) + "," + chr(34))}","x,y"'
                                   for line in _csv_lines(imu)]
    (tmp_path / "quoted.csv").write_text("\n".join(lines) + "\n")
    assert main(["estimate", str(tmp_path / "quoted.csv"), "--out", str(tmp_path / "out.csv")]) == 0
    lines[5] = lines[5].replace(lines[5].split(",")[2], '"oops"', 1)
    (tmp_path / "quoted.csv").write_text("\n".join(lines) + "\n")
    assert main(["estimate", str(tmp_path / "quoted.csv"), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert "unreadable number in line 6, column gyr_y: 'oops'" in err, err


@pytest.mark.parametrize("variable, value, message", [
    ("imu_gyr", lambda gyr: gyr + 1j * 1e-3, "imu_gyr holds complex numbers, expected real numbers"),
    ("imu_acc", lambda acc: acc > 0, "imu_acc holds logical values, expected real numbers"),
    ("sampling_rate", lambda fs: complex(fs, 1.0), "sampling_rate holds complex numbers"),
])
def test_a_mat_variable_of_the_wrong_kind_is_refused_by_name(tmp_path, imu, variable, value, message, capsys):
    """Complex and logical sensor variables are refused (their imaginary part or their
    values would be lost); a logical movement flag is read."""
    gyr, acc = imu
    content = {"imu_gyr": gyr, "imu_acc": acc, "sampling_rate": FS}
    content[variable] = value(content[variable])
    savemat(tmp_path / "rec.mat", content)
    assert main(["estimate", str(tmp_path / "rec.mat"), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    savemat(tmp_path / "flag.mat", {"imu_gyr": gyr, "imu_acc": acc, "sampling_rate": FS,
                                    "movement": np.arange(len(gyr)) > 100})
    assert main(["estimate", str(tmp_path / "flag.mat"), "--out", str(tmp_path / "out.csv")]) == 0
    capsys.readouterr()


def test_parquet_columns_not_asked_for_are_not_read_and_booleans_only_flag(tmp_path, imu, capsys):
    """A Parquet input's text and nested columns beside ours are not read; a boolean gyro
    column is refused by name, a boolean movement column read."""
    gyr, acc = imu
    columns = {"t": np.arange(1, len(gyr) + 1) / FS,
               **{f"{s}_{a}": v[:, i] for s, v in (("gyr", gyr), ("acc", acc)) for i, a in enumerate("xyz")}}
    notes = {"note": pa.array(["a,b"] * len(gyr)), "nested": pa.array([[1, 2]] * len(gyr))}
    pq.write_table(pa.table({**columns, **notes, "movement": np.arange(len(gyr)) > 100}), tmp_path / "in.parquet")
    assert main(["estimate", str(tmp_path / "in.parquet"), "--out", str(tmp_path / "out.csv")]) == 0
    assert "columns not read: note, nested" in capsys.readouterr().err
    pq.write_table(pa.table({**columns, "gyr_y": gyr[:, 1] > 0}), tmp_path / "bool.parquet")
    assert main(["estimate", str(tmp_path / "bool.parquet"), "--out", str(tmp_path / "out.csv")]) == 2
    assert "column gyr_y holds bool, expected numbers (booleans only in movement)" in capsys.readouterr().err


def test_a_v73_mat_variable_of_the_wrong_kind_is_refused_by_name(tmp_path, imu, capsys):
    """MATLAB v7.3 (HDF5) holds complex arrays as (real, imag) pairs and logical ones as
    uint8 marked logical: refused by name as in older files."""
    import h5py

    gyr, acc = imu
    pair = np.dtype([("real", float), ("imag", float)])
    for name, data, kind, message in (
            ("imu_gyr", np.rec.fromarrays([gyr.T, np.full(gyr.T.shape, 1e-3)], dtype=pair), b"double",
             "imu_gyr holds complex numbers"),
            ("imu_acc", (acc.T > 0).astype(np.uint8), b"logical", "imu_acc holds logical values")):
        path = tmp_path / f"{name}.mat"
        with h5py.File(path, "w", userblock_size=512) as f:
            for variable, value, matlab_class in (("imu_gyr", gyr.T, b"double"), ("imu_acc", acc.T, b"double"),
                                                  ("sampling_rate", np.array([[FS]]), b"double"),
                                                  ("notes", np.array([b"text"]), b"char"),
                                                  (name, data, kind)):
                if variable in f:
                    del f[variable]
                f.create_dataset(variable, data=value).attrs["MATLAB_class"] = matlab_class
        with open(path, "r+b") as fh:
            fh.write(b"MATLAB 7.3 MAT-file".ljust(116) + bytes(8) + b"\x00\x02IM")
        assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
