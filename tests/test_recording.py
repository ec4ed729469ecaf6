"""Reading recordings: CSV time stamps that jitter, are rounded or skip samples, and a
reference orientation in a CSV, evaluated as a BROAD .mat is."""
import json
import math
import shlex
import warnings

import numpy as np
import pytest
from scipy.io import savemat
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import inclination_error, rms
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import IMU_COLUMNS, REF_COLUMNS, RecordingError
from attitude_fmu import profile
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.motions import ClosedFormMotion

FS = 100.0


@pytest.fixture(scope="module")
def recording():
    """120 s of human motion at 100 Hz: (motion, gyr, acc, true up in sensor coordinates)."""
    motion = HumanMotion(delta_v=0.25, omega_c=5.0).generate(120.0, FS, seed=3)
    gyr, acc = ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=4)
    up = Rotation.from_quat(motion.quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    return motion, gyr, acc, up


def _write(path, t, gyr, acc, extra=None):
    columns = {"t": t, **{c: v for c, v in zip(IMU_COLUMNS, np.column_stack([gyr, acc]).T)}, **(extra or {})}
    np.savetxt(path, np.column_stack(list(columns.values())), delimiter=",", header=",".join(columns),
               comments="", fmt="%.17g")


def _estimate_csv(tmp_path, capsys, *flags):
    out = tmp_path / "out.csv"
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), *flags]) == 0
    return np.loadtxt(out, delimiter=",", skiprows=1), capsys.readouterr().err


def test_rounded_and_jittering_time_stamps_give_the_rate_of_the_whole_span(tmp_path, recording, capsys):
    """At 285.7 Hz (BROAD's rate) time stamps rounded to 0.1 ms step by 3.5 or 3.4 ms; a
    host clock jitters by ±20 % of a step. Both are read as uniform at the true rate, with
    the estimate of exact time stamps; only the jitter is noted."""
    _, gyr, acc, _ = recording
    fs = 285.7
    t = np.arange(len(gyr)) / fs
    jitter = np.random.default_rng(1).uniform(-0.2, 0.2, len(t)) / fs
    exact = estimate(gyr, acc, fs, gyro_offset=True).quat
    for stamps, noted in ((np.round(t, 4), False), (t + jitter, True)):
        _write(tmp_path / "in.csv", stamps, gyr, acc)
        assert read_recording(tmp_path / "in.csv").fs == pytest.approx(fs, rel=1e-5)
        data, err = _estimate_csv(tmp_path, capsys)
        assert np.allclose(data[:, 0], stamps, atol=1e-7)  # the input's time stamps
        assert np.abs(data[:, 1:5] - exact).max() < 1e-5
        assert ("off a uniform grid; the samples are taken as uniform at 285.7 Hz" in err) == noted, err


