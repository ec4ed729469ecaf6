"""`attitude simulate` and systems.simulation.recording: a recording at any rate from a sensor
of a datasheet's figures, against independent truth (scipy's rotations of the reference, the
noise densities' per-sample s.d., the same seed without a range, the reader)."""
import json
import math
import re
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import G_N
from attitude_fmu.systems.recordings.writing import CSV_DIGITS, write_recording
from attitude_fmu.systems.simulation.motion import profile
from attitude_fmu.systems.simulation.profile_table import EARTH_FIELD_UT
from attitude_fmu.systems.simulation.recording import DEFAULT_MOTION, SENSORS, Sensor, simulate_recording
from attitude_fmu.systems.simulation.scenarios import SCENARIOS

IDEAL = Sensor(gyro_noise_dps=0.0, acc_noise=0.0, mag_noise=0.0)  # no noise, scale error, offset nor range
GRAVITY = np.array([0.0, 0.0, STANDARD_GRAVITY])  # the simulation's specific force at rest, level, m/s²
SIGNALS = ("gyr", "acc", "mag", "quat_ref")


def _earth(rec) -> np.ndarray:
    """The accelerometer turned into the earth frame by the reference (N×3, m/s²)."""
    return Rotation.from_quat(rec.quat_ref, scalar_first=True).apply(rec.acc)


@pytest.mark.parametrize("suffix", ["csv", "parquet"])
def test_a_recording_written_reads_back_as_made(tmp_path, suffix):
    """A CSV keeps every value within half a unit of its 10th significant digit (relative
    5e-10, plus the rounding to the nearest double) and t to the bit; Parquet every bit. The
    reader takes the file as it is: no note."""
    rec = simulate_recording(100.0, 20.0, 2.0, seed=1)
    path = tmp_path / f"r.{suffix}"
    write_recording(path, rec)
    back = read_recording(path)
    assert back.fs == pytest.approx(rec.fs, rel=1e-12) and back.notes == []
    assert np.array_equal(back.t, rec.t) and np.array_equal(back.movement, rec.movement)
    for name in SIGNALS:
        made, read = getattr(rec, name), getattr(back, name)
        if suffix == "parquet":
            assert np.array_equal(read, made), name
        else:
            assert np.all(np.abs(read - made) <= (0.5 * 10.0 ** (1 - CSV_DIGITS) + 2.0**-52) * np.abs(made)), name


def test_an_ideal_sensor_measures_the_references_motion():
    """No noise, scale error, offset or range: the gyro is the mean rate over each sample
    time, the rotation vector of q[k−1]⁻¹·q[k] times fs (level before the first sample), and
    the magnetometer the earth's field turned into the sensor. Over the rest the reference is
    the identity, the accelerometer reads g up and the movement flag is 0, 1 after it. Turned
    into the earth frame the accelerometer is the mean acceleration over each sample time plus
    g up, so over the T s of motion its mean is g up plus v(T)/T: the velocity, first-order
    low-passed white noise of density δv and band ω_c starting at 0, has an s.d. of at most
    δv·√(ω_c/4) (its stationary one), so the mean lies within 5·δv·√(ω_c/4)/T of g up."""
    fs, rest, duration = 200.0, 5.0, 30.0
    rec = simulate_recording(fs, duration, rest, IDEAL, seed=4)
    still = round(rest * fs)
    turn = Rotation.from_quat(rec.quat_ref, scalar_first=True)
    before = Rotation.concatenate([Rotation.identity(), turn[:-1]])
    assert np.abs(rec.gyr - (before.inv() * turn).as_rotvec() * fs).max() < 1e-9
    assert np.abs(rec.mag - turn.inv().apply(EARTH_FIELD_UT)).max() < 1e-9
    assert np.array_equal(rec.quat_ref[:still], np.tile([1.0, 0.0, 0.0, 0.0], (still, 1)))
    assert np.abs(rec.acc[:still] - GRAVITY).max() < 1e-12
    assert np.array_equal(rec.movement, np.arange(len(rec.t)) >= still)
    motion = profile("human").motion(DEFAULT_MOTION)
    velocity_sd = motion.delta_v * math.sqrt(motion.omega_c / 4.0)
    assert np.abs(_earth(rec)[still:].mean(axis=0) - GRAVITY).max() < 5.0 * velocity_sd / duration


