"""Reading real files: time stamps rounded or jittered off their grid and --fs over them,
columns by position under a header with empty, repeated or two rows of names, units written
in the header, a sensor piling up at its range, a magnetometer held between its updates,
and counts that say what they count. Each file is made by the test."""
import math

import numpy as np
import pytest
from scipy.io import savemat

from attitude_fmu import profile
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import G_N, IMU_COLUMNS, MAG_COLUMNS, RecordingError
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 90.0  # the pendulum trials' rate: 11.1 ms steps


@pytest.fixture(scope="module")
def human():
    """60 s of human motion at 90 Hz: (gyr, acc)."""
    motion = HumanMotion(delta_v=0.25, omega_c=5.0).generate(60.0, FS, seed=3)
    return ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=4)


def _write(path, columns: dict, header=None, units_row=None):
    """A CSV of columns ({name: values}) under header (default: the names) and a units row."""
    lines = [",".join(header or columns)] + ([",".join(units_row)] if units_row else [])
    data = np.column_stack(list(columns.values()))
    lines += [",".join(f"{v:.17g}" for v in row) for row in data]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def _imu(t, gyr, acc, extra=None):
    columns = {} if t is None else {"t": t}
    return {**columns, **dict(zip(IMU_COLUMNS, np.column_stack([gyr, acc]).T)), **(extra or {})}


def _ours(tmp_path, gyr, acc):
    """(time stamps, the output's path, the estimate) of our own CSV of gyr and acc at FS."""
    t = np.arange(1, len(gyr) + 1) / FS
    _write(tmp_path / "ours.csv", _imu(t, gyr, acc))
    out = tmp_path / "out.csv"
    assert main(["estimate", str(tmp_path / "ours.csv"), "--out", str(out)]) == 0
    return t, out, np.loadtxt(out, delimiter=",", skiprows=1)


def _notes(rec) -> str:
    return " ".join(rec.notes)


def test_time_stamps_rounded_to_10_ms_on_an_11_ms_grid_are_the_grid_they_round(tmp_path, human, capsys):
    """90 Hz stamped to 10 ms steps by 10 and 20 ms: the step reading alone takes them for
    100 Hz with a sample missing every ninth (or, jittered before rounding, refuses them as
    irregular). Every stamp lies within half the rounding (5 ms) of the least-squares line,
    so the rows are taken as uniform at its slope, 90 Hz, none filled, with a note that says
    so; the estimate is that of exact time stamps (to 1e-3: the rate to 1e-5). Jittered by
    ±2 ms before rounding (within a quarter step plus half the rounding), the same."""
    gyr, acc = human
    n = len(gyr)
    exact = estimate(gyr, acc, FS, gyro_offset=True).quat
    rng = np.random.default_rng(1)
    for name, stamps in (("rounded", np.round(np.arange(n) / FS, 2)),
                         ("jittered", np.round(np.arange(n) / FS + rng.uniform(-0.002, 0.002, n), 2))):
        assert set(np.round(np.diff(stamps), 6)) <= {0.0, 0.01, 0.02}, name
        _write(tmp_path / "in.csv", _imu(stamps, gyr, acc))
        rec = read_recording(tmp_path / "in.csv")
        assert rec.fs == pytest.approx(FS, rel=1e-5) and len(rec.gyr) == n and rec.filled is None, name
        assert "time stamps rounded to 0.01 s, every one within" in _notes(rec), rec.notes
        assert "of the uniform 90 Hz grid they round (the least-squares line through them)" in _notes(rec)
        assert "if samples are missing instead, give the sensor's rate with --fs HZ" in _notes(rec)
        out = tmp_path / "out.csv"
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out)]) == 0
        data = np.loadtxt(out, delimiter=",", skiprows=1)
        assert np.array_equal(data[:, 0], stamps) and np.abs(data[:, 1:5] - exact).max() < 1e-3, name
        assert "missing samples" not in capsys.readouterr().err