def test_a_spreadsheets_header_and_separators_read_as_ours(tmp_path, recording):
    """A byte-order mark and spaces around the names (as spreadsheets export), semicolons
    with decimal commas (a spreadsheet in a German locale), tabs and a units row under the
    header (noted) change nothing; four rows without a number are not taken for units. A
    row that is not numbers is refused naming its line and column."""
    _, gyr, acc, _ = recording
    t = np.arange(1, 101) / FS
    _write(tmp_path / "plain.csv", t, gyr[:100], acc[:100])
    lines = (tmp_path / "plain.csv").read_text().splitlines()
    sheets = {
        "sheet.csv": ["\ufeff" + ", ".join(lines[0].split(",")), *lines[1:]],
        "semicolon.csv": [line.replace(",", ";").replace(".", ",") for line in lines],
        "tab.tsv": [line.replace(",", "\t") for line in lines],
        "units.csv": [lines[0], "s,rad/s,rad/s,rad/s,m/s²,m/s²,m/s²", *lines[1:]],
        "units_semicolon.csv": [line.replace(",", ";").replace(".", ",") for line in lines[:1]]
        + ["[s];[rad/s];[rad/s];[rad/s];[m/s²];[m/s²];[m/s²]", "; ; ; ; ; ;"]
        + [line.replace(",", ";").replace(".", ",") for line in lines[1:]],
    }
    plain = read_recording(tmp_path / "plain.csv")
    for name, sheet_lines in sheets.items():
        (tmp_path / name).write_text("\n".join(sheet_lines) + "\n", encoding="utf-8")
        sheet = read_recording(tmp_path / name)
        assert sheet.fs == plain.fs and np.array_equal(sheet.t, plain.t), name
        assert np.array_equal(sheet.gyr, plain.gyr) and np.array_equal(sheet.acc, plain.acc), name
        assert any("after the header without a number skipped (units?)" in n for n in sheet.notes) == ("units" in name)
    assert "," in sheets["semicolon.csv"][1]  # the decimal commas were there to be read
    (tmp_path / "labels.csv").write_text("\n".join([lines[0], *["a,b,c,d,e,f,g"] * 4, *lines[1:]]) + "\n")
    with pytest.raises(RecordingError, match="unreadable number in line 2, column t: 'a'"):
        read_recording(tmp_path / "labels.csv")
    for bad_line, message in ((lines[5].rsplit(",", 1)[0], "line 6 has 6 fields, the header 7"),
                              (lines[5].rsplit(",", 1)[0] + ",9.8 m/s²",
                               "unreadable number in line 6, column acc_z: '9.8 m/s²'")):
        (tmp_path / "bad.csv").write_text("\n".join([*lines[:5], bad_line, *lines[6:]]) + "\n", encoding="utf-8")
        with pytest.raises(RecordingError, match=message):
            read_recording(tmp_path / "bad.csv")