def test_the_sensors_noise_and_offset_at_rest():
    """200 s at rest at 200 Hz (40000 samples): each axis's s.d. is its one-sided density
    times √(fs/2), within 3 % (the s.d.'s own relative s.e. is 1/√(2N) = 0.35 %); the gyro's
    mean is the sensor's offset, of norm gyro_offset_dps, within 4 of its standard errors;
    the accelerometer has no offset."""
    fs, rest, seed = 200.0, 200.0, 5
    sensor = SENSORS["consumer"]
    rec = simulate_recording(fs, 1.0, rest, sensor, seed=seed)
    still = round(rest * fs)
    gyr, acc, mag = rec.gyr[:still], rec.acc[:still], rec.mag[:still]
    per_sample = math.sqrt(fs / 2.0)
    for values, density in ((gyr, math.radians(sensor.gyro_noise_dps)), (acc, sensor.acc_noise),
                            (mag, sensor.mag_noise)):
        assert np.allclose(values.std(axis=0), density * per_sample, rtol=0.03, atol=0.0)
    gyr_se, acc_se = gyr.std(axis=0) / math.sqrt(still), acc.std(axis=0) / math.sqrt(still)
    offset = gyr.mean(axis=0)
    assert abs(np.linalg.norm(offset) - math.radians(sensor.gyro_offset_dps)) < 4.0 * gyr_se.max()
    assert np.all(np.abs(offset - sensor.model(seed).gyr_offset) < 4.0 * gyr_se)
    assert np.all(np.abs(acc.mean(axis=0) - GRAVITY) < 4.0 * acc_se)


def test_the_gyros_scale_factor_matrix_is_the_sensors():
    """Without noise the gyro is (I + S)·ω of the same seed's ideal gyro, S the matrix the
    sensor draws, its 9 elements of rms within a factor 2 of gyro_scale_error; the
    accelerometer is untouched."""
    skewed = replace(IDEAL, gyro_scale_error=0.2)
    true = simulate_recording(100.0, 20.0, 1.0, IDEAL, seed=6)
    measured = simulate_recording(100.0, 20.0, 1.0, skewed, seed=6)
    scale = np.array(skewed.model(6).gyr_scale)
    assert 0.1 < np.sqrt(np.mean(scale**2)) < 0.4
    assert np.abs(measured.gyr - true.gyr @ (np.eye(3) + scale).T).max() < 1e-12
    assert np.array_equal(measured.acc, true.acc)


def test_samples_beyond_the_range_read_the_full_scale_and_no_other_changes(tmp_path):
    """Against the same seed without a range: a sample within the range is unchanged, one
    beyond it reads ± the full scale (so none exceeds it); the note counts the rows at full
    scale. Read back, the reader finds each sensor held at that range (checks.saturation_notes)."""
    free = replace(SENSORS["consumer"], gyro_range_dps=math.inf, acc_range_g=math.inf)
    ranged = replace(free, gyro_range_dps=150.0, acc_range_g=1.6)
    clipped = simulate_recording(100.0, 30.0, 2.0, ranged, seed=7, name="x")
    unclipped = simulate_recording(100.0, 30.0, 2.0, free, seed=7, name="x")
    assert unclipped.notes == [] and len(clipped.notes) == 2
    write_recording(tmp_path / "x.parquet", clipped)
    read_notes = " ".join(read_recording(tmp_path / "x.parquet").notes)
    for what, name, full, unit in (("gyro", "gyr", math.radians(150.0), "rad/s"),
                                   ("accelerometer", "acc", 1.6 * G_N, "m/s²")):
        values, truth = getattr(clipped, name), getattr(unclipped, name)
        inside = np.abs(truth) <= full
        assert np.array_equal(values[inside], truth[inside])
        assert np.array_equal(values[~inside], np.copysign(full, truth[~inside]))
        counted = [int(m[1]) for n in clipped.notes if (m := re.match(rf"x: (\d+) {what} samples beyond", n))]
        assert counted == [np.count_nonzero((np.abs(values) == full).any(axis=1))] and counted[0] > 0
        held = f"the {what} stays at its largest value on [^:]*{re.escape(f'±{full:.4g} {unit}')}"
        assert re.search(held, read_notes), read_notes


