"""The `attitude` command line: its contract (columns, JSON keys) and its errors."""
import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest
from scipy.io import savemat
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings.writing import EULER_COLUMNS, OUTPUT_COLUMNS
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0


@pytest.fixture(scope="module")
def imu():
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(30.0, FS, seed=11)
    return ImuModel(delta_n=math.radians(0.05)).apply(motion, seed=12)


def _write_csv(path, columns: dict):
    names = list(columns)
    np.savetxt(path, np.column_stack([columns[n] for n in names]), delimiter=",",
               header=",".join(names), comments="", fmt="%.17g")


def _imu_columns(gyr, acc, with_t=True):
    cols = {"t": np.arange(1, len(gyr) + 1) / FS} if with_t else {}
    cols.update({f"gyr_{a}": gyr[:, i] for i, a in enumerate("xyz")})
    cols.update({f"acc_{a}": acc[:, i] for i, a in enumerate("xyz")})
    return cols


def _read_output(path):
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1)


def test_estimate_csv_writes_the_contracted_columns_equal_to_the_batch_path(tmp_path, imu, capsys):
    gyr, acc = imu
    _write_csv(tmp_path / "in.csv", _imu_columns(gyr, acc))
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv"),
                 "--param", "delta_n=0.001", "--param", "delta_v=1.5"]) == 0
    progress = [line for line in capsys.readouterr().err.splitlines() if line.endswith(" s)")]
    assert [line.split(" (")[0] for line in progress] == [
        f"attitude: read {len(gyr)} samples at {FS:g} Hz from {tmp_path / 'in.csv'}",
        "attitude: estimated with wiener", f"attitude: wrote {tmp_path / 'out.csv'}"]
    header, data = _read_output(tmp_path / "out.csv")
    assert header == list(OUTPUT_COLUMNS)
    ref = estimate(gyr, acc, FS, "wiener", {"delta_n": 0.001, "delta_v": 1.5}, gyro_offset=True)  # CLI defaults
    assert np.allclose(data[:, 0], np.arange(1, len(gyr) + 1) / FS)
    assert np.abs(data[:, 1:5] - ref.quat).max() < 1e-9
    assert np.abs(data[:, 5:8] - ref.up).max() < 1e-9
    assert np.allclose(np.linalg.norm(data[:, 5:8], axis=1), 1.0)


def test_euler_adds_the_angles_of_the_fmus_outputs(tmp_path, imu):
    """--euler appends roll, pitch, yaw in degrees, those the AttitudeEstimator FMU outputs: the
    Z-Y-X angles of the same quaternions (scipy's as_euler("ZYX"), reversed); the other columns stay."""
    gyr, acc = imu
    _write_csv(tmp_path / "in.csv", _imu_columns(gyr, acc))
    outputs = {}
    for flags in ([], ["--euler"]):
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv"), *flags]) == 0
        outputs[bool(flags)] = _read_output(tmp_path / "out.csv")
    header, data = outputs[True]
    assert header == [*OUTPUT_COLUMNS, *EULER_COLUMNS]
    assert np.array_equal(data[:, :len(OUTPUT_COLUMNS)], outputs[False][1])
    fmu_angles = Rotation.from_quat(data[:, 1:5], scalar_first=True).as_euler("ZYX", degrees=True)[:, ::-1]
    assert np.abs(data[:, len(OUTPUT_COLUMNS):] - fmu_angles).max() < 1e-6
    assert np.ptp(data[:, -3:], axis=0).min() > 5.0  # the motion turns every angle