def test_columns_it_cannot_use_are_refused_or_named(tmp_path, recording, capsys):
    """A magnetometer with an axis missing is refused, as a partial reference is; columns
    it does not know (a capitalised name, a temperature) are named on standard error, not
    silently dropped; a header without rows is refused in one message."""
    _, gyr, acc, _ = recording
    t = np.arange(1, 101) / FS
    field = {f"mag_{a}": np.full(100, v) for a, v in zip("xy", (20.0, -40.0))}
    _write(tmp_path / "in.csv", t, gyr[:100], acc[:100], field)
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert "the magnetometer needs all of mag_x,mag_y,mag_z, the header has only mag_x,mag_y" in err, err
    _write(tmp_path / "in.csv", t, gyr[:100], acc[:100], {"mag_X": np.ones(100), "temp": np.ones(100)})
    plain, _ = _estimate_csv(tmp_path, capsys)
    assert "columns not read: mag_X, temp" in _estimate_csv(tmp_path, capsys)[1]
    _write(tmp_path / "in.csv", t, gyr[:100], acc[:100])
    assert np.array_equal(_estimate_csv(tmp_path, capsys)[0], plain)
    (tmp_path / "in.csv").write_text("t," + ",".join(IMU_COLUMNS) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv")]) == 2
    assert "expected 7 columns of numbers and at least one row" in capsys.readouterr().err


def test_a_loggers_header_is_read_through_column_names(tmp_path, recording, capsys):
    """A logger's export (Xsens-style names, deg/s and g, no t) is refused with the
    --column flags that read it, and read with them gives our CSV's estimate; so does a
    header marked as a comment with spaces in its names and t in ns (EuRoC-style). A
    column of the file that has a name given to another is left unread and noted;
    a name given twice, a header name not in the file, one given two names and a name
    not read are refused. A .mat of one's own is refused naming its variables, and read
    with them named for BROAD's."""
    _, gyr, acc, _ = recording
    n = 1000
    t = np.arange(1, n + 1) / FS
    _write(tmp_path / "in.csv", t, gyr[:n], acc[:n])
    ours, _ = _estimate_csv(tmp_path, capsys)
    export = tmp_path / "export.csv"
    np.savetxt(export, np.column_stack([np.arange(n), acc[:n] / 9.80665, np.degrees(gyr[:n])]), delimiter=",",
               header="PacketCounter,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z", comments="", fmt="%.17g")
    flags = ["--fs", str(FS), "--gyr-unit", "deg/s", "--acc-unit", "g"]
    out = tmp_path / "out.csv"
    assert main(["estimate", str(export), "--out", str(out), *flags]) == 2
    err = capsys.readouterr().err
    assert "missing columns gyr_x, gyr_y, gyr_z, acc_x, acc_y, acc_z" in err, err
    hinted = shlex.split(err.split("to read them pass ")[1])
    assert hinted == [x for c in ("gyr", "acc") for a in "xyz" for x in ("--column", f"{c}_{a}={c.title()}_{a.upper()}")]
    assert main(["estimate", str(export), "--out", str(out), *flags, *hinted]) == 0
    assert "columns not read: PacketCounter" in capsys.readouterr().err
    assert np.abs(np.loadtxt(out, delimiter=",", skiprows=1)[:, 1:] - ours[:, 1:]).max() < 1e-9

    names = ["timestamp [ns]", *(f"{s}_RS_S_{a} [{u}]" for s, u in (("w", "rad s^-1"), ("a", "m s^-2")) for a in "xyz")]
    euroc = tmp_path / "euroc.csv"
    np.savetxt(euroc, np.column_stack([np.round(t * 1e9), gyr[:n], acc[:n]]), delimiter=",", header=",".join(names),
               fmt="%.17g")  # numpy's default comments="# "
    renames = [x for ours_name, theirs in zip(("t", *IMU_COLUMNS), names) for x in ("--column", f"{ours_name}={theirs}")]
    assert main(["estimate", str(euroc), "--out", str(out), "--t-unit", "ns", *renames]) == 0
    assert np.abs(np.loadtxt(out, delimiter=",", skiprows=1) - ours).max() < 1e-9
    capsys.readouterr()

    _write(tmp_path / "in.csv", t, gyr[:n], acc[:n], {"time": t + 5.0})  # t, and the logger's own time
    shifted, err = _estimate_csv(tmp_path, capsys, "--column", "t=time")
    assert "columns not read: t (replaced by --column)" in err, err
    assert np.allclose(shifted[:, 0], ours[:, 0] + 5.0) and np.array_equal(shifted[:, 1:], ours[:, 1:])
    savemat(tmp_path / "in.mat", {"imu_gyr": gyr[:n], "imu_acc": acc[:n], "sampling_rate": FS})
    refused = {
        ("--column", "gyr_x=time", "--column", "gyr_x=t"): "--column gives gyr_x more than once",
        ("--column", "gyr_x=temp"): "--column names temp, not in the header",
        ("--column", "gyr_x=time", "--column", "gyr_y=time"): "--column gives the file's column time more than one name",
    }
    for flags_given, message in refused.items():
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), *flags_given]) == 2
        assert message in capsys.readouterr().err, message
    assert main(["estimate", str(tmp_path / "in.mat"), "--out", str(out), "--column", "t=time"]) == 2
    assert "--column names t; a .mat's names read are imu_gyr, imu_acc" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--column", "gyro_x=time"])
    assert "'gyro_x' is not a column read" in capsys.readouterr().err
    # a .mat of one's own: its variables named for BROAD's, as the message says
    savemat(tmp_path / "own.mat", {"gyro": gyr[:n], "accel": acc[:n], "rate": FS})
    assert main(["estimate", str(tmp_path / "own.mat"), "--out", str(out)]) == 2
    assert ("missing variables imu_gyr, imu_acc, sampling_rate (expected a BROAD recording; without sampling_rate "
            "give --fs HZ; the file has gyro, accel, rate: name them with --column") in capsys.readouterr().err
    assert main(["estimate", str(tmp_path / "own.mat"), "--out", str(out), "--column", "imu_gyr=gyro",
                 "--column", "imu_acc=accel", "--column", "sampling_rate=rate"]) == 0
    assert np.array_equal(np.loadtxt(out, delimiter=",", skiprows=1)[:, 1:], ours[:, 1:])