def test_the_rate_does_not_change_the_motion():
    """The motion lives on its own grid: at 40 and 1000 Hz the same seed gives the same
    reference at the common times, and the earth-frame accelerometer at 40 Hz (the mean
    acceleration over 25 ms) is the mean of the 25 at 1000 Hz over those 25 ms."""
    slow = simulate_recording(40.0, 20.0, 2.0, IDEAL, seed=8)
    fast = simulate_recording(1000.0, 20.0, 2.0, IDEAL, seed=8)
    step = 25
    assert np.abs(fast.t[step - 1::step] - slow.t).max() < 1e-12
    assert np.abs(fast.quat_ref[step - 1::step] - slow.quat_ref).max() < 1e-9
    assert np.abs(_earth(fast).reshape(-1, step, 3).mean(axis=1) - _earth(slow)).max() < 1e-9


def test_simulate_writes_the_recording_the_library_makes(tmp_path, capsys):
    """The verb's file is simulate_recording's of the flags, bit for bit (Parquet), with its
    saturation notes on standard error (low_range's ±2 g; --gyro-range inf: none for the
    gyro); --no-mag leaves the magnetometer out."""
    out = tmp_path / "r.parquet"
    assert main(["simulate", "--out", str(out), "--fs", "125", "--duration", "20", "--rest", "2", "--sensor",
                 "low_range", "--gyro-noise", "0.01", "--gyro-range", "inf", "--motion", "rot_rms=0.5",
                 "--seed", "3"]) == 0
    err = capsys.readouterr().err
    sensor = replace(SENSORS["low_range"], gyro_noise_dps=0.01, gyro_range_dps=math.inf)
    rec = simulate_recording(125.0, 20.0, 2.0, sensor, {"rot_rms": 0.5}, seed=3, name=out.stem)
    back = read_recording(out)
    assert back.fs == pytest.approx(125.0, rel=1e-12) and np.array_equal(back.movement, rec.movement)
    for name in SIGNALS:
        assert np.array_equal(getattr(back, name), getattr(rec, name)), name
    assert rec.notes and all(f"attitude: note: {note}\n" in err for note in rec.notes) and "gyro samples" not in err
    assert f"attitude: wrote {out}: 2750 samples at 125 Hz" in err
    assert main(["simulate", "--out", str(tmp_path / "r.csv"), "--fs", "125", "--duration", "20", "--no-mag"]) == 0
    back = read_recording(tmp_path / "r.csv")
    assert back.mag is None and back.quat_ref is not None and len(back.t) == 125 * 30
    assert np.count_nonzero(back.movement) == 125 * 20


@pytest.mark.parametrize("flags, message", [
    (["--gyro-noise", "-1"], "argument --gyro-noise: -1 is outside the plausible [0, 1000) °/s/√Hz"),
    (["--gyro-scale-error", "0.6"], "argument --gyro-scale-error: 0.6 is outside the plausible [0, 0.5)"),
    (["--sensor", "phone"], "argument --sensor: invalid choice: 'phone'"),
    (["--acc-range", "0"], "argument --acc-range: 0 is outside the plausible (0, 1e+09] g"),
    (["--motion", "unknown_name=1"], "unknown parameter 'unknown_name' for profile 'human'"),
    (["--out", "absent/r.csv", "--acc-range", "0.5"], "there is no folder"),
    (["--scenario", "phone"], "attitude: error: unknown scenario 'phone'; available: phone_flat, phone_running, "
                              "tactical_handheld, robot_arm, segment_40hz\n"),
    (["--scenario", "robot_arm", "--motion", "rot_rms=1"], "unknown parameter 'rot_rms' for profile 'robot_arm'"),
])
def test_bad_flags_are_refused_naming_them(tmp_path, monkeypatch, capsys, flags, message):
    """Exit status 2 and a message naming the flag, before any work: nothing written, and no
    saturation note (at ±0.5 g every sample would have one)."""
    monkeypatch.chdir(tmp_path)
    try:
        status = main(["simulate", "--out", "r.csv", "--duration", "5", *flags])
    except SystemExit as refused:  # a flag's range, checked as the command line is parsed
        status = refused.code
    err = capsys.readouterr().err
    assert status == 2 and message in err and "note:" not in err, err
    assert not any(tmp_path.iterdir())


