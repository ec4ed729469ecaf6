"""Recordings and options a demanding user gives: each ends in a clear message (exit 2) or a
graceful estimate with a note, finite, the input unchanged; and a property-based test that
generates malformed and extreme CSVs and .mat files for every command that reads them."""
import hashlib
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.io import savemat
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import inclination_error
from attitude_fmu.blocks.methods.registry import METHODS
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.pipeline.causal import ESTIMATORS
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.simulation.motion import HumanMotion
from attitude_fmu.systems.simulation.sensor_model import ImuModel

FS = 100.0
HEADER = "t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z"


@pytest.fixture(scope="module")
def recording():
    """60 s of human motion (long enough for the axes and unit checks): gyr, acc, mag, true up, quat."""
    motion = HumanMotion(delta_v=0.1, omega_c=5.0).generate(60.0, FS, seed=31)
    imu = ImuModel(delta_n=math.radians(0.05), mag_noise=0.2)
    gyr, acc = imu.apply(motion, seed=32)
    up = Rotation.from_quat(motion.quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    return gyr, acc, imu.apply_mag(motion, seed=33), up, motion.quat


def _write(path, gyr, acc, mag=None, quat=None):
    columns, names = [np.arange(1, len(gyr) + 1) / FS, gyr, acc], HEADER
    if mag is not None:
        columns, names = columns + [mag], names + ",mag_x,mag_y,mag_z"
    if quat is not None:
        columns, names = columns + [quat], names + ",ref_q_w,ref_q_x,ref_q_y,ref_q_z"
    np.savetxt(path, np.column_stack(columns), delimiter=",", header=names, comments="", fmt="%.17g")


def _digest(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def _run(tmp_path, capsys, gyr, acc, *options, mag=None):
    """attitude estimate on a CSV of gyr, acc (and mag): (exit, stderr, output rows or None);
    the input's bytes are checked unchanged."""
    source = tmp_path / "in.csv"
    _write(source, gyr, acc, mag)
    before = _digest(source)
    out = tmp_path / "out.csv"
    out.unlink(missing_ok=True)
    code = main(["estimate", str(source), "--out", str(out), *options])
    err = capsys.readouterr().err
    assert _digest(source) == before and "Traceback" not in err
    return code, err, np.loadtxt(out, delimiter=",", skiprows=1) if code == 0 else None


def _rms_deg(rows, up) -> float:
    return math.degrees(float(np.sqrt(np.mean(inclination_error(rows[:, 5:8], up) ** 2))))


@pytest.mark.parametrize("sensor, row, axis, value", [
    ("gyr", 3000, 1, 1e160), ("gyr", 3000, 0, -1e155), ("acc", 3000, 0, 1e4), ("acc", 3000, 2, 1e6),
    ("gyr", 3000, 1, 100.0),  # a single spike of 100 rad/s: not a unit mistake
])
def test_a_sample_beyond_every_sensors_range_is_an_invalid_sample(tmp_path, capsys, recording, sensor, row, axis,
                                                                  value):
    """Interpolated as a missing sample is and noted: the estimate is that of the
    recording with the sample interpolated (its inclination RMS within 0.05° of the
    clean recording's), finite, without a unit hint."""
    gyr, acc, _, up, _ = recording
    bad = {"gyr": gyr.copy(), "acc": acc.copy()}
    bad[sensor][row, axis] = value
    code, err, rows = _run(tmp_path, capsys, bad["gyr"], bad["acc"])
    assert code == 0 and np.isfinite(rows).all()
    assert "1 rows with gyro or accelerometer values that are beyond every IMU's range" in err, err
    assert "--gyr-unit" not in err and "--acc-unit" not in err
    clean = estimate(gyr, acc, FS)
    assert abs(_rms_deg(rows, up) - _rms_deg(np.hstack([rows[:, :5], clean.up]), up)) < 0.05


def test_an_accelerometer_without_gravity_is_refused_and_waited_out_at_the_start(tmp_path, capsys, recording):
    """All zero: refused (no "down" to start on). Zero for the first 2 s: the estimate
    starts on the first sample with gravity, as on the recording cut there, and holds
    that start over the rows before."""
    gyr, acc, _, up, _ = recording
    code, err, _ = _run(tmp_path, capsys, gyr, np.zeros_like(acc))
    assert code == 2 and "the accelerometer shows no gravity (median norm 0 m/s²" in err, err
    late = acc.copy()
    late[:200] = 0.0
    code, err, rows = _run(tmp_path, capsys, gyr, late)
    assert code == 0 and np.isfinite(rows).all()
    assert "no gravity (norm below 1 m/s²) in the first 200 samples (2 s): the estimate waits for sample 201" in err
    cut = estimate(gyr[200:], acc[200:], FS)
    assert np.abs(rows[200:, 1:5] - cut.quat).max() < 1e-9 and np.abs(rows[:200, 1:5] - cut.quat[0]).max() < 1e-9


@pytest.mark.parametrize("truth, given, mag", [("rad/s", "deg/s", False), ("rad/s", "deg/s", True),
                                               ("deg/s", "mdeg/s", False)])
def test_a_gyro_read_in_the_wrong_unit_is_noted_with_the_flag(tmp_path, capsys, recording, truth, given, mag):
    """The accelerometer (and magnetometer) turn 57.3 or 1000 times as much as the gyro
    says: the note names --gyr-unit with the unit that fits; the estimate goes on."""
    from attitude_fmu.systems.recordings.recording import GYR_UNITS

    gyr, acc, field, _, _ = recording
    code, err, rows = _run(tmp_path, capsys, gyr / GYR_UNITS[truth], acc, "--gyr-unit", given,
                           mag=field if mag else None)
    factor = GYR_UNITS[truth] / GYR_UNITS[given]
    assert code == 0 and np.isfinite(rows).all()
    assert f"turn{'' if mag else 's'} {factor:.4g} times more than the gyro read in {given} says" in err, err
    assert f"pass --gyr-unit {truth}" in err
    code, err, _ = _run(tmp_path, capsys, gyr / GYR_UNITS[truth], acc, "--gyr-unit", truth)
    assert code == 0 and "--gyr-unit" not in err  # read right: nothing said


def test_every_parameter_has_a_plausible_range_checked_before_work(tmp_path, capsys):
    """Every parameter of every method and stage documents low ≤ default ≤ high (finite);
    values beyond either end, and 1e300, are refused with exit 2 naming the range, before
    the (absent) input is read."""
    params = {p.name: p for ps in (*(m.params for m in METHODS.values()), *ESTIMATORS.values()) for p in ps}
    for p in params.values():
        assert math.isfinite(p.high) and 0 <= p.low < p.high, p
        assert p.default is None or p.low <= p.default <= p.high, p
        assert (p.low == 0) == p.allow_zero or p.low > 0, p
    for name, p in params.items():
        method = next((m for m in METHODS if any(q.name == name for q in METHODS[m].params)), "wiener")
        for value in (p.high * 10 + 1, 1e300):
            code = main(["estimate", str(tmp_path / "absent.csv"), "--out", str(tmp_path / "o.csv"),
                         "--method", method, "--param", f"{name}={value}"])
            err = capsys.readouterr().err
            assert code == 2 and f"parameter {name}" in err and "absent.csv" not in err, (name, err)
            assert "plausible range" in err or "must be" in err, err


def test_mahonys_gains_unstable_at_the_sample_rate_are_refused_with_the_bound(tmp_path, capsys, recording):
    """k_P·Ts ≥ 2 or k_I·Ts² ≥ 4 − 2·k_P·Ts: the command line refuses them naming the bound
    (the rule itself against the eigenvalues of the linearised step: tests/test_refusals.py)."""
    gyr, acc, _, _, _ = recording
    for method in ("mahony", "tseng_adaptive"):
        code, err, _ = _run(tmp_path, capsys, gyr[:500], acc[:500], "--method", method, "--param", "k_P=1000")
        assert code == 2 and "k_P = 1000 1/s is unstable at the sample time 0.01 s" in err and "k_P < 200" in err
    code, err, rows = _run(tmp_path, capsys, gyr[:500], acc[:500], "--method", "mahony", "--param", "k_P=150")
    assert code == 0 and np.isfinite(rows).all()


def test_evaluate_notes_a_reference_stored_scalar_last(tmp_path, capsys, recording):
    gyr, acc, _, _, quat = recording
    _write(tmp_path / "rec.csv", gyr, acc, quat=np.roll(quat, -1, axis=1))  # x,y,z,w under the w,x,y,z names
    assert main(["evaluate", str(tmp_path / "rec.csv"), "--json"]) == 0
    err = capsys.readouterr().err
    assert "rec: the reference fits the estimate far better read as stored x,y,z,w (scalar last)" in err, err
    _write(tmp_path / "rec.csv", gyr, acc, quat=quat)
    assert main(["evaluate", str(tmp_path / "rec.csv"), "--json"]) == 0
    assert "fits the estimate far better" not in capsys.readouterr().err


def test_read_errors_name_the_file_and_say_what_was_expected(tmp_path, capsys, recording):
    gyr, acc, _, _, _ = recording
    rng = np.random.default_rng(5)
    (tmp_path / "noise.csv").write_bytes(rng.integers(0, 256, 3000, dtype=np.uint8).tobytes())
    savemat(tmp_path / "rec.mat", {"imu_gyr": gyr[:5000], "imu_acc": acc[:5714], "sampling_rate": FS})
    (tmp_path / "named.csv").write_bytes((tmp_path / "rec.mat").read_bytes())
    for name, message in (("noise.csv", "noise.csv: not a text CSV"),
                          ("named.csv", "named.csv: not a text CSV (byte 0x"),
                          ("rec.mat", "rec.mat: imu_acc has 5714 samples, imu_gyr 5000: expected one accelerometer "
                                      "sample per gyro sample")):
        before = _digest(tmp_path / name)
        assert main(["estimate", str(tmp_path / name), "--out", str(tmp_path / "o.csv")]) == 2
        err = capsys.readouterr().err
        assert message in err and "expected" in err, err
        assert _digest(tmp_path / name) == before
    assert main(["estimate", str(tmp_path / "named.csv"), "--out", str(tmp_path / "o.csv")]) == 2
    assert "it looks like a MATLAB file: name it .mat" in capsys.readouterr().err


# the property-based test: malformed and extreme recordings for every command that reads one

EXTREMES = [0.0, -0.0, 1e4, -1e6, 1e155, -1e300, math.nan, math.inf, -math.inf, 5e-324, 1e-300, 69.0, 4000.0]
CELL = st.tuples(st.integers(0, 119), st.integers(0, 6), st.sampled_from(EXTREMES) | st.floats(allow_nan=True))
TEXT_EDITS = st.sampled_from(["none", "semicolons", "bom", "truncate_line", "garbage_line", "header_only", "empty",
                              "bytes", "drop_column", "repeat_t", "reverse_t", "units_row", "comment_line",
                              "decimal_commas"])


def _csv_text(rows: np.ndarray, edit: str, data) -> bytes:
    lines = [HEADER] + [",".join(repr(float(v)) for v in row) for row in rows]
    if edit == "semicolons":
        lines = [line.replace(",", ";") for line in lines]
    elif edit == "decimal_commas":
        lines = [line.replace(",", ";").replace(".", ",") for line in lines]
    elif edit == "truncate_line":
        k = data.draw(st.integers(1, len(lines) - 1))
        lines[k] = lines[k][: data.draw(st.integers(0, len(lines[k])))]
    elif edit == "garbage_line":
        lines.insert(data.draw(st.integers(1, len(lines))), data.draw(st.text(max_size=30)).replace("\n", " "))
    elif edit == "header_only":
        lines = lines[:1]
    elif edit == "drop_column":
        k = data.draw(st.integers(0, 6))
        lines = [",".join(f for i, f in enumerate(line.split(",")) if i != k) for line in lines]
    elif edit == "units_row":
        lines.insert(1, "s,rad/s,rad/s,rad/s,m/s2,m/s2,m/s2")
    elif edit == "comment_line":
        lines.insert(data.draw(st.integers(1, len(lines))), "# a comment")
    text = "\n".join(lines) + "\n"
    if edit == "empty":
        return b""
    if edit == "bytes":
        return data.draw(st.binary(max_size=400))
    return (("\ufeff" if edit == "bom" else "") + text).encode("utf-8", "surrogatepass")


MAT_EDITS = st.sampled_from(["none", "transposed", "short_acc", "no_rate", "rate_zero", "rate_nan", "text_gyr",
                             "empty", "mag_short", "quat_bad"])


def _mat(path, gyr, acc, edit: str) -> None:
    content = {"imu_gyr": gyr, "imu_acc": acc, "sampling_rate": FS}
    if edit == "transposed":
        content["imu_gyr"] = gyr.T
    elif edit == "short_acc":
        content["imu_acc"] = acc[:-7]
    elif edit == "no_rate":
        del content["sampling_rate"]
    elif edit in ("rate_zero", "rate_nan"):
        content["sampling_rate"] = 0.0 if edit == "rate_zero" else math.nan
    elif edit == "text_gyr":
        content["imu_gyr"] = "not numbers"
    elif edit == "empty":
        content["imu_gyr"], content["imu_acc"] = np.zeros((0, 3)), np.zeros((0, 3))
    elif edit == "mag_short":
        content["imu_mag"] = np.ones((5, 3))
    elif edit == "quat_bad":
        content["opt_quat"] = np.tile([2.0, 0.0, 0.0, 0.0], (len(gyr), 1))
    savemat(path, content)


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(data=st.data())
def test_malformed_and_extreme_recordings_end_in_exit_0_with_finite_output_or_exit_2_naming_the_file(
        tmp_path, capsys, recording, data):
    """Every command that reads a recording (estimate, evaluate, plot) on a CSV or .mat
    with extreme cells and malformed text: exit 0 with finite output, or exit 2 with a
    message naming the file; never a traceback (main raises nothing else), the input
    unchanged."""
    gyr, acc, _, _, _ = recording
    rows = np.column_stack([np.arange(1, 121) / FS, gyr[:120], acc[:120]])
    for row, column, value in data.draw(st.lists(CELL, max_size=6)):
        rows[row, column] = value
    if data.draw(st.booleans()):
        path = tmp_path / "rec.mat"
        _mat(path, rows[:, 1:4], rows[:, 4:7], data.draw(MAT_EDITS))
    else:
        path = tmp_path / "rec.csv"
        path.write_bytes(_csv_text(rows, data.draw(TEXT_EDITS), data))
    before = _digest(path)
    command = data.draw(st.sampled_from(["estimate", "evaluate", "plot"]))
    out = tmp_path / ("out.png" if command == "plot" else "out.csv")
    out.unlink(missing_ok=True)
    capsys.readouterr()
    code = main([command, str(path), *([] if command == "evaluate" else ["--out", str(out)])])
    err = capsys.readouterr().err
    assert _digest(path) == before
    assert code in (0, 2), err
    if code == 2:
        assert "attitude: error:" in err and ("rec" in err.split("attitude: error:")[1]), err
    elif command == "estimate":
        assert np.isfinite(np.loadtxt(out, delimiter=",", skiprows=1)).all()
    elif command == "plot":
        assert out.stat().st_size > 0