def test_a_sensor_held_at_its_range_is_noted(tmp_path):
    """A gyro of ±125 °/s on vigorous human motion and an accelerometer of ±2 g on a ±90°
    swing at 0.5 Hz at the end of a 1 m arm (16-bit and 1 mg samples) stay at their range for tens
    of ms: each is noted with its axes and value. The same samples unclipped are not; nor
    are a 1 kHz recording of a ±90° swing at 1 Hz (a smooth peak of 565 °/s, where 16-bit
    samples of ±2000 °/s hold one value for a few ms) and a noise-free turntable at a
    steady 3 rad/s (16-bit samples, which hold it exactly), throughout or after 40 s at rest."""
    lsb = math.radians(2000.0) / 32768
    quantized = lambda g, a: (np.round(g / lsb) * lsb, np.round(a / 1e-3) * 1e-3)
    sensor = ImuModel(delta_n=math.radians(0.05), acc_noise=0.002)
    human = quantized(*sensor.apply(HumanMotion(delta_v=0.2, omega_c=5.0).generate(60.0, FS, seed=8), seed=9))
    arm_motion = profile("offset_rotation").motion({"frequency": 0.5, "amplitude_deg": 90.0, "radius": 1.0})
    arm = quantized(*sensor.apply(arm_motion.generate(60.0, FS), seed=9))
    swing = profile("sine_rotation").motion({"amplitude_deg": 90.0, "frequency": 1.0}).generate(30.0, 1000.0)
    assert np.abs(swing.gyr).max() > math.radians(560.0)
    turntable = profile("lever_arm").motion({"rate": 3.0}).generate(60.0, FS)
    turned = lambda t: Rotation.from_rotvec(np.outer(3.0 * np.maximum(t - 40.0, 0.0), [0, 0, 1]))
    started = ClosedFormMotion(turned).generate(60.0, FS)
    gyr_limit = math.radians(125.0)
    cases = [  # (name, (gyr, acc), the note, rate)
        ("gyro", (np.clip(human[0], -gyr_limit, gyr_limit), human[1]),
         "the gyro stays at its largest value on x at ±2.182 rad/s", FS),
        ("acc", (arm[0], np.clip(arm[1], -19.6133, 19.6133)),
         "the accelerometer stays at its largest value on x at ±19.61 m/s²", FS),
        ("human", human, None, FS),
        ("arm", arm, None, FS),
        ("swing", quantized(swing.gyr, swing.acc), None, 1000.0),
        ("turntable", quantized(turntable.gyr, turntable.acc), None, FS),
        ("started", quantized(started.gyr, started.acc), None, FS),
    ]
    for name, (gyr, acc), noted, fs in cases:
        savemat(tmp_path / "in.mat", {"imu_gyr": gyr, "imu_acc": acc, "sampling_rate": fs})
        notes = " ".join(read_recording(tmp_path / "in.mat").notes)
        assert (noted in notes) if noted else ("largest value" not in notes), (name, notes)


