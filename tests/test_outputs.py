"""Outputs that lose nothing (systems.recordings.output): the input is never the output,
a failed write leaves the previous file, unwritable targets are refused before any work;
standard input and output; CSV and Parquet through pyarrow."""
import errno
import hashlib
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings import output
from attitude_fmu.systems.recordings.writing import significant
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0


@pytest.fixture(scope="module")
def imu():
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(8.0, FS, seed=21)
    return ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=22)


def _write_csv(path, gyr, acc):
    t = np.arange(1, len(gyr) + 1) / FS
    np.savetxt(path, np.column_stack([t, gyr, acc]), delimiter=",", header="t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z",
               comments="", fmt="%.17g")


def _digest(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def test_the_output_is_never_the_input_by_any_name(tmp_path, imu, capsys):
    """A hard link, a symbolic link and a path through another folder all name the input
    file: each is refused before the input is read, and the input keeps its bytes."""
    source = tmp_path / "in.csv"
    _write_csv(source, *imu)
    before = _digest(source)
    (tmp_path / "sub").mkdir()
    os.link(source, tmp_path / "hard.csv")
    os.symlink(source, tmp_path / "soft.csv")
    for out in (tmp_path / "hard.csv", tmp_path / "soft.csv", tmp_path / "sub" / ".." / "in.csv"):
        for command in (["estimate", str(source)], ["plot", str(source)]):
            assert main([*command, "--out", str(out)]) == 2
            err = capsys.readouterr().err
            assert "it is the input" in err and "attitude: read" not in err, err
    assert main(["estimate", str(tmp_path / "hard.csv"), "--out", str(source)]) == 2  # the other way round
    assert "it is the input" in capsys.readouterr().err
    assert _digest(source) == before


def test_a_failed_write_leaves_the_previous_output_and_no_partial_file(tmp_path, imu, monkeypatch, capsys):
    """A disk that fills up during the write (ENOSPC from the file's write after 4 kB):
    exit 2 naming the file, the previous output byte for byte, no temporary file left."""
    source, out = tmp_path / "in.csv", tmp_path / "out.csv"
    _write_csv(source, *imu)
    assert main(["estimate", str(source), "--out", str(out)]) == 0
    previous = _digest(out)
    real_fdopen = os.fdopen

    class FullDisk:
        def __init__(self, fh):
            self.fh, self.written = fh, 0

        def write(self, data):
            self.written += len(data)
            if self.written > 4096:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return self.fh.write(data)

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

    monkeypatch.setattr(output.os, "fdopen", lambda fd, mode: FullDisk(real_fdopen(fd, mode)))
    for options in ([], ["--euler", "--offsets"]):
        capsys.readouterr()
        assert main(["estimate", str(source), "--out", str(out), *options]) == 2
        err = capsys.readouterr().err
        assert f"cannot write {out}: No space left on device; {out} is as it was" in err, err
        assert _digest(out) == previous
        assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv", "out.csv"]


def test_an_output_that_cannot_be_written_is_refused_before_any_work(tmp_path, imu, capsys):
    source = tmp_path / "in.csv"
    _write_csv(source, *imu)
    (tmp_path / "locked.csv").write_text("kept\n")
    (tmp_path / "locked.csv").chmod(0o444)
    for out, message in (("/proc/out.csv", "the folder /proc takes no new file"),
                         (str(tmp_path / "locked.csv"), "the file is read-only")):
        for command in (["estimate", str(source)], ["plot", str(source)]):
            assert main([*command, "--out", out]) == 2
            err = capsys.readouterr().err
            assert message in err and "attitude: read" not in err, err
    assert (tmp_path / "locked.csv").read_text() == "kept\n"


def test_standard_input_and_output_as_dash(tmp_path, imu):
    """`-` reads a CSV from standard input, `--out -` writes it to standard output: the
    same numbers as from and into files; so does /dev/stdin, a pipe that is no file."""
    source = tmp_path / "in.csv"
    _write_csv(source, *imu)
    assert main(["estimate", str(source), "--out", str(tmp_path / "file.csv")]) == 0
    command = [sys.executable, "-m", "attitude_fmu.systems.cli.commands", "estimate"]
    for args in (["-", "--out", "-"], ["/dev/stdin", "--out", "-"]):
        with open(source, "rb") as fh:
            run = subprocess.run([*command, *args], stdin=fh, capture_output=True, timeout=300)
        assert run.returncode == 0, run.stderr.decode()
        assert run.stdout == (tmp_path / "file.csv").read_bytes()
        assert b"wrote standard output" in run.stderr


def test_parquet_in_and_out_carry_the_csvs_estimate_to_every_bit(tmp_path, imu):
    """A .parquet input gives the estimate of the same recording as a CSV; a .parquet
    output holds the batch path's float64 values exactly, the CSV's to 10 digits."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    gyr, acc = imu
    t = np.arange(1, len(gyr) + 1) / FS
    columns = {"t": t, **{f"{s}_{a}": v[:, i] for s, v in (("gyr", gyr), ("acc", acc)) for i, a in enumerate("xyz")}}
    pq.write_table(pa.table(columns), tmp_path / "in.parquet")
    _write_csv(tmp_path / "in.csv", gyr, acc)
    assert main(["estimate", str(tmp_path / "in.parquet"), "--out", str(tmp_path / "out.parquet")]) == 0
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv")]) == 0
    table = pq.read_table(tmp_path / "out.parquet")
    ref = estimate(gyr, acc, FS)
    assert table.column_names == ["t", "q_w", "q_x", "q_y", "q_z", "g_x", "g_y", "g_z"]
    quat = np.column_stack([table.column(n).to_numpy() for n in ("q_w", "q_x", "q_y", "q_z")])
    assert np.array_equal(quat, ref.quat) and np.array_equal(table.column("t").to_numpy(), t)
    from_csv = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1)
    assert np.abs(from_csv[:, 1:5] - ref.quat).max() < 1e-9


def test_csv_numbers_are_those_of_ten_significant_digits():
    """significant() gives the double of each value's %.10g text (Python's formatting as
    the independent truth), from 1e-300 to 1e300."""
    rng = np.random.default_rng(3)
    x = rng.normal(size=20000) * 10.0 ** rng.integers(-300, 300, 20000)
    x[:4] = (0.0, -0.0, 123456789012.0, 5e-324)
    rounded = significant(x)
    ordinary = np.abs(np.floor(np.log10(np.abs(np.where(x == 0, 1, x))))) <= 12
    assert all(float(f"{v:.10g}") == r for v, r in zip(x[ordinary], rounded[ordinary]))
    assert all(r in (v, float(f"{v:.10g}")) for v, r in zip(x[~ordinary], rounded[~ordinary]))  # or as they are