def test_fs_places_the_time_stamps_on_its_grid_or_overrides_them(tmp_path, human, capsys):
    """--fs given with a t column: stamps within half a step of its grid are placed on it
    (rounded ones: none missing; 100 Hz stamps with every 50th row dropped: those filled in,
    which read without --fs give the same), jitter of ±35 % of a step (refused without
    --fs: a quarter step is all the step reading and the line take) included. Stamps off its
    grid (a host clock 3 % fast) are kept for the output only, the rows taken as uniform at
    --fs. Each says so in a note; --fs far from the stamps' rate (a factor 2) is refused."""
    gyr, acc = human
    n = len(gyr)
    k = np.arange(n)
    rng = np.random.default_rng(2)
    _write(tmp_path / "in.csv", _imu(np.round(k / FS, 2), gyr, acc))
    rec = read_recording(tmp_path / "in.csv", fs=FS)
    assert rec.fs == FS and rec.filled is None
    assert "--fs 90 Hz given: the time stamps, up to 40% of a step off its grid, place the rows on it" in _notes(rec)

    jittered = (k + rng.uniform(-0.35, 0.35, n)) / FS
    _write(tmp_path / "in.csv", _imu(jittered, gyr, acc))
    with pytest.raises(RecordingError, match="column t is irregular.*give it with --fs HZ"):
        read_recording(tmp_path / "in.csv")
    rec = read_recording(tmp_path / "in.csv", fs=FS)
    assert rec.fs == FS and rec.filled is None and np.array_equal(rec.gyr, gyr)
    assert "place the rows on it" in _notes(rec)

    keep = np.ones(n, dtype=bool)
    keep[100::50] = False
    _write(tmp_path / "in.csv", _imu(k[keep] / 100.0, gyr[keep], acc[keep]))
    given, read = read_recording(tmp_path / "in.csv", fs=100.0), read_recording(tmp_path / "in.csv")
    assert given.fs == 100.0 and given.filled.sum() == (~keep).sum() and np.array_equal(given.filled, ~keep)
    assert np.allclose(given.gyr, read.gyr, rtol=0, atol=1e-12) and np.array_equal(given.filled, read.filled)

    fast = k / FS * 0.97  # the host's clock runs 3 % fast against the sensor's
    _write(tmp_path / "in.csv", _imu(fast, gyr, acc))
    out = tmp_path / "out.csv"
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--fs", "90"]) == 0
    err = capsys.readouterr().err
    assert (f"--fs 90 Hz given: the rows are taken as uniform at it; the time stamps ({FS / 0.97:.6g} Hz, not on "
            "its grid) are kept for the output only") in err, err
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.allclose(data[:, 0], fast, rtol=0, atol=1e-12)
    assert np.abs(data[:, 1:5] - estimate(gyr, acc, FS, gyro_offset=True).quat).max() < 1e-9
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--fs", "45"]) == 2
    assert (f"--fs 45 Hz disagrees with the time stamps' {FS / 0.97:.6g} Hz by more than 10%: is --fs or --t-unit "
            "wrong?" in capsys.readouterr().err)