def test_mat_files_with_a_transposed_array_no_rate_or_no_magnetometer_sample(tmp_path, recording, capsys):
    """A 3×N array is refused with the hint to transpose it; a file without sampling_rate
    reads at --fs; a magnetometer that is NaN throughout is noted and left out (6D), as
    --heading gyro would, instead of ending the run."""
    _, gyr, acc, _ = recording
    gyr, acc = gyr[:1000], acc[:1000]
    savemat(tmp_path / "t.mat", {"imu_gyr": gyr.T, "imu_acc": acc.T, "sampling_rate": FS})
    assert main(["estimate", str(tmp_path / "t.mat"), "--out", str(tmp_path / "o.csv")]) == 2
    assert "gyr must be N×3 with N ≥ 1, got (3, 1000); stored as 3×N? transpose it" in capsys.readouterr().err
    savemat(tmp_path / "ref.mat", {"imu_gyr": gyr, "imu_acc": acc, "sampling_rate": FS})
    savemat(tmp_path / "in.mat", {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": np.full_like(gyr, np.nan)})
    assert main(["estimate", str(tmp_path / "in.mat"), "--out", str(tmp_path / "o.csv")]) == 2
    assert "missing variables sampling_rate" in capsys.readouterr().err
    outputs = []
    for name, flags in (("in", ["--fs", str(FS)]), ("ref", ["--heading", "gyro"])):
        assert main(["estimate", str(tmp_path / f"{name}.mat"), "--out", str(tmp_path / f"{name}.csv"), *flags]) == 0
        outputs.append((np.loadtxt(tmp_path / f"{name}.csv", delimiter=",", skiprows=1), capsys.readouterr().err))
    assert np.array_equal(outputs[0][0], outputs[1][0])
    assert "the magnetometer has no sample (NaN throughout); heading from the gyro" in outputs[0][1]


def _savemat_v73(path, variables):
    """A MATLAB v7.3 file as MATLAB writes one: HDF5 behind a 512-byte block whose first 128
    bytes are the MAT header (version 0x0200), arrays stored transposed."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            f.create_dataset(name, data=np.atleast_2d(np.asarray(value, dtype=float)).T).attrs["MATLAB_class"] = b"double"
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Wed Nov 25 08:00:00 2026 HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(header.ljust(116) + bytes(8) + b"\x00\x02IM")


def test_a_mat_file_of_matlab_v73_reads_as_an_older_one(tmp_path, recording):
    """MATLAB v7.3 (HDF5, which scipy's loadmat does not read) gives the same recording as
    the v5 file of the same variables, transposition and a scalar rate included; a file
    that only claims to be v7.3 is refused with a message."""
    motion, gyr, acc, _ = recording
    n = 500
    variables = {"imu_gyr": gyr[:n], "imu_acc": acc[:n], "sampling_rate": FS,
                 "opt_quat": motion.quat[:n], "movement": np.arange(n) > 100}
    savemat(tmp_path / "v5.mat", variables)
    _savemat_v73(tmp_path / "v73.mat", variables)
    old, new = read_recording(tmp_path / "v5.mat"), read_recording(tmp_path / "v73.mat")
    assert new.fs == FS
    for name in ("gyr", "acc", "t", "quat_ref", "movement"):
        assert np.array_equal(getattr(new, name), getattr(old, name)), name
    with open(tmp_path / "v73.mat", "r+b") as fh:  # the header stays, the HDF5 behind it goes
        fh.truncate(600)
    with pytest.raises(RecordingError, match="not a readable MATLAB v7.3 file"):
        read_recording(tmp_path / "v73.mat")


def test_time_stamps_in_milliseconds_need_their_unit(tmp_path, recording, capsys):
    """t in ms (10, 20, …) read as seconds is a 0.1 Hz recording: refused with the hint;
    with --t-unit ms it is the recording in seconds."""
    _, gyr, acc, _ = recording
    t = np.arange(1, 1001) / FS
    _write(tmp_path / "in.csv", t, gyr[:1000], acc[:1000])
    seconds, _ = _estimate_csv(tmp_path, capsys)
    _write(tmp_path / "in.csv", np.round(t * 1000), gyr[:1000], acc[:1000])
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "o.csv")]) == 2
    assert "a sample rate of 0.1 Hz is outside the 1–100000 Hz of IMUs; are the time stamps in seconds? " \
           "If not, pass --t-unit (s, ms, us, ns)" in capsys.readouterr().err
    milliseconds, _ = _estimate_csv(tmp_path, capsys, "--t-unit", "ms")
    assert np.allclose(milliseconds, seconds, rtol=0, atol=1e-9)


def test_one_time_stamp_reads_at_the_rate_given(tmp_path, capsys):
    """A CSV of one row has no step to take the rate from: refused with the hint, and read
    at --fs, its time stamp kept, with it."""
    (tmp_path / "in.csv").write_text("t," + ",".join(IMU_COLUMNS) + "\n0.5,0.01,0,0,0,0,9.8\n")
    with pytest.raises(RecordingError, match="one sample cannot give a sample rate; give --fs HZ"):
        read_recording(tmp_path / "in.csv")
    rec = read_recording(tmp_path / "in.csv", fs=FS)
    assert rec.fs == FS and np.array_equal(rec.t, [0.5])
    data, _ = _estimate_csv(tmp_path, capsys, "--fs", str(FS))
    assert data.shape == (8,) and data[0] == 0.5 and np.allclose(data[5:8], [0.0, 0.0, 1.0])


def _kept_rows(n, seed, runs):
    """(n, bool) rows a logger kept: False in `runs` dropouts of 1–29 rows from a fixed seed."""
    rng = np.random.default_rng(seed)
    keep = np.ones(n, dtype=bool)
    for start in rng.integers(100, n - 100, runs):
        keep[start:start + rng.integers(1, 30)] = False
    return keep


def test_missing_samples_are_filled_in_and_the_output_keeps_the_input_rows(tmp_path, recording, capsys):
    """30 runs of 1–29 dropped samples: filled in (gyro and accelerometer interpolated), the
    inclination error at the rows kept is below that of the same rows taken as uniform (the
    rotation during each gap lost; measured 6.0° against 6.3°, 0.8° with no sample dropped;
    over other realisations of the motion 5.4–6.7° against 9.5–12.7°), and the output has
    the input's rows."""
    _, gyr, acc, up = recording
    keep = _kept_rows(len(gyr), seed=5, runs=30)
    t = np.arange(1, len(gyr) + 1) / FS
    _write(tmp_path / "in.csv", t[keep], gyr[keep], acc[keep])
    data, err = _estimate_csv(tmp_path, capsys)
    assert np.allclose(data[:, 0], t[keep], atol=1e-9)
    assert f"{(~keep).sum()} missing samples in 30 gaps" in err
    filled = rms(inclination_error(data[:, 5:8], up[keep]))
    as_uniform = rms(inclination_error(estimate(gyr[keep], acc[keep], FS, gyro_offset=True).up, up[keep]))
    complete = rms(inclination_error(estimate(gyr, acc, FS, gyro_offset=True).up, up))
    print(f"\ninclination RMS: complete {math.degrees(complete):.2f}°, gaps filled {math.degrees(filled):.2f}°, "
          f"gaps ignored {math.degrees(as_uniform):.2f}°")
    assert complete < filled < as_uniform


def test_rows_that_are_not_finite_are_filled_in_as_missing_samples_are(tmp_path, recording, capsys):
    """A logger's dropouts written as NaN (or ±inf) rows, in a CSV or a .mat: interpolated as
    the same rows missing from the time stamps are, so the estimate at the other rows is
    theirs; the output keeps every row. Such values in the first or last row, or in a run
    longer than --max-gap, are refused."""
    _, gyr, acc, _ = recording
    keep = _kept_rows(len(gyr), seed=6, runs=20)
    t = np.arange(1, len(gyr) + 1) / FS
    _write(tmp_path / "in.csv", t[keep], gyr[keep], acc[keep])
    missing, _ = _estimate_csv(tmp_path, capsys)
    dropped_gyr, dropped_acc = gyr.copy(), acc.copy()
    dropped_gyr[~keep], dropped_acc[~keep] = np.nan, np.where(np.arange(len(gyr)) % 2, np.inf, np.nan)[~keep, None]
    _write(tmp_path / "in.csv", t, dropped_gyr, dropped_acc)
    data, err = _estimate_csv(tmp_path, capsys)
    runs = int((np.diff(keep.astype(int)) == -1).sum())
    assert f"{(~keep).sum()} rows with gyro or accelerometer values that are not finite, in {runs} runs" in err, err
    assert len(data) == len(gyr) and np.abs(data[keep] - missing).max() < 1e-9
    savemat(tmp_path / "in.mat", {"imu_gyr": dropped_gyr, "imu_acc": dropped_acc, "sampling_rate": FS})
    assert np.array_equal(read_recording(tmp_path / "in.mat").acc, read_recording(tmp_path / "in.csv").acc)
    dropped_gyr[~keep] = gyr[~keep]
    dropped_gyr[~keep, 1] = np.nan  # one column lost: the others are kept
    _write(tmp_path / "in.csv", t, dropped_gyr, acc)
    partial = read_recording(tmp_path / "in.csv").gyr
    assert np.array_equal(partial[:, [0, 2]], gyr[:, [0, 2]]) and np.array_equal(partial[keep], gyr[keep])
    for rows, flags, message in ((slice(0, 1), [], "not finite in the first row"),
                                 (slice(-1, None), [], "not finite in the last row"),
                                 (slice(300, 321), ["--max-gap", "0.2"], "not finite in rows 301–321, longer than "
                                                                         "--max-gap 0.2 s")):
        bad = gyr.copy()
        bad[rows] = np.nan
        _write(tmp_path / "in.csv", t, bad, acc)
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "o.csv"), *flags]) == 2
        assert message in capsys.readouterr().err