def test_offsets_add_the_gyro_offset_and_hard_iron_estimates_that_find_the_sensors(tmp_path):
    """--offsets appends the gyro-offset and hard-iron estimates and the magnetometer's delay
    allowed for after each sample, the batch path's (and the FMU's outputs of those names;
    the delay's is mag_delay_used); on 120 s of human motion from a
    gyro (1, −0.6, 0.4) °/s off and a magnetometer with (15, −10, 5) µT of hard iron they
    end within 0.1 °/s (tracked in motion alone: the motion never rests) and 0.5 µT of the
    truth. With --gyro-offset off the gyro columns are 0; without a magnetometer there are
    no hard-iron columns."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(120.0, FS, seed=11)
    truth_gyr, truth_mag = np.radians([1.0, -0.6, 0.4]), np.array([15.0, -10.0, 5.0])
    sensor = ImuModel(delta_n=math.radians(0.05), gyr_offset=tuple(truth_gyr), mag_noise=0.2,
                      mag_offset=tuple(truth_mag))
    gyr, acc = sensor.apply(motion, seed=12)
    mag = sensor.apply_mag(motion, seed=12)
    _write_csv(tmp_path / "in.csv", {**_imu_columns(gyr, acc), **{f"mag_{a}": mag[:, i] for i, a in enumerate("xyz")}})
    out = tmp_path / "out.csv"
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--euler", "--offsets"]) == 0
    header, data = _read_output(out)
    offsets = [f"{s}_offset_{a}" for s in ("gyr", "mag") for a in "xyz"]
    assert header == [*OUTPUT_COLUMNS, *EULER_COLUMNS, *offsets, "mag_delay"]
    ref = estimate(gyr, acc, FS, gyro_offset=True, mag=mag)
    assert np.allclose(data[:, -7:-4], ref.offset, rtol=1e-9, atol=1e-12)
    assert np.allclose(data[:, -4:-1], ref.mag_offset, rtol=1e-9, atol=1e-9)
    assert np.allclose(data[:, -1], ref.mag_delay, rtol=1e-9, atol=1e-12)
    assert np.abs(np.degrees(data[-1, -7:-4] - truth_gyr)).max() < 0.1
    assert np.abs(data[-1, -4:-1] - truth_mag).max() < 0.5
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--offsets", "--gyro-offset", "off",
                 "--heading", "gyro"]) == 0
    header, data = _read_output(out)
    assert header == [*OUTPUT_COLUMNS, *offsets[:3]] and not data[:, -3:].any()


def test_estimate_without_t_column_needs_fs_and_honours_units(tmp_path, imu):
    gyr, acc = imu
    ref = estimate(gyr, acc, FS, "first_order", gyro_offset=True)
    out = tmp_path / "out.csv"
    for gyr_unit, acc_unit, scale in (("deg/s", "g", 1.0), ("mdeg/s", "mg", 1e3)):
        _write_csv(tmp_path / "in.csv", _imu_columns(np.degrees(gyr) * scale, acc / 9.80665 * scale, with_t=False))
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out)]) == 2
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(out), "--fs", "100",
                     "--gyr-unit", gyr_unit, "--acc-unit", acc_unit, "--method", "first_order"]) == 0
        assert np.abs(_read_output(out)[1][:, 1:5] - ref.quat).max() < 1e-8, gyr_unit


def test_values_no_unit_explains_are_noted_and_estimated_as_read(tmp_path, imu, capsys):
    """A sensor shaken far harder than a person moves (median accelerometer norm 11 g), which
    no other unit would make plausible, is noted and estimated as the batch path does (a
    unit mistake is refused: test_bad_input_ends_with_a_message_and_exit_2). A gyro scaled
    to reach 66 rad/s (3800 °/s) is within the widest MEMS range and read without a note."""
    gyr, acc = imu
    for scaled_gyr, scaled_acc, note in (
        (gyr, acc * 10.0, "note: in: median accelerometer norm is 110 m/s² read as m/s2, far from gravity, and no "
                          "other unit (m/s2, g, mg) explains it; read as it is"),
        (gyr * (math.radians(3800.0) / np.abs(gyr).max()), acc, None),
    ):
        _write_csv(tmp_path / "in.csv", _imu_columns(scaled_gyr, scaled_acc))
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv")]) == 0
        err = capsys.readouterr().err
        assert (note in err) if note else ("note:" not in err), err
        expected = estimate(scaled_gyr, scaled_acc, FS, gyro_offset=True).quat
        assert np.abs(_read_output(tmp_path / "out.csv")[1][:, 1:5] - expected).max() < 1e-8


def test_estimate_takes_the_magnetometer_unit_and_notes_a_norm_far_from_the_earths(tmp_path, imu, capsys):
    """--mag-unit G converts to µT: the estimate and the reported hard-iron offset are those
    of the field in µT. Without it the field in G (norm 0.5) is noted as far from the
    earth's (49.2 µT read as 0.492); the heading, which uses directions and relative norms
    only, is the same."""
    gyr, acc = imu
    field = HumanMotion(delta_v=0.1, omega_c=5.0).generate(30.0, FS, seed=11).mag  # the imu fixture's motion
    outputs, notes = [], []
    for unit, scale in (("uT", 1.0), ("G", 0.01), (None, 0.01)):
        _write_csv(tmp_path / "in.csv", {**_imu_columns(gyr, acc), **{f"mag_{a}": scale * field[:, i]
                                                                      for i, a in enumerate("xyz")}})
        flags = ["--mag-unit", unit] if unit else []
        assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv"), *flags]) == 0
        outputs.append(_read_output(tmp_path / "out.csv")[1])
        err = capsys.readouterr().err
        notes.append("note: in: the magnetometer's median norm is 0.492 µT" in err and "--mag-unit" in err)
    assert notes == [False, False, True]
    assert np.abs(outputs[1] - outputs[0]).max() < 1e-9 and np.abs(outputs[2] - outputs[0]).max() < 1e-9
    assert np.abs(outputs[0][:, 1:5] - estimate(gyr, acc, FS, gyro_offset=True, mag=field).quat).max() < 1e-9


def test_the_share_of_magnetometer_samples_used_counts_the_samples_there_are(tmp_path, imu, capsys):
    """A magnetometer at a quarter of the rate (NaN in between) on an undisturbed field: every
    one of its samples is used, not 25 % of the rows; on time, its delay is estimated under
    half a gyro sample (4.8 ms here; none over five other realisations of the motion)."""
    gyr, acc = imu
    field = HumanMotion(delta_v=0.1, omega_c=5.0).generate(30.0, FS, seed=11).mag  # the imu fixture's motion
    field[np.arange(len(field)) % 4 != 0] = np.nan
    _write_csv(tmp_path / "in.csv", {**_imu_columns(gyr, acc), **{f"mag_{a}": field[:, i] for i, a in enumerate("xyz")}})
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv")]) == 0
    err = capsys.readouterr().err
    assert "magnetometer samples used for heading 100 %" in err
    delay = re.search(r"its delay behind the gyro ([0-9.]+) ms \(estimated online", err)
    assert "no delay behind the gyro that the recording shows" in err or float(delay.group(1)) < 0.5e3 / FS
    late = np.vstack([field[:2], field[:-2]])  # 20 ms late, given
    _write_csv(tmp_path / "late.csv", {**_imu_columns(gyr, acc), **{f"mag_{a}": late[:, i] for i, a in enumerate("xyz")}})
    assert main(["estimate", str(tmp_path / "late.csv"), "--out", str(tmp_path / "out.csv"),
                 "--param", "mag_delay=0.02"]) == 0
    assert "its delay behind the gyro 20.0 ms (given)" in capsys.readouterr().err


def test_estimate_reads_a_broad_mat_recording(tmp_path, imu, capsys):
    gyr, acc = imu
    mag = np.tile([0.0, 20.0, -45.0], (len(gyr), 1))
    savemat(tmp_path / "rec.mat", {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": mag,
                                   "sampling_rate": FS, "movement": np.ones(len(gyr))})
    for heading, ref_mag in (("mag", mag), ("gyro", None)):
        out = tmp_path / f"out_{heading}.csv"
        assert main(["estimate", str(tmp_path / "rec.mat"), "--out", str(out), "--heading", heading]) == 0
        ref = estimate(gyr, acc, FS, gyro_offset=True, mag=ref_mag)
        assert np.abs(_read_output(out)[1][:, 1:5] - ref.quat).max() < 1e-9
        # the summary names the offset estimates, the hard iron only with the magnetometer
        err = capsys.readouterr().err
        b = np.degrees(ref.offset[-1])
        assert f"gyro offset estimate at the end ({b[0]:.3f}, {b[1]:.3f}, {b[2]:.3f}) °/s" in err
        assert ("hard-iron offset at the end (0.0, 0.0, 0.0) µT" in err) == (heading == "mag")


def _bad_inputs(tmp_path, gyr, acc):
    cols = _imu_columns(gyr, acc)
    cases = {}
    missing = dict(cols)
    del missing["acc_z"]
    cases["missing columns acc_z"] = (missing, [])
    nan = {k: v.copy() for k, v in cols.items()}
    nan["gyr_y"][0] = np.nan
    cases["values that are not finite in the first row"] = (nan, [])
    cases["looks like deg/s: pass --gyr-unit deg/s"] = ({**cols, **{f"gyr_{a}": np.degrees(cols[f"gyr_{a}"]) * 10 for a in "xyz"}}, [])
    cases["looks like g: pass --acc-unit g"] = ({**cols, **{f"acc_{a}": cols[f"acc_{a}"] / 9.81 for a in "xyz"}}, [])
    cases["looks like mg: pass --acc-unit mg"] = ({**cols, **{f"acc_{a}": cols[f"acc_{a}"] * 102 for a in "xyz"}}, [])
    mdeg = {**cols, **{f"gyr_{a}": np.degrees(cols[f"gyr_{a}"]) * 1e3 for a in "xyz"}}
    cases["read as deg/s, beyond any MEMS gyro; looks like mdeg/s: pass --gyr-unit mdeg/s"] = (
        mdeg, ["--gyr-unit", "deg/s"])
    jitter = dict(cols, t=cols["t"] * (1 + 0.2 * (np.arange(len(gyr)) % 2) / len(gyr)) + (np.arange(len(gyr)) % 3) * 0.004)
    cases["column t is irregular"] = (jitter, [])
    cases["unknown parameter"] = (cols, ["--param", "delta_q=1"])
    cases["unknown parameter 'mag_norm_tol'"] = (cols, ["--param", "mag_norm_tol=0.2"])  # no magnetometer
    cases["finite positive"] = (cols, ["--param", "delta_n=-1"])
    cases["disagrees"] = (cols, ["--fs", "50"])
    return cases


def test_bad_input_ends_with_a_message_and_exit_2(tmp_path, imu, capsys):
    for expected, (cols, extra) in _bad_inputs(tmp_path, *imu).items():
        path = tmp_path / "bad.csv"
        _write_csv(path, cols)
        assert main(["estimate", str(path), "--out", str(tmp_path / "o.csv"), *extra]) == 2, expected
        err = capsys.readouterr().err
        assert "attitude: error:" in err and expected in err and "Traceback" not in err, (expected, err)
    (tmp_path / "broken.mat").write_bytes(b"MATLAB 5.0 MAT-file, truncated")
    for path in (tmp_path / "broken.mat", tmp_path / "absent.csv"):
        assert main(["estimate", str(path), "--out", str(tmp_path / "o.csv")]) == 2
        assert "attitude: error:" in capsys.readouterr().err
    # an output folder that does not exist is refused before the input is read
    _write_csv(tmp_path / "good.csv", _imu_columns(*imu))
    for command in (["estimate", str(tmp_path / "good.csv")], ["plot", str(tmp_path / "good.csv"), "--method", "wiener"]):
        assert main([*command, "--out", str(tmp_path / "absent" / "o.csv")]) == 2
        err = capsys.readouterr().err
        assert f"there is no folder {tmp_path / 'absent'}" in err and "attitude: read" not in err, err
    # an output that is the input (by another path) is refused, the recording kept
    before = (tmp_path / "good.csv").read_bytes()
    (tmp_path / "sub").mkdir()
    for command in (["estimate", str(tmp_path / "good.csv")], ["plot", str(tmp_path / "good.csv"), "--method", "wiener"]):
        assert main([*command, "--out", str(tmp_path / "sub" / ".." / "good.csv")]) == 2
        assert "it is the input; choose another --out" in capsys.readouterr().err
    assert (tmp_path / "good.csv").read_bytes() == before
    # a figure written to a folder, or in a format matplotlib does not write
    for command, out, message in ((["plot", "--method", "wiener"], tmp_path / "sub", "it is a folder"),
                                  (["plot", "--method", "wiener"], tmp_path / "p.txt", "ends in one of")):
        assert main([command[0], str(tmp_path / "good.csv"), *command[1:], "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert message in err and "attitude: read" not in err, err
    assert main(["bode", "--out", str(tmp_path / "b.txt")]) == 2
    assert ".png" in capsys.readouterr().err and not (tmp_path / "b.txt").exists()


def test_several_inputs_each_give_their_own_output_and_one_that_fails_stops_none(tmp_path, imu, capsys):
    gyr, acc = imu
    (tmp_path / "in").mkdir()
    _write_csv(tmp_path / "in" / "left.csv", _imu_columns(gyr, acc))
    _write_csv(tmp_path / "in" / "right.csv", _imu_columns(gyr[::-1].copy(), acc[::-1].copy()))
    _write_csv(tmp_path / "in" / "broken.csv", {"t": np.arange(3.0), "gyr_x": np.zeros(3)})
    inputs = [str(tmp_path / "in" / f"{name}.csv") for name in ("left", "broken", "right")]
    assert main(["estimate", *inputs, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "[2/3] error:" in err and "missing columns" in err and "1 of 3 inputs failed" in err, err
    for name, (g, a) in (("left", (gyr, acc)), ("right", (gyr[::-1], acc[::-1]))):
        ref = estimate(g, a, FS, gyro_offset=True)
        assert np.abs(_read_output(tmp_path / "out" / f"{name}.csv")[1][:, 1:5] - ref.quat).max() < 1e-9
    assert not (tmp_path / "out" / "broken.csv").exists()
    (tmp_path / "in" / "broken.csv").rename(tmp_path / "in" / "broken2.csv")
    _write_csv(tmp_path / "in" / "broken.csv", {"t": np.arange(3.0), "gyr_x": np.zeros(3)})
    assert main(["estimate", inputs[1], str(tmp_path / "in" / "broken2.csv"), "--out", str(tmp_path / "none")]) == 2
    err = capsys.readouterr().err
    assert "2 of 2 inputs failed" in err and "none was written" in err, err
    # one input into a folder that exists
    assert main(["estimate", inputs[0], "--out", str(tmp_path / "in")]) == 2  # would overwrite the input
    assert "it is an input" in capsys.readouterr().err
    (tmp_path / "one").mkdir()
    assert main(["estimate", inputs[0], "--out", str(tmp_path / "one")]) == 0
    assert (tmp_path / "one" / "left.csv").exists()
    # refused before any work: two inputs of one name, a file where the folder should be
    for out, extra, message in ((tmp_path / "o2", [str(tmp_path / "one" / "left.csv")], "share the names left"),
                                (tmp_path / "in" / "left.csv", [inputs[2]], "is a file")):
        assert main(["estimate", inputs[0], *extra, "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert message in err and "attitude: [1/2] read" not in err, err
    assert not (tmp_path / "o2").exists()


def test_options_are_refused_before_any_input_is_read(tmp_path, capsys):
    """Inputs that do not exist: the error must name the option, so nothing was read."""
    absent = [str(tmp_path / "a.csv"), str(tmp_path / "b.csv")]
    cases = ((["--method", "luinge", "--offline"], "offline smoothing needs an earth-frame filter method"),
             (["--param", "delta_q=1"], "unknown parameter 'delta_q'"),
             (["--param", "stationary=2"], "stationary must be 0 or 1"),
             (["--param", "rest_time=0"], "rest_time must be a finite positive number"),
             (["--param", "tau_heading=-1"], "tau_heading must be a finite positive number"),
             (["--latency", "1"], "argument --latency: 1 is outside the plausible [-0.5, 0.5] s"))
    for options, message in cases:
        for command in (["estimate", *absent, "--out", str(tmp_path / "out")],
                        ["evaluate", *absent],
                        ["plot", absent[0], "--out", str(tmp_path / "p.png")]):
            if command[0] == "plot" and "--method" not in options:
                command += ["--method", "wiener"]
            try:
                status = main([*command, *options])
            except SystemExit as refused:  # a flag's range, checked as the command line is parsed
                status = refused.code
            assert status == 2, (command, options)
            err = capsys.readouterr().err
            assert message in err and "a.csv" not in err, (command, options, err)
    assert not (tmp_path / "out").exists()


def test_console_entry_point_reports_errors_without_traceback(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "attitude_fmu.systems.cli.commands", "estimate", str(tmp_path / "none.csv"),
                           "--out", str(tmp_path / "o.csv")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "no such file" in proc.stderr and "Traceback" not in proc.stderr


@pytest.mark.slow  # the whole of Table 1 simulated (its first row: tests/test_paper.py)
def test_table1_json_every_cell_within_7_percent(capsys):
    assert main(["table1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [(r["delta_n_deg"], r["delta_v"]) for r in rows] == [(0.1, 1.0), (0.1, 2.0), (0.2, 1.0), (0.2, 2.0)]
    for row in rows:
        assert set(row) == {"delta_n_deg", "delta_v", "inv_omega_g_s", "cells"}
        assert [c["a"] for c in row["cells"]] == [1.0, 0.5, 2.0]
        for cell in row["cells"]:
            assert cell["simulated_deg"] == pytest.approx(cell["analytic_deg"], rel=0.07)


def test_bench_json_reports_rates_and_ratios(capsys):
    assert main(["bench", "--json", "--samples", "2000", "--repeat", "1"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result["samples_per_s"]) == {"wiener", "wiener_held", "wiener_stationary", "wiener_offset", "wiener_9d",
                                            "vqf", "vqf_9d", "madgwick"}
    assert result["ratio_vs_vqf"]["vqf"] == pytest.approx(1.0)
    assert result["ratio_vs_vqf_9d"]["vqf_9d"] == pytest.approx(1.0)
    assert all(rate > 0 for rate in result["samples_per_s"].values())


@pytest.mark.parametrize("method", sorted(METHODS))
def test_estimate_runs_every_method_as_the_batch_path_does(tmp_path, imu, method):
    gyr, acc = imu
    _write_csv(tmp_path / "in.csv", _imu_columns(gyr, acc))
    assert main(["estimate", str(tmp_path / "in.csv"), "--out", str(tmp_path / "out.csv"), "--method", method]) == 0
    ref = estimate(gyr, acc, FS, method, gyro_offset=True)
    assert np.abs(_read_output(tmp_path / "out.csv")[1][:, 1:5] - ref.quat).max() < 1e-9


def test_estimate_help_lists_every_stage_with_its_parameters(capsys):
    with pytest.raises(SystemExit):
        main(["estimate", "--help"])
    text = capsys.readouterr().out
    for title, line in (("wiener:", "scale_error [1] (default 0.005)"),
                        ("the gyro-offset estimator (--gyro-offset on):", "rest_time [s] (default 1.5)"),
                        ("the heading estimator (--heading mag and a magnetometer):", "mag_cal_recent [s] (default 2)")):
        assert title in text and f"    {line}: " in text.split(title, 1)[1]