def test_columns_by_position_under_empty_repeated_or_two_rows_of_names(tmp_path, human, capsys):
    """A logger's two-row header (names in one row, several empty, units in the next) cannot
    be read by names: refused with the header numbered; --column NAME=#N (counted from 1)
    reads it, and gives the estimate of our own CSV. A name the header repeats is refused
    with the positions to use; a position beyond the header, #0 and a position in a .mat
    are refused."""
    gyr, acc = human
    n = 600
    t, out, ours = _ours(tmp_path, gyr[:n], acc[:n])
    two_rows = tmp_path / "logger.csv"
    _write(two_rows, {"t": t, "temp": np.full(n, 21.5), **_imu(None, gyr[:n], acc[:n])},
           header=["Time", "Temperature", "Gyroscope", "", "", "Accelerometer", "", ""],
           units_row=["s", "degC", "rad/s", "rad/s", "rad/s", "m/s^2", "m/s^2", "m/s^2"])
    assert main(["estimate", str(two_rows), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert ("missing columns gyr_x, gyr_y, gyr_z, acc_x, acc_y, acc_z (header: Time,Temperature,Gyroscope,,,"
            "Accelerometer,,); name them by position, --column NAME=#N: #1 Time, #2 Temperature, #3 Gyroscope, "
            "#4 (unnamed), #5 (unnamed), #6 Accelerometer, #7 (unnamed), #8 (unnamed)") in err, err
    flags = [x for name, k in zip(("t", *IMU_COLUMNS), (1, 3, 4, 5, 6, 7, 8)) for x in ("--column", f"{name}=#{k}")]
    assert main(["estimate", str(two_rows), "--out", str(out), *flags]) == 0
    assert "1 row after the header without a number skipped (units?): s,degC,rad/s" in capsys.readouterr().err
    assert np.array_equal(np.loadtxt(out, delimiter=",", skiprows=1), ours)

    repeated = tmp_path / "repeated.csv"
    _write(repeated, _imu(t, gyr[:n], acc[:n]), header=["t", "gyro", "gyro", "gyro", "acc", "acc", "acc"])
    refused = {("--column", "gyr_x=gyro"): "--column names gyro, which the header has 3 times; select one by "
                                           "position, e.g. --column gyr_x=#2 (#1 t, #2 gyro, #3 gyro",
               ("--column", "gyr_x=#9"): "--column gyr_x=#9: the file has 7 columns, counted from #1: #1 t, #2 gyro",
               ("--column", "gyr_x=#2", "--column", "gyr_y=#2"): "--column gives the file's column #2 more than "
                                                                 "one name"}
    for given, message in refused.items():
        assert main(["estimate", str(repeated), "--out", str(out), *given]) == 2
        assert message in capsys.readouterr().err, message
    flags = [x for name, k in zip(IMU_COLUMNS, range(2, 8)) for x in ("--column", f"{name}=#{k}")]
    assert main(["estimate", str(repeated), "--out", str(out), *flags]) == 0
    assert np.array_equal(np.loadtxt(out, delimiter=",", skiprows=1), ours)
    with pytest.raises(SystemExit):
        main(["estimate", str(repeated), "--out", str(out), "--column", "gyr_x=#0"])
    assert "a column by position is #N, N counted from 1" in capsys.readouterr().err
    savemat(tmp_path / "in.mat", {"imu_gyr": gyr[:n], "imu_acc": acc[:n], "sampling_rate": FS})
    with pytest.raises(RecordingError, match="a .mat's variables are named, not numbered"):
        read_recording(tmp_path / "in.mat", columns={"imu_gyr": "#2"})


def test_units_written_in_the_header_are_named_with_their_flag(tmp_path, human, capsys):
    """"gyr_x (deg/s)" and "acc_x [g]" are read as gyr_x and acc_x; the units they write,
    or a units row writes ("°/s", "mG"), that differ from the unit in use are refused when
    no flag gave it, naming the flag; with the flag the file gives our CSV's estimate. A
    flag given against the header is obeyed, and noted. Units that agree pass silently."""
    gyr, acc = human
    n = 600
    t, out, ours = _ours(tmp_path, gyr[:n], acc[:n])
    header = ["t (s)", *(f"gyr_{a} (deg/s)" for a in "xyz"), *(f"acc_{a} [g]" for a in "xyz")]
    written = tmp_path / "written.csv"
    _write(written, _imu(t, np.degrees(gyr[:n]), acc[:n] / G_N), header=header)
    assert main(["estimate", str(written), "--out", str(out)]) == 2
    assert ("the header gives the gyro in deg/s ('gyr_x (deg/s)', 'gyr_y (deg/s)', 'gyr_z (deg/s)'), read in "
            "rad/s by default: pass --gyr-unit deg/s (or --gyr-unit rad/s to read it as rad/s)"
            in capsys.readouterr().err)
    assert main(["estimate", str(written), "--out", str(out), "--gyr-unit", "deg/s"]) == 2
    assert "the header gives the accelerometer in g" in capsys.readouterr().err
    assert main(["estimate", str(written), "--out", str(out), "--gyr-unit", "deg/s", "--acc-unit", "g"]) == 0
    assert "read 't (s)' as t, 'gyr_x (deg/s)' as gyr_x" in capsys.readouterr().err
    assert np.abs(np.loadtxt(out, delimiter=",", skiprows=1) - ours).max() < 1e-9

    _write(written, _imu(t, gyr[:n], acc[:n]), header=header)  # a header that says deg/s over rad/s
    rec = read_recording(written, gyr_unit="rad/s", acc_unit="m/s2")
    assert np.array_equal(rec.gyr, gyr[:n])
    assert "the header gives the gyro in deg/s ('gyr_x (deg/s)', 'gyr_y (deg/s)', 'gyr_z (deg/s)'); read in " \
           "rad/s as --gyr-unit says" in _notes(rec)
    mag = np.tile([200.0, 0.0, -400.0], (n, 1))  # mG
    units_row = ["s", "°/s", "°/s", "°/s", "m/s²", "m/s²", "m/s²", "mG", "mG", "mG"]
    _write(written, _imu(t, np.degrees(gyr[:n]), acc[:n], dict(zip(MAG_COLUMNS, mag.T))), units_row=units_row)
    with pytest.raises(RecordingError, match=r"gyro in deg/s \('°/s' under column #2, '°/s' under column #3, "
                                             r"'°/s' under column #4\).*pass --gyr-unit deg/s"):
        read_recording(written)
    with pytest.raises(RecordingError, match="the header gives the magnetometer in mG .*pass --mag-unit mG"):
        read_recording(written, gyr_unit="deg/s")
    rec = read_recording(written, gyr_unit="deg/s", mag_unit="mG")
    assert np.allclose(rec.mag, mag / 10) and not any("header gives" in note for note in rec.notes)


def _clipped_arm(fs):
    """A ±90° swing at 0.5 Hz at the end of a 1 m arm (an accelerometer's x beyond 2 g)
    at fs: (gyr, acc); a calibration with 0.4 % cross-axis terms applied after the sensor."""
    motion = profile("offset_rotation").motion({"frequency": 0.5, "amplitude_deg": 90.0, "radius": 1.0})
    gyr, acc = ImuModel(delta_n=math.radians(0.05), acc_noise=0.002).apply(motion.generate(60.0, fs), seed=9)
    calibration = np.eye(3) + 0.004 * np.array([[0, 1, -1], [1, 0, 1], [-1, 1, 0]])
    return gyr, acc, calibration


@pytest.mark.parametrize("fs", [40.0, 100.0])
def test_an_accelerometer_piling_up_at_its_range_is_noted(tmp_path, fs):
    """Clipped at 19.4 m/s² (±2 g less its offset) before a calibration spreads the clipped
    values over 0.2 %, at 40 Hz (the arm segments' rate) and 100 Hz: no run at exactly one
    value, yet the accelerometer piles up within 0.5 % of its extreme with few samples in
    the 5 % below it: noted with the axis, the value, the share and ±2 g. Unclipped, not;
    nor a gyro swinging ±90° at 1 Hz (its smooth peaks reached every period)."""
    gyr, acc, calibration = _clipped_arm(fs)
    for name, a, noted in (("clipped", np.clip(acc, -19.4, 19.4) @ calibration.T, True),
                           ("unclipped", acc @ calibration.T, False)):
        _write(tmp_path / "in.csv", _imu(np.arange(len(gyr)) / fs, gyr, a))
        notes = _notes(read_recording(tmp_path / "in.csv"))
        assert ("the accelerometer piles up at its extremes, clipped at its range: x at -19.47 m/s² (1.985 g; likely "
                "the ±2 g range): " in notes) == noted, (name, notes)
        assert "stays at its largest value" not in notes and "the gyro piles up" not in notes, notes
        if noted:
            share = np.mean(-a[:, 0] >= (-a[:, 0]).max() * 0.995)
            assert f"samples, {share:.1%} of them, within 0.5% of it against" in notes, notes


def test_a_gyro_piling_up_at_its_range_is_noted(tmp_path):
    """A ±90° swing at 1 Hz (565 °/s peaks) through a ±500 °/s gyro at 100 Hz, clipped
    before a 0.3 % scale error: the gyro piles up at ±8.754 rad/s: its ±500 °/s range."""
    motion = profile("sine_rotation").motion({"amplitude_deg": 90.0, "frequency": 1.0}).generate(30.0, 100.0)
    gyr, acc = ImuModel(delta_n=math.radians(0.05), acc_noise=0.002).apply(motion, seed=9)
    limit = math.radians(500.0)
    for clipped in (False, True):
        g = np.clip(gyr, -limit, limit) * (1.003 + 1e-4 * np.sin(np.arange(len(gyr)))[:, None]) if clipped else gyr
        _write(tmp_path / "in.csv", _imu(np.arange(len(gyr)) / 100.0, g, acc))
        notes = _notes(read_recording(tmp_path / "in.csv"))
        assert ("the gyro piles up at its extremes, clipped at its range: y at +8.754 rad/s (501.5 °/s; likely the "
                "±500 °/s range)" in notes) == clipped, notes


def test_a_held_magnetometer_is_read_as_no_sample_between_its_updates(tmp_path, human, capsys):
    """A magnetometer at 22.5 Hz whose logger repeats its last sample on the gyro's 90 Hz
    rows: the repeats are read as no sample (NaN), noted with their count and the rate, and
    the estimate is that of the same file with NaN written there. A magnetometer that
    repeats its value only while at rest (a noise-free field, every row new in motion) is
    read as it is; so is BROAD's, whose rows repeat in runs of 3 between single new ones
    (tests/test_broad_benchmark.py keeps its figures)."""
    gyr, acc = human
    n = len(gyr)
    t = np.arange(1, n + 1) / FS
    field = np.array([20.0, 0.0, -40.0]) + np.random.default_rng(3).normal(0.0, 0.3, (n, 3))
    updates = np.arange(n) % 4 == 0
    held = field[np.flatnonzero(updates)[np.cumsum(updates) - 1]]
    _write(tmp_path / "held.csv", _imu(t, gyr, acc, dict(zip(MAG_COLUMNS, held.T))))
    sparse = np.where(updates[:, None], field, np.nan)
    _write(tmp_path / "sparse.csv", _imu(t, gyr, acc, dict(zip(MAG_COLUMNS, sparse.T))))
    rec = read_recording(tmp_path / "held.csv")
    assert np.array_equal(np.isnan(rec.mag).any(axis=1), ~updates) and np.array_equal(rec.mag[updates], field[updates])
    assert (f"the magnetometer repeats its previous sample in {(~updates).sum()} of {n} rows: held between updates "
            "at about 22.5 Hz (a new value every 4 rows in the median); the repeats are taken as no sample (NaN)"
            ) in _notes(rec), rec.notes
    outputs = []
    for name in ("held", "sparse"):
        assert main(["estimate", str(tmp_path / f"{name}.csv"), "--out", str(tmp_path / f"{name}_out.csv")]) == 0
        outputs.append(np.loadtxt(tmp_path / f"{name}_out.csv", delimiter=",", skiprows=1))
    assert np.array_equal(outputs[0], outputs[1])
    capsys.readouterr()
    at_rest = np.tile([20.0, 0.0, -40.0], (n, 1))
    moving = np.arange(n) > n // 3
    at_rest[moving] += np.random.default_rng(4).normal(0.0, 0.3, (moving.sum(), 3))
    _write(tmp_path / "rest.csv", _imu(t, gyr, acc, dict(zip(MAG_COLUMNS, at_rest.T))))
    rec = read_recording(tmp_path / "rest.csv")
    assert np.array_equal(rec.mag, at_rest) and "repeats its previous sample" not in _notes(rec)
    runs = np.where(np.arange(n) % 4 == 0, 3, 1)  # a value held over 3 rows, then 3 new ones, as BROAD's
    broad_like = np.repeat(field, runs, axis=0)[:n]
    _write(tmp_path / "broad.csv", _imu(t, gyr, acc, dict(zip(MAG_COLUMNS, broad_like.T))))
    assert not np.isnan(read_recording(tmp_path / "broad.csv").mag).any()


def test_the_read_count_says_what_it_counts(tmp_path, human, capsys):
    """13514 rows whose time stamps skip 20 samples: "read 13514 samples …, and filled 20
    more into the gaps of its time stamps", not 13534 samples; a file without gaps says
    its rows only; the output has the input's rows."""
    gyr, acc = human
    n = 13534
    gyr, acc = np.resize(gyr, (n, 3)), np.resize(acc, (n, 3))
    t = np.arange(1, n + 1) / FS
    keep = np.ones(n, dtype=bool)
    keep[[500, 900, 1400]] = False
    keep[6000:6017] = False
    _write(tmp_path / "in.csv", _imu(t[keep], gyr[keep], acc[keep]))
    out = tmp_path / "out.csv"
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert (f"attitude: read 13514 samples at 90 Hz from {tmp_path / 'in.csv'}, and filled 20 more into the gaps "
            "of its time stamps (") in err and "13534" not in err, err
    assert "20 missing samples in 4 gaps" in err and len(np.loadtxt(out, delimiter=",", skiprows=1)) == 13514
    _write(tmp_path / "whole.csv", _imu(t[:1000], gyr[:1000], acc[:1000]))
    assert main(["estimate", str(tmp_path / "whole.csv"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"attitude: read 1000 samples at 90 Hz from {tmp_path / 'whole.csv'} (" in err and "filled" not in err