def test_time_stamps_that_cannot_be_read_as_one_rate_are_refused(tmp_path, recording, capsys):
    _, gyr, acc, _ = recording
    t = np.arange(1, len(gyr) + 1) / FS
    gap = np.concatenate([t[:500], t[700:]])  # 2 s missing
    half_rate = np.concatenate([t[:6000], t[6000] + 0.015 * np.arange(len(t) - 6000)])
    cases = {"a gap of 2 s, longer than --max-gap 1 s": gap,
             "does the sample rate change?": half_rate,
             "must increase strictly": np.concatenate([t[:9], t[8:-1]])}
    for message, stamps in cases.items():
        _write(tmp_path / "in.csv", stamps, gyr[:len(stamps)], acc[:len(stamps)])
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "o.csv")]) == 2
        assert message in capsys.readouterr().err, message
    _write(tmp_path / "in.csv", gap, gyr[:len(gap)], acc[:len(gap)])
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "o.csv"), "--max-gap", "2"]) == 0
    assert "200 missing samples in 1 gap (the longest 2 s)" in capsys.readouterr().err


def _turns():
    return ClosedFormMotion(lambda t: Rotation.from_euler("ZY", np.column_stack([
        0.8 * np.sin(0.5 * t), 0.5 * np.sin(0.3 * t)]))).generate(60.0, FS)


