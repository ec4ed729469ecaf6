"""Reads and work with bounds (issue 50, point 4): a recording followed by NUL padding (a logger's
preallocated file, written or sparse), an endless pipe or standard input, a header of 40 000 columns,
and a sweep grid of 10^8 combinations are each refused in one line, within bounded memory and time."""
import os
import subprocess
import sys
import threading
import time

import pytest

from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.evaluation.sweep import MAX_COMBINATIONS
from attitude_fmu.systems.recordings.tables import MAX_STREAM_BYTES

RECORDING = "t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z\n" + "".join(
    f"{k / 100:.2f},0,0,0,0,0,9.81\n" for k in range(200))
GIB = 2**30
# runs the command given as its arguments and prints the command's exit status and peak memory (bytes)
MEASURED = ("import resource, subprocess, sys\n"
            "done = subprocess.run(sys.argv[1:], stdin=sys.stdin, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)\n"
            "sys.stderr.buffer.write(done.stderr)\n"
            "print(done.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024)\n")


def _measured(argv, stdin=None) -> tuple[int, int, str]:
    """(exit status, peak resident memory in bytes, standard error) of `attitude argv` in a process of its own."""
    done = subprocess.run([sys.executable, "-c", MEASURED, sys.executable, "-m", "attitude_fmu.systems.cli.commands",
                           *map(str, argv)], stdin=stdin, capture_output=True, text=True, timeout=300)
    status, peak = map(int, done.stdout.split())
    return status, peak, done.stderr


@pytest.mark.parametrize("sparse", [True, False], ids=["sparse", "written"])
def test_a_recording_padded_with_200_mb_of_nul_is_refused_in_one_line(tmp_path, sparse):
    path = tmp_path / "logger.csv"
    path.write_text(RECORDING)
    size = len(RECORDING)
    if sparse:
        os.truncate(path, size + 200 * 2**20)
    else:
        with path.open("ab") as fh:
            for _ in range(200):
                fh.write(bytes(2**20))
    status, peak, err = _measured(["estimate", path, "--out", tmp_path / "out.csv"])
    assert status == 2 and peak < GIB, (status, peak, err)
    assert err == (f"attitude: error: {path}: its last {200 * 2**20} bytes (from offset {size}) are NUL, not text: "
                   f"a logger's preallocated space; cut them: truncate -s {size} {path}\n"), err
    assert not (tmp_path / "out.csv").exists()
    os.truncate(path, size)  # as the message says: then it is read
    assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 0


def _endless(fh) -> None:
    """Rows of a recording written to fh until the reader hangs up."""
    row = b"0,0,0,0,0,9.81\n" * 4096
    try:
        while True:
            fh.write(row)
    except (BrokenPipeError, OSError):
        pass
    finally:
        try:
            fh.close()
        except OSError:
            pass


def test_an_endless_named_pipe_is_refused_in_bounded_memory(tmp_path):
    fifo = tmp_path / "endless"
    os.mkfifo(fifo)
    writer = threading.Thread(target=lambda: _endless(open(fifo, "wb")), daemon=True)
    writer.start()
    status, peak, err = _measured(["estimate", fifo, "--fs", "100", "--out", tmp_path / "out.csv"])
    assert status == 2 and peak < GIB, (status, peak, err)
    assert err == (f"attitude: error: {fifo}: a stream of more than {MAX_STREAM_BYTES // 2**20} MiB (or one that "
                   "does not end); a stream is read whole into memory: write the recording to a file and give the "
                   "file\n"), err
    writer.join(30)


def test_endless_standard_input_is_refused_in_bounded_memory(tmp_path):
    read, write = os.pipe()
    writer = threading.Thread(target=lambda: _endless(os.fdopen(write, "wb")), daemon=True)
    writer.start()
    with os.fdopen(read, "rb") as stdin:
        status, peak, err = _measured(["estimate", "-", "--fs", "100", "--out", tmp_path / "out.csv"], stdin=stdin)
    assert status == 2 and peak < GIB, (status, peak, err)
    assert err.startswith("attitude: error: standard input: a stream of more than") and err.count("\n") == 1, err
    writer.join(30)


def test_a_short_stream_is_still_read(tmp_path):
    done = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", "estimate", "-", "--out", "-"],
                          input=RECORDING, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert len(done.stdout.splitlines()) == 201


def test_a_header_of_40000_columns_is_read_in_linear_time_and_not_echoed_whole(tmp_path, capsys):
    """40 000 named columns, none an IMU's: refused at once (the duplicate-name check was quadratic, 47 s), its
    message showing the first columns and how many more."""
    path = tmp_path / "wide.csv"
    path.write_text(",".join(f"col{k}" for k in range(40_000)) + "\n" + ",".join(["1"] * 40_000) + "\n")
    start = time.monotonic()
    assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 2
    assert time.monotonic() - start < 10.0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and len(err) < 600, err
    assert "(header: col0,col1," in err and "col23, … and 39976 more of its 40000 columns)" in err, err


def test_a_header_line_without_end_is_refused(tmp_path, capsys):
    """A first line longer than any header (a binary or a one-line file of 8 MB): refused after 4 MiB read."""
    path = tmp_path / "line.csv"
    path.write_text("t" + ",0" * 4 * 2**20)
    assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "its first line, the header, runs past 4194304 characters" in err, err


def test_a_sweep_of_10_to_the_8_combinations_is_refused_within_a_second(tmp_path, capsys):
    path = tmp_path / "r.csv"
    path.write_text(RECORDING)
    values = ",".join(str(k) for k in range(1, 101))
    grid = [a for name in ("delta_n", "scale_error", "omega_g", "tau_heading") for a in ("--grid", f"{name}={values}")]
    start = time.monotonic()
    assert main(["sweep", str(path), *grid]) == 2
    assert time.monotonic() - start < 1.0
    err = capsys.readouterr().err
    assert err == (f"attitude: error: the grid makes 100000000 combinations (100 × 100 × 100 × 100); a sweep runs "
                   f"{MAX_COMBINATIONS} at most: give fewer values, or sweep the parameters in turn\n"), err