def test_simulate_writes_a_scenario_with_the_flags_given_overriding_it(tmp_path, capsys):
    """--scenario phone_flat: the scenario's recording (its rate, rest, sensor and seed) of the
    --duration asked; --fs, --seed and a sensor figure override the scenario's, --motion adds to its motion."""
    out = tmp_path / "x.parquet"
    assert main(["simulate", "--scenario", "phone_flat", "--out", str(out), "--duration", "5"]) == 0
    rec = replace(SCENARIOS["phone_flat"], duration=5.0).recording(out.stem)
    back = read_recording(out)
    assert back.fs == pytest.approx(100.0, rel=1e-12) and len(back.t) == 100 * 15
    for name in SIGNALS:
        assert np.array_equal(getattr(back, name), getattr(rec, name)), name
    assert f"attitude: wrote {out}: 1500 samples at 100 Hz (10 s at rest, then 5 s of motion), scenario phone_flat" \
        in capsys.readouterr().err
    assert main(["simulate", "--scenario", "phone_flat", "--out", str(tmp_path / "x.csv"), "--duration", "5",
                 "--fs", "199", "--seed", "7", "--gyro-noise", "0.02", "--motion", "tilt_deg=10"]) == 0
    s = SCENARIOS["phone_flat"]
    rec = replace(s, duration=5.0, fs=199.0, seed=7, sensor=replace(s.sensor, gyro_noise_dps=0.02)).recording(
        "x", motion={"tilt_deg": 10.0})
    back = read_recording(tmp_path / "x.csv")
    assert len(back.t) == len(rec.t) == 199 * 15
    assert np.abs(back.gyr - rec.gyr).max() < 1e-9 and np.abs(back.quat_ref - rec.quat_ref).max() < 1e-9


def test_evaluate_scores_a_simulated_recording(tmp_path, capsys):
    """`attitude evaluate` takes the file as a lab's recording. The consumer gyro's 0.5 °/s
    offset alone would tilt a gyro-only estimate by up to 30° over the 60 s; an inclination
    RMSE below 3° (below evaluate's REFERENCE_NOTE_DEG, at which it suspects a reference read
    in the wrong order) shows the accelerometer correcting it against a reference read as
    written, and a heading RMSE below 3° with magnetic north that the magnetometer and the
    reference share their north."""
    path = tmp_path / "sim.csv"
    assert main(["simulate", "--out", str(path), "--fs", "125", "--duration", "60"]) == 0
    capsys.readouterr()
    assert main(["evaluate", "--json", "--reference-north", "magnetic", str(path)]) == 0
    scores = json.loads(capsys.readouterr().out)["recordings"]["sim"]
    for method in ("wiener", "vqf"):
        assert 0.0 < scores[method]["inclination_rmse_deg"] < 3.0, scores
    for method in ("wiener", "vqf_9d"):
        assert 0.0 < scores[method]["heading_rmse_deg"] < 3.0, scores


def test_evaluate_reports_the_share_of_field_samples_the_heading_used(tmp_path, capsys):
    """A magnet beside the sensor in spells (the field 60 % stronger for 10 s of every 12.5 s of
    the movement, shorter than mag_new_time, so never taken as a new field): the guard refuses
    those samples, and evaluate reports the share it used as the spells leave it (within the
    low-pass's edges, 0.02) and notes it, being below half; the clean copy uses every sample, unnoted."""
    rec = simulate_recording(100.0, 60.0, rest=10.0, seed=3)
    moving = rec.movement.astype(bool)
    spell = moving & (np.mod(rec.t - rec.t[moving][0], 12.5) < 10.0)
    write_recording(tmp_path / "clean.csv", rec)
    write_recording(tmp_path / "magnet.csv", replace(rec, mag=np.where(spell[:, None], 1.6 * rec.mag, rec.mag)))
    capsys.readouterr()
    assert main(["evaluate", "--json", str(tmp_path / "clean.csv"), str(tmp_path / "magnet.csv")]) == 0
    captured = capsys.readouterr()
    used = json.loads(captured.out)["mag_used"]
    expected = 1.0 - spell[moving].mean()
    print(f"used {used}, clean share of the magnet's movement {expected:.3f}")
    assert used["clean"] > 0.999 and abs(used["magnet"] - expected) < 0.02
    assert (f"magnet: the heading used the magnetometer for {100 * used['magnet']:.0f} % of the movement's field "
            "samples; the disturbance guard refused the rest") in captured.err
    assert "clean: the heading used" not in captured.err