def test_a_csv_with_a_reference_is_evaluated_as_the_same_mat(tmp_path, capsys):
    """ref_q_w..z and movement in a CSV give the figures of the BROAD .mat with opt_quat and
    movement; without movement every sample with a reference counts, as a .mat without it."""
    motion = _turns()
    gyr, acc = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002).apply(motion, seed=1)
    t = np.arange(1, len(gyr) + 1) / FS
    ref = motion.quat.copy()
    ref[100:120] = np.nan
    movement = (np.arange(len(gyr)) > 500).astype(float)
    results = {}
    for name, flag in (("moving", movement), ("whole", None)):
        mat = {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": motion.mag, "sampling_rate": FS, "opt_quat": ref}
        csv = {**{c: v for c, v in zip(("mag_x", "mag_y", "mag_z"), motion.mag.T)},
               **{c: v for c, v in zip(REF_COLUMNS, ref.T)}}
        if flag is not None:
            mat["movement"] = csv["movement"] = flag
        savemat(tmp_path / f"{name}.mat", mat)
        _write(tmp_path / f"{name}.csv", t, gyr, acc, csv)
        for suffix in ("mat", "csv"):
            assert main(["evaluate", "--json", str(tmp_path / f"{name}.{suffix}")]) == 0
            out = capsys.readouterr()
            results[name, suffix] = json.loads(out.out)["mean"]
            assert ("no movement flag; errors over every sample with a reference" in out.err) == (flag is None)
        for label, row in results[name, "mat"].items():
            assert results[name, "csv"][label] == pytest.approx(row, rel=1e-9), label
    # the start (the filter settling, no movement flag) counts only without the flag
    assert results["whole", "csv"]["wiener"] != pytest.approx(results["moving", "csv"]["wiener"], rel=1e-3)


@pytest.mark.parametrize("case", ["partial", "not unit", "movement 2"])
def test_a_bad_reference_in_a_csv_is_refused(tmp_path, capsys, case):
    motion = _turns()
    gyr, acc = ImuModel().apply(motion, seed=1)
    ref = {c: v for c, v in zip(REF_COLUMNS, motion.quat.T)}
    expected = {"partial": "the reference needs all of ref_q_w,ref_q_x,ref_q_y,ref_q_z",
                "not unit": "the reference quaternion in row 1 has the norm 2",
                "movement 2": "movement must be 0 or 1, row 1 has 2"}[case]
    if case == "partial":
        del ref["ref_q_z"]
    elif case == "not unit":
        ref = {c: 2 * v for c, v in ref.items()}
    else:
        ref["movement"] = np.full(len(gyr), 2.0)
    _write(tmp_path / "in.csv", np.arange(1, len(gyr) + 1) / FS, gyr, acc, ref)
    assert main(["evaluate", str(tmp_path / "in.csv")]) == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err, err
