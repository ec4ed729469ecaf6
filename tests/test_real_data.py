"""Real-recording tools: the offline Wiener smoother, the gyro-offset estimator and
`attitude evaluate` (on small synthetic recordings written here; the BROAD run is a
benchmark, tests/test_broad_benchmark.py, that skips without the files)."""
import json
import math
import shutil
from dataclasses import replace

import numpy as np
import pytest
from scipy import integrate
from scipy.io import loadmat, savemat
from scipy.signal import lfilter
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import inclination_error, quaternion_errors, rms
from attitude_fmu.blocks.filters import accuracy as ac
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.stages import gyro_offset
from attitude_fmu.blocks.stages.gyro_offset import correct as correct_gyro
from attitude_fmu.blocks.stages.heading import with_magnetometer
from attitude_fmu.blocks.stages.scale_error import SCALE_ERRORS
from attitude_fmu.blocks.stages.timing import interval_means
from attitude_fmu.systems.cli.commands import main
from attitude_fmu.systems.evaluation import experiments as ex
from attitude_fmu.systems.evaluation.compare import peer_quaternions
from attitude_fmu.systems.evaluation.evaluate import evaluate_recording, imu_latency
from attitude_fmu.systems.recordings.reading import read_recording
from attitude_fmu.systems.recordings.recording import Recording
from attitude_fmu.systems.simulation.motion import EARTH_FIELD_UT, PROFILES, HumanMotion, Motion
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.motions import ClosedFormMotion

FS = 100.0


@pytest.mark.parametrize("a", [0.5, 1.0, 2.0])
def test_smoother_mean_square_error_is_the_integral_of_eq41(a):
    dn, dv = math.radians(0.1), 1.0
    wg = ef.omega_g(dn, dv)
    spectrum = lambda w: ac.smoother_error_spectrum(ef.butterworth(wg), np.array([w]), dn, a * dv)[0]
    numeric = 2 * sum(integrate.quad(spectrum, lo, hi, limit=400)[0] for lo, hi in ((1e-12, wg), (wg, np.inf)))
    assert numeric / (2 * math.pi) == pytest.approx(ac.smoother_mean_square_gravity_error(dn, dv, a), rel=1e-8)


def test_offline_smoother_simulated_error_agrees_with_its_derivation():
    dn, dv = math.radians(0.1), 1.0
    run = ex.simulate_human(dn, dv, duration=20000.0, seed=3, offline=True)
    assert ex.rms(run.errors) == pytest.approx(ac.smoother_rms_attitude_error(dn, dv, 1.0, ex.PAPER_G), rel=0.10)
    # and it halves the causal filter's error, as the derivation says
    online = ex.simulate_human(dn, dv, duration=20000.0, seed=3)
    assert ex.rms(run.errors) / ex.rms(online.errors) == pytest.approx(0.5, rel=0.1)


def test_offline_needs_an_earth_frame_filter():
    rng = np.random.default_rng(0)
    gyr, acc = rng.normal(0, 0.1, (50, 3)), rng.normal(0, 0.1, (50, 3)) + [0, 0, 9.81]
    with pytest.raises(ValueError, match="offline smoothing needs"):
        estimate(gyr, acc, FS, "mahony", offline=True, gyro_offset=False)


def _window(t, period=300.0, rest=60.0, ramp=2.0):
    """0 during the first `rest` seconds of every period, 1 while moving, smooth ramps."""
    into = np.mod(t, period)
    up = 0.5 - 0.5 * np.cos(np.pi * np.clip((into - rest) / ramp, 0, 1))
    down = 0.5 - 0.5 * np.cos(np.pi * np.clip((period - into) / ramp, 0, 1))
    return np.minimum(up, down)


def _motion_with_rests(duration=3600.0, fs=FS):
    """Rotation and translation with a 60 s rest every 5 minutes (closed form), by default an hour."""
    def orientation(t):
        w = _window(t)
        return Rotation.from_euler("ZYX", np.column_stack([
            w * (1.0 * np.sin(0.7 * t) + 0.5 * np.sin(1.9 * t)), w * 0.6 * np.sin(1.1 * t),
            w * 0.4 * np.sin(1.3 * t + 1.0)]))

    def velocity(t):
        return _window(t)[:, None] * 0.3 * np.column_stack([np.sin(2.3 * t), np.cos(1.7 * t), 0.5 * np.sin(3.1 * t)])

    return ClosedFormMotion(orientation, velocity).generate(duration, fs)


def test_gyro_offset_converges_and_attitude_stays_bounded_over_an_hour():
    motion = _motion_with_rests()
    offset = np.radians([1.0, -1.0, 1.0])  # 1 °/s on every axis
    imu = ImuModel(delta_n=math.radians(0.01), gyr_offset=tuple(offset), acc_noise=0.002)
    gyr, acc = imu.apply(motion, seed=5)
    est = estimate(gyr, acc, FS, gyro_offset=True)
    after_first_rest = int(62 * FS)
    assert np.degrees(np.abs(est.offset[after_first_rest:] - offset)).max() < 0.05
    inclination = np.degrees(inclination_error(est.gravity, motion.up))
    assert inclination[after_first_rest:].max() < 1.0
    # no drift: the last ten minutes are no worse than the first hour's quarter
    assert inclination[-60000:].max() < 2 * inclination[after_first_rest:int(900 * FS)].max() + 0.1
    # without the offset estimator the same recording is far off
    without = np.degrees(inclination_error(estimate(gyr, acc, FS, gyro_offset=False).gravity, motion.up))
    print(f"max inclination error with the offset estimator {inclination[after_first_rest:].max():.2f}°, "
          f"without {without[after_first_rest:].max():.2f}°")
    assert without[after_first_rest:].max() > 4 * inclination[after_first_rest:].max()


def _first_rest_offset_error(density):
    """Offset error (°/s, largest axis) when the motion starts after the first minute's
    rest at 250 Hz, for a gyro of the density (°/s/√Hz) with 1 °/s on every axis, as a
    function of the estimator's parameters."""
    fs = 250.0
    offset = np.radians([1.0, -1.0, 1.0])
    gyr, acc = ImuModel(delta_n=math.radians(density), gyr_offset=tuple(offset),
                        acc_noise=0.002).apply(_motion_with_rests(70.0, fs), seed=5)
    return lambda params: np.degrees(np.abs(correct_gyro(gyr, acc, fs, params)[1][int(60 * fs)] - offset)).max()


def test_a_noisy_gyro_at_a_high_rate_still_finds_rest():
    """0.1 °/s/√Hz at 250 Hz: white noise alone deviates about 2 °/s per sample, so a
    per-sample rest test at rest_gyr (tau_short → 0, as vqf's; delta_n → 0 keeps the
    threshold from rising with the noise) never finds the first minute's rest; through
    the short low-pass it does, and the offset is known when the motion starts."""
    error = _first_rest_offset_error(0.1)
    per_sample = {"tau_short": 1e-9, "delta_n": 1e-12}
    print(f"offset error when the motion starts: {error({}):.3f} °/s, per-sample test {error(per_sample):.3f} °/s")
    assert error({}) < 0.05
    assert error(per_sample) > 0.5


def test_a_gyro_told_noisier_raises_the_rest_threshold_above_its_noise():
    """0.3 °/s/√Hz: through tau_short each axis has 1.06 °/s of noise, and the norm of the
    deviation exceeds the default rest_gyr (2 °/s) often enough that no rest lasts 1.5 s.
    Told delta_n, the threshold is 4.5 times that noise: the first minute's rest gives the
    offset."""
    error = _first_rest_offset_error(0.3)
    told, untold = error({"delta_n": math.radians(0.3)}), error({})
    print(f"offset error when the motion starts: delta_n told {told:.3f} °/s, untold {untold:.3f} °/s")
    assert told < 0.1 and untold > 0.5


def test_a_short_rest_gives_the_mean_of_its_gyro_samples():
    """A 2 °/s offset and 10 s at rest: once rest is detected (1.5 s) each gyro sample, low-passed
    over tau_rest from the rest's start, counts with the white-noise variance r = δn²·fs/2 of the
    default δn = 0.1 °/s/√Hz, so the estimate is the Kalman mean of a constant: the rest's n
    low-passed samples against the prior (0, σ_init² = (0.5 °/s)²), Σg/(n + r/σ_init²), not an
    average still forgetting its start (the offset's allowed drift, σ_motion per τ_motion, weights
    late samples a little more)."""
    rng = np.random.default_rng(7)
    n = int(10 * FS)
    offset = np.radians([2.0, -1.0, 1.5])
    gyr = offset + rng.normal(0.0, math.radians(0.03) * math.sqrt(FS / 2), (n, 3))
    acc = np.array([0.0, 0.0, 9.81]) + rng.normal(0.0, 0.02, (n, 3))
    _, estimate_ = correct_gyro(gyr, acc, FS)
    rest_from = int(np.argmax(np.abs(estimate_).sum(axis=1) > 0))
    assert abs(rest_from - 1.5 * FS) <= 1  # the rest conditions hold from the first sample on
    prior_weight = (math.radians(0.1) ** 2 * FS / 2) / math.radians(0.5) ** 2
    a = 1.0 - math.exp(-1.0 / (FS * gyro_offset.resolve()["tau_rest"]))
    low_passed = lfilter([a], [1.0, a - 1.0], gyr, axis=0, zi=(1.0 - a) * gyr[:1])[0]  # from gyr[0], at rest
    for k in (int(3 * FS), n - 1):
        mean = low_passed[rest_from:k + 1].sum(axis=0) / (k + 1 - rest_from + prior_weight)
        assert np.degrees(np.abs(estimate_[k] - mean)).max() < 0.005  # °/s
    assert np.degrees(np.abs(estimate_[-1] - offset)).max() < 0.03  # 4 σ of 850 samples' mean


@pytest.mark.parametrize("size", [1.0, 3.0])  # °/s; vqf clips its estimate at 2 °/s
def test_offset_is_tracked_while_moving_without_rest(size):
    """No rest at all: the accelerometer in the gyro frame pins the offset down (blocks.stages.gyro_offset):
    the tilt error within 15 % of a gyro without offset's (2–4 % at 1 °/s, 7–13 % at 3 °/s over
    six realisations). Every estimate holds the same scale_error, so that the batch path's choice
    of it (blocks.stages.scale_error) does not differ between them."""
    motion = HumanMotion(delta_v=0.25).generate(600.0, FS, seed=1)
    held = {"scale_error": 0.005}
    gyr, acc = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002).apply(motion, seed=11)
    offset = np.radians([1.0, -1.0, 0.5]) * size
    est = estimate(gyr + offset, acc, FS, params=held, gyro_offset=True)
    half = int(300 * FS)
    assert np.degrees(np.abs(est.offset[half:] - offset)).max() < 0.1  # °/s
    error = lambda up: rms(np.degrees(inclination_error(up[half:], motion.up[half:])))
    untracked, _ = correct_gyro(gyr + offset, acc, FS, {"tau_motion": 0.0})
    vqf_up = Rotation.from_quat(peer_quaternions("vqf", gyr + offset, acc, FS), scalar_first=True).inv().apply([0, 0, 1])
    print(f"offset {size} °/s, inclination RMS: tracked {error(est.up):.3f}°, "
          f"without offset {error(estimate(gyr, acc, FS, params=held, gyro_offset=False).up):.3f}°, "
          f"rest-only estimator {error(estimate(untracked, acc, FS, params=held, gyro_offset=False).up):.3f}°, vqf {error(vqf_up):.3f}°")
    assert error(est.up) < 1.15 * error(estimate(gyr, acc, FS, params=held, gyro_offset=False).up)
    assert error(estimate(untracked, acc, FS, params=held, gyro_offset=False).up) > 5 * error(est.up)
    if size > 2.0:
        assert error(vqf_up) > 5 * error(est.up)


def test_offset_tracking_started_in_motion_does_not_depend_on_the_sample_rate():
    """Vigorous slosh (0.5 m/s/√Hz) from the first sample, no offset, at 1 kHz and the same
    motion averaged to 100 Hz: a single first accelerometer sample is off by tens of m/s²
    at 1 kHz (the motion's white acceleration), and a low-pass started on it turned the
    gyro-frame direction for long enough to teach the tracking a false offset (measured
    0.19 °/s RMS at 1 kHz, 0.14 °/s at 100 Hz). Started on the running mean of the first
    tau_acc, both stay within 0.05 °/s."""
    motion = HumanMotion(delta_v=0.5, omega_c=5.0, rot_rms=0.3).generate(200.0, 1000.0, seed=20)
    steps = Rotation.from_rotvec(motion.gyr / 1000.0)
    turns = steps[0::10]
    for i in range(1, 10):
        turns = turns * steps[i::10]
    rates = {1000.0: (motion.gyr, motion.acc),
             100.0: (turns.as_rotvec() * 100.0, motion.acc.reshape(-1, 10, 3).mean(axis=1))}
    for fs, (gyr, acc) in rates.items():
        _, est = correct_gyro(gyr, acc, fs)
        error = math.degrees(rms(est[int(30 * fs):]))
        print(f"{fs:g} Hz: offset estimate RMS after 30 s {error:.3f} °/s")
        assert error < 0.05  # °/s


def test_offline_offset_comes_from_the_whole_recording():
    """A rest only at the end: offline, the backward pass brings its offset to the start
    (each axis weighted by the passes' variances), where the forward pass knows nothing yet."""
    motion = HumanMotion(delta_v=0.25).generate(200.0, FS, seed=1)
    imu = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002)
    gyr, acc = imu.apply(motion, seed=4)
    end = Rotation.from_quat(motion.quat[-1], scalar_first=True).inv()
    rest_gyr = np.random.default_rng(5).normal(0.0, 1e-3, (3000, 3))
    rest_acc = end.apply(np.tile([0.0, 0.0, 9.81], (3000, 1)))
    offset = np.radians([1.0, -1.0, 0.5])
    gyr, acc = np.vstack([gyr, rest_gyr]) + offset, np.vstack([acc, rest_acc])
    up = np.vstack([motion.up, np.tile(motion.up[-1], (3000, 1))])
    est = estimate(gyr, acc, FS, offline=True, gyro_offset=True)
    causal, _ = correct_gyro(gyr, acc, FS)
    error = lambda e: rms(np.degrees(inclination_error(e.up, up)))
    print(f"offline inclination RMS: offset from both passes {error(est):.3f}°, "
          f"forward only {error(estimate(causal, acc, FS, offline=True, gyro_offset=False)):.3f}°")
    assert np.degrees(np.abs(est.offset - offset)).max() < 0.15  # °/s, from the first sample on
    assert error(est) < 0.6 * error(estimate(causal, acc, FS, offline=True, gyro_offset=False))


def test_offline_a_pass_that_learnt_nothing_of_an_axis_leaves_it_to_the_other():
    """10 s at rest, then 120 s turning about the vertical while lying flat, a vertical offset of 4 °/s
    (and 0.3, −0.2 °/s across): the forward pass learns the vertical offset at the rest, the backward pass
    never (gravity cannot show it while flat; its variance stays sigma_init²). Both passes start from the
    same prior, counted once: offline the vertical offset is the forward pass's over the motion, within
    0.02 °/s of the truth (what its rest found), where an average by inverse variances pulled it back
    towards 0, by 0.2 °/s at the end."""
    rng = np.random.default_rng(2)
    t = np.arange(int(130 * FS)) / FS
    yaw_rate = np.where(t < 10.0, 0.0, 0.8 * np.sin(0.3 * (t - 10.0)) + 0.5 * np.sin(1.1 * (t - 10.0)))
    offset = np.radians([0.3, -0.2, 4.0])
    gyr = np.column_stack([np.zeros_like(t), np.zeros_like(t), yaw_rate]) + offset
    gyr += rng.normal(0.0, math.radians(0.01) * math.sqrt(FS / 2), gyr.shape)
    acc = np.tile([0.0, 0.0, 9.81], (len(t), 1)) + rng.normal(0.0, 1.5e-3 * math.sqrt(FS / 2), (len(t), 3))
    offline = np.degrees(correct_gyro(gyr, acc, FS, offline=True)[1][t >= 12.0, 2])
    print(f"vertical offset error over the motion, offline: {np.abs(offline - 4.0).max():.4f} °/s")
    assert np.abs(offline - 4.0).max() < 0.02  # °/s


def test_a_raw_phone_gyros_offset_is_found_at_its_first_rest():
    """The phone_running scenario: 4 °/s on every axis (6.9 °/s in all, beyond a calibrated gyro's but
    within a raw MEMS gyro's datasheet), 5 s at rest, then running. The rest before the run finds the
    offset (the stage kept it at 0 while its rest threshold was 5 °/s), and every cell of the scenario
    table is ahead of vqf, the 6D heading included (0.7° against 91°, which the unseen vertical offset
    took to 91.9° before)."""
    from attitude_fmu.systems.evaluation.scenarios import score
    from attitude_fmu.systems.simulation.scenarios import SCENARIOS, scenario

    s = SCENARIOS["phone_running"]
    rec = scenario("phone_running").recording()
    found = np.degrees(correct_gyro(rec.gyr, rec.acc, rec.fs)[1][int(s.rest * rec.fs)])
    truth = np.degrees(s.sensor.model(s.seed).gyr_offset)
    scores = score("phone_running")
    print(f"offset after the rest {np.round(found, 3)} °/s (truth {np.round(truth, 3)}); "
          + str({column: {k: round(v, 2) for k, v in cells.items()} for column, cells in scores.items()}))
    assert np.abs(found - truth).max() < 0.05  # °/s
    for column, cells in scores.items():
        assert cells["ours"] < 0.5 * cells["vqf"], column


def test_offline_a_slow_onset_of_motion_is_not_taken_for_rest():
    """5 s at rest, then turns of 90° about the vertical of minimum jerk (1.2 s; rate 30·s²(1 − s)²·θ/T, which
    starts too slowly to break the rest at once) between 0.5-s dwells, then 5 s at rest; a calibrated gyro
    (0.004 °/s/√Hz) with a known offset, the accelerometer still. Forward in time, with each raw sample
    measuring the offset (tau_rest → 0), the onset's first samples count as rest and shift the vertical
    offset by 0.012 °/s; through tau_rest's low-pass, which lags the onset, by 0.002 °/s; offline a rest's
    sample counts only where the rest holds rest_time after it too. Both stay within 0.005 °/s of the
    truth over the motion."""
    rng = np.random.default_rng(1)
    s = np.arange(int(1.2 * FS)) / (1.2 * FS)
    rate = math.radians(90.0) / 1.2 * 30.0 * s ** 2 * (1.0 - s) ** 2
    dwell, rest = np.zeros(int(0.5 * FS)), np.zeros(int(5 * FS))
    turn = np.concatenate([rest, *[piece for i in range(20) for piece in ((-1) ** i * rate, dwell)], rest])
    n = len(turn)
    offset = np.radians([0.03, -0.02, 0.05])
    gyr = np.column_stack([np.zeros(n), np.zeros(n), turn]) + offset
    gyr += rng.normal(0.0, math.radians(0.004) * math.sqrt(FS / 2), (n, 3))
    acc = np.tile([0.0, 0.0, 9.81], (n, 1)) + rng.normal(0.0, 6e-4, (n, 3))
    motion = slice(int(5 * FS), n - int(5 * FS))
    errors = {(offline, raw): np.degrees(correct_gyro(gyr, acc, FS, {"tau_rest": 1e-9} if raw else None,
                                                      offline=offline)[1] - offset)[motion, 2]
              for offline, raw in ((False, True), (False, False), (True, False))}
    print({key: round(float(np.abs(e).max()), 4) for key, e in errors.items()})
    assert np.abs(errors[False, True]).max() > 0.008  # °/s: forward from raw samples, the onset taken for rest
    assert np.abs(errors[False, False]).max() < 0.005 and np.abs(errors[True, False]).max() < 0.005


@pytest.mark.parametrize("profile", ["lever_arm", "offset_rotation"])
def test_offset_tracking_does_not_take_centripetal_acceleration_for_an_offset(profile):
    """Steady or swinging rotation on an arm: the sensor-fixed centripetal acceleration turns
    with the sensor like an offset across the rotation axis would; the estimate stays within
    the uncertainty the tracking claims (sigma_motion, 0.1 °/s)."""
    motion = PROFILES[profile].motion().generate(300.0, FS, 0)
    gyr, acc = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002).apply(motion, seed=1)
    _, est = correct_gyro(gyr, acc, FS)
    print(f"{profile}: largest offset estimate {np.degrees(np.abs(est)).max():.3f} °/s")
    assert np.degrees(np.abs(est)).max() < 0.1  # °/s


def _broad_like(path, motion, quat_ref=True, movement=True):
    gyr, acc = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002).apply(motion, seed=1)
    data = {"imu_gyr": gyr, "imu_acc": acc, "imu_mag": motion.mag, "sampling_rate": FS}
    if quat_ref:
        ref = motion.quat.copy()
        ref[100:120] = np.nan  # the optical system lost the body for a moment
        data["opt_quat"] = ref
    if movement:
        data["movement"] = (np.arange(len(gyr)) > 500).astype(float)
    savemat(path, data)


def test_evaluate_json_contract_on_synthetic_recordings(tmp_path, capsys):
    motion = ClosedFormMotion(lambda t: Rotation.from_euler("ZY", np.column_stack([
        0.8 * np.sin(0.5 * t), 0.5 * np.sin(0.3 * t)]))).generate(60.0, FS)
    for name in ("a", "b"):
        _broad_like(tmp_path / f"{name}.mat", motion)
    assert main(["evaluate", "--json", "--workers", "1", str(tmp_path / "a.mat"), str(tmp_path / "b.mat")]) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result) == {"recordings", "mean", "imu_latency_s", "chosen", "mag_used"}
    assert set(result["recordings"]) == {"a", "b"} and set(result["mag_used"]) == {"a", "b"}
    assert set(result["chosen"]) == {"a", "b"}  # each recording's scale_error (blocks.stages.scale_error)
    assert all(found["scale_error"] in SCALE_ERRORS for found in result["chosen"].values())
    assert all(abs(lag) < 1e-3 for lag in result["imu_latency_s"].values())  # written without a delay (slow turns)
    for table in (result["recordings"]["a"], result["mean"]):
        assert set(table) == {"wiener", "vqf", "vqf_offline", "madgwick", "vqf_9d"}
        for row in table.values():
            assert set(row) == {"inclination_rmse_deg", "heading_rmse_deg", "total_rmse_deg"}
            assert row["inclination_rmse_deg"] <= row["total_rmse_deg"] + 1e-9
    assert result["mean"]["wiener"]["inclination_rmse_deg"] < 0.5
    assert main(["evaluate", "--json", "--offline", str(tmp_path / "a.mat")]) == 0
    assert "wiener_offline" in json.loads(capsys.readouterr().out)["mean"]
    # --start-in-movement: the same figures as on the recording cut there (movement from index 501)
    assert main(["evaluate", "--json", "--start-in-movement", "2", str(tmp_path / "a.mat")]) == 0
    cut = read_recording(tmp_path / "a.mat").into_movement(2.0)
    assert len(cut.gyr) == len(motion.gyr) - 501 - 200
    assert json.loads(capsys.readouterr().out)["recordings"]["a"] == evaluate_recording(cut)
    assert main(["evaluate", "--start-in-movement", "100", str(tmp_path / "a.mat")]) == 2
    assert "ends before 100 s into its movement phase" in capsys.readouterr().err
    # files of one name from two folders are told apart by their paths
    (tmp_path / "x").mkdir()
    shutil.copy(tmp_path / "a.mat", tmp_path / "x" / "a.mat")
    paths = [str(tmp_path / "a.mat"), str(tmp_path / "x" / "a.mat")]
    assert main(["evaluate", "--json", "--workers", "1", *paths]) == 0
    assert list(json.loads(capsys.readouterr().out)["recordings"]) == paths


def _delayed_imu(motion, duration: float, delay: float):
    """(gyr, acc) of an IMU whose samples lag the motion by delay (s), and the truth now."""
    t = np.arange(1, int(duration * FS) + 1) / FS
    gyr, acc, _ = motion.at(t - delay, 1.0 / FS)
    truth = motion.at(t, 1.0 / FS)
    return gyr, acc, truth


@pytest.mark.parametrize("offline", [False, True])
def test_latency_carries_a_delayed_imu_onto_the_motion(offline):
    """An IMU 8 ms (0.8 samples) behind a closed-form pitching motion: the estimate lags
    with it, its inclination error the rate times the delay (RMS of |ω|·d, within 5 %).
    Carried forward over the delay (blocks.stages.timing), what is left is the extrapolation's
    second-order term: the gyro's last sample is the rate (d + Ts)/2 before the middle of
    the delay, so |ω̇|·d·(d + Ts)/2 (within 10 %), under 3 % of the lag's error."""
    delay = 0.008
    motion = PROFILES["sine_rotation"].motion({"inclination_deg": 20.0})
    gyr, acc, (true_gyr, _, true_quat) = _delayed_imu(motion, 60.0, delay)
    up = Rotation.from_quat(true_quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    settled = slice(int(20 * FS), None)
    errors = {}
    for latency in (0.0, delay):
        est = estimate(gyr, acc, FS, offline=offline, latency=latency, gyro_offset=False)
        errors[latency] = rms(inclination_error(est.up[settled], up[settled]))
        from_quat = Rotation.from_quat(est.quat[settled], scalar_first=True).inv().apply([0.0, 0.0, 1.0])
        assert np.abs(from_quat - est.up[settled]).max() < 1e-9  # q and the up-vector carried alike
    lag = rms(np.linalg.norm(true_gyr[settled], axis=1) * delay)
    left = rms(np.linalg.norm(np.gradient(true_gyr, axis=0)[settled], axis=1) * FS * delay * (delay + 1 / FS) / 2)
    print(f"inclination RMS: {math.degrees(errors[0.0]):.4f}° without (|ω|·d {math.degrees(lag):.4f}°), "
          f"{math.degrees(errors[delay]):.5f}° with latency compensation (|ω̇|·d·(d + Ts)/2 {math.degrees(left):.5f}°)")
    assert errors[0.0] == pytest.approx(lag, rel=0.05)
    assert errors[delay] == pytest.approx(left, rel=0.1) and errors[delay] < 0.03 * errors[0.0]


def _mean_specific_force(motion, t, parts: int = 64):
    """The specific force of a closed-form motion averaged over each sample time (t_k − 1/FS,
    t_k] (midpoints of `parts` slices), as a sensor that averages it reads it (N×3, m/s²)."""
    return np.mean([motion.at(t - (j + 0.5) / (parts * FS), 1e-7)[1] for j in range(parts)], axis=0)


@pytest.mark.parametrize("convention", ["gyr_samples", "acc_samples"])
def test_samples_of_another_timing_are_turned_into_the_convention(convention):
    """The ±10° pitch at 0.5 Hz (Ω = π rad/s) at 100 Hz sampled with another timing than
    the project's, read as if it had it; the filter is eq. 34 at ω_g = 1 rad/s:
    - gyro point samples, the rate at t_k (a simulation that samples ω(t_k)): integrated
      as means, the gyro's frame leads by Ts/2, which the filter passes on through its
      complementary high-pass 1 − B(jΩ);
    - accelerometer means over each sample time (a recording averaged down): read as the
      force at t_k, gravity lags by Ts/2, which the filter passes through its low-pass B(jΩ).
    Either way a tilt RMS of that gain times |ω|·Ts/2 (within 3 %), under 2 % of it with
    the convention given (gyr_samples "point", acc_samples "mean"); vqf, which reads
    samples as the project does, keeps an error of that order. imu_latency sees point
    samples of the rate Ts/2 ahead of the reference, and on time once turned into means."""
    motion = PROFILES["sine_rotation"].motion({"inclination_deg": 20.0})
    t = np.arange(1, int(60 * FS) + 1) / FS
    s = 1j * math.pi
    low_pass = 1.0 / (s * s + math.sqrt(2.0) * s + 1.0)
    if convention == "gyr_samples":
        gyr, acc, quat = motion.at(t, 1e-7)  # the rate and specific force at t_k
        given, gain = "point", abs(1.0 - low_pass)
    else:
        gyr, _, quat = motion.at(t, 1 / FS)
        acc, given, gain = _mean_specific_force(motion, t), "mean", abs(low_pass)
    up = Rotation.from_quat(quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    settled = slice(int(20 * FS), None)
    errors = {told: rms(inclination_error(estimate(gyr, acc, FS, params={"omega_g": 1.0},
                                                   **({convention: given} if told else {})).up[settled], up[settled]))
              for told in (False, True)}
    expected = gain * rms(np.linalg.norm(gyr[settled], axis=1) / FS / 2)
    print(f"tilt RMS with {convention} {given} read as the convention {math.degrees(errors[False]):.5f}° "
          f"(gain·|ω|·Ts/2 {math.degrees(expected):.5f}°), turned into it {math.degrees(errors[True]):.6f}°")
    assert errors[False] == pytest.approx(expected, rel=0.03) and errors[True] < 0.02 * expected
    vqf_up = Rotation.from_quat(peer_quaternions("vqf", gyr, acc, FS), scalar_first=True).inv().apply([0, 0, 1.0])
    vqf_error = rms(inclination_error(vqf_up[settled], up[settled]))
    print(f"vqf: {math.degrees(vqf_error):.5f}°")
    assert vqf_error > 0.5 * expected
    if convention == "gyr_samples":
        rec = Recording("point", FS, gyr, acc, t, quat_ref=quat, movement=t > 20.0)
        assert imu_latency(rec) == pytest.approx(-0.5 / FS, abs=1e-4)
        assert imu_latency(replace(rec, gyr=interval_means(gyr))) == pytest.approx(0.0, abs=1e-4)


@pytest.mark.parametrize("flag, value", [("--gyr-samples", "point"), ("--acc-samples", "mean")])
def test_sample_conventions_reach_evaluate_estimate_and_the_peers(tmp_path, capsys, flag, value):
    """The coning motion sampled as the flag says (the rate at t_k; the specific force
    averaged over each sample time): with the flag every method's error falls by half or
    more, the peers' too (they get the same conversion; on the averaged specific force,
    where their error is much the noise's, vqf's by two fifths and vqf_offline's by a tenth:
    by 47–60 % and 15–33 % over six realisations of the noise), and gyro point samples are
    measured on time instead of Ts/2 ahead; estimate writes the batch path's estimate."""
    motion = PROFILES["coning"].motion()
    t = np.arange(1, int(60 * FS) + 1) / FS
    gyr, acc, quat = motion.at(t, 1e-7 if flag == "--gyr-samples" else 1 / FS)
    if flag == "--acc-samples":
        acc = _mean_specific_force(motion, t)
    _broad_like(tmp_path / "sampled.mat", Motion(FS, quat, gyr, acc))
    runs = {}
    for given in ("default", value):
        assert main(["evaluate", "--json", str(tmp_path / "sampled.mat")]
                    + ([flag, value] if given == value else [])) == 0
        runs[given] = json.loads(capsys.readouterr().out)
    ahead = -0.5 / FS if flag == "--gyr-samples" else 0.0
    assert runs["default"]["imu_latency_s"]["sampled"] == pytest.approx(ahead, abs=2e-4)
    assert runs[value]["imu_latency_s"]["sampled"] == pytest.approx(0.0, abs=2e-4)
    noise_bound = {"vqf": 0.6, "vqf_offline": 0.9} if flag == "--acc-samples" else {}  # much of it the noise's
    for label in ("wiener", "vqf", "vqf_offline"):
        assert (runs[value]["mean"][label]["inclination_rmse_deg"]
                < noise_bound.get(label, 0.5) * runs["default"]["mean"][label]["inclination_rmse_deg"]), label
    out = tmp_path / "est.csv"
    assert main(["estimate", str(tmp_path / "sampled.mat"), "--out", str(out), flag, value]) == 0
    rec = read_recording(tmp_path / "sampled.mat")
    ref = estimate(rec.gyr, rec.acc, FS, gyro_offset=True, mag=rec.mag, **{flag[2:].replace("-", "_"): value})
    written = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.abs(written[:, 1:5] - ref.quat).max() < 1e-9


@pytest.mark.parametrize("delay", [0.0037, -0.002])
def test_imu_latency_measures_the_delay_behind_the_reference(delay):
    """A noisy IMU behind (or ahead of) a reference with a gap: imu_latency finds the
    delay within 0.1 ms; a reference with less than a second of rates gives None."""
    motion = PROFILES["coning"].motion()
    gyr, acc, (_, _, quat) = _delayed_imu(motion, 30.0, delay)
    gyr = gyr + np.random.default_rng(4).standard_normal(gyr.shape) * math.radians(0.02) * math.sqrt(FS / 2)
    quat[1000:1100] = np.nan
    rec = Recording("delayed", FS, gyr, acc, np.arange(len(gyr)) / FS, quat_ref=quat)
    assert imu_latency(rec) == pytest.approx(delay, abs=1e-4)
    quat[int(FS) - 1:] = np.nan
    assert imu_latency(Recording("short", FS, gyr, acc, rec.t, quat_ref=quat)) is None


def test_evaluate_measures_the_imu_latency_and_carries_every_estimate_over_it(tmp_path, capsys):
    """A recording whose IMU trails its reference by 6 ms: `attitude evaluate` reports the
    delay (JSON and a note), and with --latency at that value every method, ours and the
    peers', gets the error it has on the same IMU without the delay, within 0.01°. (Most
    errors fall a lot; Madgwick's rises, as its own error on coning, 0.48°, and the
    delay's happened to partly cancel.)"""
    delay = 0.006
    motion = PROFILES["coning"].motion()
    for name, d in (("late", delay), ("prompt", 0.0)):
        gyr, acc, (_, _, quat) = _delayed_imu(motion, 60.0, d)
        _broad_like(tmp_path / f"{name}.mat", Motion(FS, quat, gyr, acc))
    runs = []
    for name, latency in (("late", "0"), ("late", "0.006"), ("prompt", "0")):
        assert main(["evaluate", "--json", "--latency", latency, str(tmp_path / f"{name}.mat")]) == 0
        out, err = capsys.readouterr()
        runs.append(json.loads(out))
        if name == "late":
            assert runs[-1]["imu_latency_s"]["late"] == pytest.approx(delay, abs=2e-4)
            assert "the IMU lags the reference by 5.98" in err and f"(now {latency})" in err
    before, after, prompt = (run["mean"] for run in runs)
    with capsys.disabled():
        print({label: f"{before[label]['inclination_rmse_deg']:.3f}° → {after[label]['inclination_rmse_deg']:.3f}° "
                      f"(no delay {prompt[label]['inclination_rmse_deg']:.3f}°)" for label in before})
    for label in before:
        assert after[label]["inclination_rmse_deg"] == pytest.approx(prompt[label]["inclination_rmse_deg"], abs=0.01)
    assert after["wiener"]["inclination_rmse_deg"] < 0.3 * before["wiener"]["inclination_rmse_deg"]
    with pytest.raises(SystemExit) as refused:
        main(["evaluate", "--latency", "inf", str(tmp_path / "late.mat")])
    assert refused.value.code == 2
    assert "argument --latency: inf is outside the plausible [-0.5, 0.5] s" in capsys.readouterr().err


@pytest.mark.parametrize("case", ["no optical reference", "no valid sample during movement", "not a readable",
                                  "no movement phase"])
def test_evaluate_without_reference_or_on_a_broken_file_fails_cleanly(tmp_path, capsys, case):
    motion = ClosedFormMotion(lambda t: Rotation.from_rotvec(np.zeros((len(t), 3)))).generate(10.0, FS)
    path = tmp_path / "rec.mat"
    if case == "not a readable":
        path.write_bytes(b"MATLAB 5.0 MAT-file; broken on purpose")
    else:
        _broad_like(path, motion, quat_ref=case != "no optical reference")
        if case == "no valid sample during movement":  # the optical system lost the body throughout
            data = loadmat(path)
            savemat(path, {**{k: v for k, v in data.items() if not k.startswith("__")},
                           "opt_quat": np.full_like(data["opt_quat"], np.nan)})
        if case == "no movement phase":  # a movement flag of 0 throughout
            data = loadmat(path)
            savemat(path, {**{k: v for k, v in data.items() if not k.startswith("__")},
                           "movement": np.zeros_like(data["movement"])})
    _broad_like(tmp_path / "good.mat", motion)
    assert main(["evaluate", "--workers", "1", str(tmp_path / "good.mat"), str(path)]) == 2
    out, err = capsys.readouterr()
    assert "[2/2] error:" in err and case in err and "1 of 2 recordings failed" in err and "Traceback" not in err, err
    assert out.splitlines()[2].split()[0] == "good"  # the good file is evaluated all the same


def test_quaternion_errors_split_heading_from_inclination():
    ref = Rotation.random(20, random_state=2)
    heading_only = Rotation.from_euler("z", np.full((20, 1), 0.3)) * ref
    total, heading, inclination = quaternion_errors(heading_only.as_quat(scalar_first=True),
                                                    ref.as_quat(scalar_first=True))
    assert np.allclose(heading, 0.3) and np.allclose(inclination, 0.0, atol=1e-7) and np.allclose(total, 0.3)


def _turns_with_field(earth_field=None, rest=None, duration=600.0):
    """`duration` s of turning (heading ±86°, tilt ±29°; still from rest[0] to rest[1] s if
    given) with a 0.2 °/s gyro offset about z: (motion, gyr, acc, magnetometer with 0.5 µT
    noise). earth_field (N×3, µT, ENU) is the field where the sensor is, by default the
    homogeneous EARTH_FIELD_UT."""
    def angles(t):
        if rest is not None:
            t = np.where(t < rest[0], t, np.maximum(t - (rest[1] - rest[0]), rest[0]))
        return np.column_stack([1.5 * np.sin(0.2 * t) + 0.3, 0.5 * np.sin(0.3 * t), 0.4 * np.sin(0.5 * t)])
    motion = ClosedFormMotion(lambda t: Rotation.from_euler("ZYX", angles(t))).generate(duration, FS)
    gyr, acc = ImuModel(delta_n=math.radians(0.05), gyr_offset=(0.0, 0.0, math.radians(0.2))).apply(motion, seed=1)
    ideal = motion.mag if earth_field is None else Rotation.from_quat(motion.quat, scalar_first=True).inv().apply(earth_field)
    return motion, gyr, acc, ideal + np.random.default_rng(2).normal(0, 0.5, ideal.shape)


def test_parameters_reach_every_running_stage_that_has_them():
    """params go to the method, the gyro-offset and the heading estimator, to each that
    runs and has the name: delta_n, the gyro's noise density, to the first two alike. A
    name no running stage has is refused, with the names they have."""
    motion, gyr, acc, mag = _turns_with_field(duration=100.0)
    noise, offset_only, heading_only = {"delta_n": math.radians(0.3)}, {"rest_time": 3.0}, {"tau_heading": 5.0}
    est = estimate(gyr, acc, FS, params={**noise, **offset_only, **heading_only}, gyro_offset=True, mag=mag)
    corrected, offset = correct_gyro(gyr, acc, FS, {**noise, **offset_only})
    quat = with_magnetometer(estimate(corrected, acc, FS, params=noise, gyro_offset=False).quat, mag, FS,
                             {**noise, **heading_only})[0]
    assert np.array_equal(est.offset, offset) and np.array_equal(est.quat, quat)
    assert np.abs(est.quat - estimate(gyr, acc, FS, gyro_offset=True, mag=mag).quat).max() > 1e-4
    with pytest.raises(ValueError, match=r"unknown parameter 'tau_heading' \(the method wiener: delta_n.*; "
                                         r"the gyro-offset estimator: rest_gyr.*\)$"):
        estimate(gyr, acc, FS, params=heading_only, gyro_offset=True)


def test_magnetometer_heading_follows_the_field_and_survives_a_disturbance():
    motion, gyr, acc, mag = _turns_with_field()
    heading_of = lambda est: np.degrees(quaternion_errors(est.quat, motion.quat)[1])
    gyro_only, with_mag = estimate(gyr, acc, FS, gyro_offset=False), estimate(gyr, acc, FS, mag=mag, gyro_offset=False)
    assert heading_of(gyro_only)[-1] > 45.0  # the gyro's heading walks off
    assert np.sqrt(np.mean(heading_of(with_mag) ** 2)) < 3.0
    # inclination is not touched by the heading stage
    assert np.allclose(quaternion_errors(with_mag.quat, motion.quat)[2], quaternion_errors(gyro_only.quat, motion.quat)[2])
    # 100 s of a 30 µT disturbance fixed to the sensor, the hard-iron fit off: rejected, bounded, recovered
    disturbed = mag.copy()
    disturbed[20000:30000] += [30.0, 0.0, 0.0]
    out, accepted, _, _ = with_magnetometer(gyro_only.quat, disturbed, FS, {"mag_cal_time": 0.0})
    heading = np.degrees(quaternion_errors(out, motion.quat)[1])
    assert accepted[20000:30000].mean() < 0.2 and accepted[31000:].all()
    assert heading[20000:30000].max() < 30.0  # about the gyro's 0.2 °/s over 100 s, not the field's pull
    assert heading[40000:].max() < 3.0


@pytest.mark.parametrize("case, every", [("disturbed start", 1), ("another field from 200 s", 1),
                                         ("disturbed start", 4)])
def test_heading_takes_a_new_field_that_stays_steady_while_the_sensor_turns(case, every):
    """A wrong reference (the first 30 s next to an earth-fixed disturbance of 31 µT) or a
    move to a place whose field differs (norm −15 %, dip +7°, north unchanged): the guard
    would refuse the true field for good; the new field, steady for mag_new_time (20 s)
    while the sensor turns, becomes the reference and the heading follows it again. With a
    magnetometer at a quarter of the IMU's rate (NaN between its samples) the times stay
    in seconds."""
    earth = np.tile(EARTH_FIELD_UT, (int(600 * FS), 1)).astype(float)
    change = int(30 * FS) if case == "disturbed start" else int(200 * FS)
    if case == "disturbed start":
        earth[:change] += [25.0, -10.0, 15.0]
    else:
        earth[change:] = [0.0, 12.0, -38.0]
    motion, gyr, acc, mag = _turns_with_field(earth)
    mag[np.arange(len(mag)) % every != 0] = np.nan
    est = estimate(gyr, acc, FS, mag=mag, gyro_offset=True)
    heading = np.degrees(quaternion_errors(est.quat, motion.quat)[1])
    proven = change + int(25 * FS)  # mag_new_time and a few seconds of averaging later
    print(f"{case}, field every {every} samples: heading from {proven / FS:.0f} s max "
          f"{heading[proven:].max():.2f}°, accepted {est.mag_accepted[proven::every].mean():.3f}")
    assert est.mag_accepted[proven::every].all()
    assert heading[proven:].max() < 3.0


def test_a_new_field_needs_the_sensor_to_turn():
    """A field fixed to the sensor (a magnet carried along, 30 µT for the last 400 s of the
    turning) changes its norm and dip as the sensor turns: never taken as the reference
    (the hard-iron fit, which would remove it, off), the output equals that of an
    estimator that never takes one. A steady new field at a sensor that does not turn is
    refused as well, until mag_new_angle asks for no turn; its step is seen at once (a field
    without noise needs no low-pass before the guard, blocks.stages.heading)."""
    motion, gyr, acc, mag = _turns_with_field()
    mag[20000:] += [30.0, 0.0, 0.0]
    quat = estimate(gyr, acc, FS, gyro_offset=False).quat
    default, accepted, _, _ = with_magnetometer(quat, mag, FS, {"mag_cal_time": 0.0})
    never, _, _, _ = with_magnetometer(quat, mag, FS, {"mag_new_time": 1e9, "mag_cal_time": 0.0})
    assert np.array_equal(default, never) and accepted[20000:].mean() < 0.1
    still = np.tile([1.0, 0.0, 0.0, 0.0], (int(200 * FS), 1))
    field = np.tile(EARTH_FIELD_UT, (len(still), 1)).astype(float)
    field[int(30 * FS):] = [0.0, 12.0, -38.0]
    for params, taken in (({}, False), ({"mag_new_angle": 0.0}, True)):
        _, accepted, _, _ = with_magnetometer(still, field, FS, params)
        seen = int(30 * FS)
        assert accepted[-int(100 * FS):].all() == taken and not accepted[seen:int(49 * FS)].any()


@pytest.mark.parametrize("offset, start", [((5.0, 0.0, 0.0), 0), ((40.0, 10.0, -20.0), 0), ((30.0, 0.0, 0.0), 200)])
def test_a_hard_iron_offset_is_fitted_and_removed(offset, start):
    """A field fixed to the sensor from `start` s on (the magnetometer's own hard iron, or a
    magnet carried along): once the sphere fit of the recent samples proves it (samples in
    every direction, a sphere about b and not about 0, for mag_new_time), it is removed and
    the heading follows the earth's field; with the fit off the guard can only fall back
    on the gyro. On the clean field the estimate stays exactly 0."""
    motion, gyr, acc, mag = _turns_with_field()
    quat = estimate(gyr, acc, FS, gyro_offset=True).quat  # 6D
    _, _, clean_offset, _ = with_magnetometer(quat, mag, FS)
    assert not clean_offset.any()
    mag[int(start * FS):] += offset
    heading_of = lambda out: np.degrees(quaternion_errors(out, motion.quat)[1])
    out, _, estimate_, _ = with_magnetometer(quat, mag, FS)
    without = heading_of(with_magnetometer(quat, mag, FS, {"mag_cal_time": 0.0})[0])
    taken = int(np.argmax(np.abs(estimate_).sum(axis=1) > 0))
    heading = heading_of(out)
    print(f"hard iron {offset} µT from {start} s: taken at {taken / FS:.0f} s, estimate "
          f"{np.round(estimate_[-1], 2)}, heading max from 5 s later {heading[taken + int(5 * FS):].max():.2f}°, "
          f"without the fit {without[taken:].max():.2f}°")
    assert start * FS < taken < (start + 250) * FS
    assert np.abs(estimate_[-1] - offset).max() < 0.5  # µT
    assert heading[taken + int(5 * FS):].max() < 2.0
    assert without[taken:].max() > 5.0


def test_a_magnet_carried_for_a_while_is_fitted_then_dropped():
    """A 30 µT magnet carried along from 200 s to 300 s: the latest samples leave the sphere
    the recent field fits, so the fit starts afresh from them, takes the magnet's offset
    while it is carried and drops it soon after it is gone. The guard alone (fit off) can
    only fall back on the gyro, whose 0.2 °/s offset walks the heading off meanwhile."""
    motion, gyr, acc, mag = _turns_with_field()
    mag[20000:30000] += [30.0, 0.0, 0.0]
    quat = estimate(gyr, acc, FS, gyro_offset=False).quat  # 6D
    rms_heading = lambda out: rms(np.degrees(quaternion_errors(out, motion.quat)[1]))
    out, _, offset, _ = with_magnetometer(quat, mag, FS)
    used = np.abs(offset).sum(axis=1) > 0
    taken, dropped = int(np.argmax(used)), 30000 + int(np.argmin(used[30000:]))
    without = with_magnetometer(quat, mag, FS, {"mag_cal_time": 0.0})[0]
    print(f"magnet 200–300 s: taken at {taken / FS:.1f} s ({np.round(offset[taken], 2)} µT), dropped at "
          f"{dropped / FS:.1f} s; heading RMS {rms_heading(out):.2f}°, with the fit off {rms_heading(without):.2f}°")
    assert 20000 < taken < 28000 and np.abs(offset[taken:30000] - [30.0, 0.0, 0.0]).max() < 1.0
    assert 30000 < dropped < 30000 + 60 * FS and not used[dropped:].any()
    assert rms_heading(out) < 0.7 * rms_heading(without)


def test_offline_each_hard_iron_offset_holds_from_where_the_field_began_to_fit_it():
    """The magnet of the test above, offline: the forward pass proves the offset only
    after mag_new_time of fitting, and drops it as late; offline each change is moved back
    to where the field began to fit the new sphere (blocks.stages.hard_iron.back_dated). So the
    offset is in use from within 1 s of 200 s to within 1 s of 300 s, and the heading is
    better than the forward pass's on the same smoothed attitude."""
    motion, gyr, acc, mag = _turns_with_field()
    mag[20000:30000] += [30.0, 0.0, 0.0]
    est = estimate(gyr, acc, FS, gyro_offset=True, mag=mag, offline=True)
    smoothed = estimate(gyr, acc, FS, gyro_offset=True, offline=True).quat
    forward, _, forward_offset, _ = with_magnetometer(smoothed, mag, FS, {"mag_delay": est.mag_delay[0]})
    rms_heading = lambda quat: rms(np.degrees(quaternion_errors(quat, motion.quat)[1]))
    used, forward_used = est.mag_offset.any(axis=1), forward_offset.any(axis=1)
    span = lambda used: (np.argmax(used) / FS, (len(used) - np.argmax(used[::-1])) / FS)
    print(f"magnet 200–300 s offline: in use {span(used)[0]:.2f}–{span(used)[1]:.2f} s (forward pass "
          f"{span(forward_used)[0]:.2f}–{span(forward_used)[1]:.2f} s); heading RMS {rms_heading(est.quat):.2f}°, "
          f"forward pass {rms_heading(forward):.2f}°")
    assert span(used)[0] == pytest.approx(200.0, abs=1.0) and span(used)[1] == pytest.approx(300.0, abs=1.0)
    assert np.abs(est.mag_offset[used] - [30.0, 0.0, 0.0]).max() < 1.0
    assert rms_heading(est.quat) < 0.5 * rms_heading(forward)


@pytest.mark.parametrize("case", ["put on at rest", "brought up while turning"])
def test_a_magnet_put_on_is_taken_however_it_arrives(case):
    """8 µT of hard iron (a small magnet a few centimetres away), put on 30 s into a minute
    at rest before the turning, or brought up over 10 s while the sensor turns, passing on
    its way through up to 27 µT more. The window forgets the field before once the latest
    samples leave its norm, at rest too, where no sphere about b can be told, or once it
    covers every direction and fits no sphere. So the offset is taken within 80 s of the
    turning or the arrival: 75 s and 71 s. Before either rule: 151 s, and never after the
    passage, with heading RMS 5.9° and 9.5°."""
    motion, _, _, mag = _turns_with_field(rest=(0.0, 60.0) if case == "put on at rest" else None, duration=400.0)
    t = np.arange(len(mag)) / FS
    offset = np.array([3.0, -5.0, 5.5])
    if case == "put on at rest":
        mag[t >= 30.0] += offset
        moving = 60.0
    else:
        moving = 200.0
        arrival = np.clip((t - moving) / 10.0, 0.0, 1.0)
        mag += arrival[:, None] * offset + np.sin(np.pi * arrival)[:, None] * [20.0, 10.0, -15.0]
    out, _, estimate_, _ = with_magnetometer(motion.quat, mag, FS)
    used = np.abs(estimate_).sum(axis=1) > 0
    taken = np.argmax(used) / FS
    heading = rms(np.degrees(quaternion_errors(out[t >= moving], motion.quat[t >= moving])[1]))
    print(f"8 µT {case}: taken {taken - moving:.1f} s after {moving:.0f} s, heading RMS from then {heading:.2f}°")
    assert used.any() and moving < taken < moving + 80.0
    assert np.abs(estimate_[-1] - offset).max() < 0.5  # µT
    assert heading < 3.0


def test_a_hard_iron_offset_survives_a_long_rest():
    """18 µT of hard iron, turning, 300 s still, turning again: at rest the field covers no
    directions, so it proves neither sphere and the offset taken before stays."""
    motion, _, _, mag = _turns_with_field(rest=(200.0, 500.0), duration=700.0)
    mag += [15.0, -5.0, 8.0]
    out, _, offset, _ = with_magnetometer(motion.quat, mag, FS)
    taken = int(np.argmax(np.abs(offset).sum(axis=1) > 0))
    heading = np.degrees(quaternion_errors(out, motion.quat)[1])
    assert taken < 20000 and np.abs(offset[taken:] - [15.0, -5.0, 8.0]).max() < 0.5
    assert heading[taken + int(5 * FS):].max() < 1.0


def _hard_iron_case():
    """240 s of the turning's true orientation and field, still for the first 30 s, with
    18 µT of hard iron put on at rest at 15–20 s (the window starts afresh at 20 s, with
    no directions) and taken off at 130–135 s through up to 27 µT more (the window that
    holds it fits no sphere and starts afresh at 155 s), and every third field sample
    missing: every branch of blocks.stages.hard_iron (taken at 105 s, dropped at 231 s)."""
    motion, _, _, mag = _turns_with_field(rest=(0.0, 30.0), duration=240.0)
    t = np.arange(len(mag)) / FS
    on, off = np.clip((t - 15.0) / 5.0, 0.0, 1.0), np.clip((t - 130.0) / 5.0, 0.0, 1.0)
    mag += (on - off)[:, None] * [15.0, -5.0, 8.0] + np.sin(np.pi * off)[:, None] * [20.0, 10.0, -15.0]
    mag[1::3] = np.nan
    return np.ascontiguousarray(motion.quat), mag


def test_hard_iron_put_on_at_rest_and_taken_off_through_a_stronger_field_is_taken_then_dropped():
    out, accepted, offset, _ = with_magnetometer(*_hard_iron_case(), FS)
    t = np.arange(len(offset)) / FS
    taken, dropped = t[np.argmax(offset.any(axis=1))], t[len(offset) - np.argmax(offset[::-1].any(axis=1))]
    print(f"hard iron taken at {taken:.1f} s as {offset[12000]}, dropped at {dropped:.1f} s")
    assert 60.0 < taken < 120.0 and 135.0 < dropped < 240.0 and not offset[-1].any()
    assert np.abs(offset[12000] - [15.0, -5.0, 8.0]).max() < 0.5 and np.isfinite(out).all()


@pytest.mark.parametrize("bad, message", [
    (lambda m: m[:-1], "must have the shape"),
    (lambda m: np.where(np.arange(len(m))[:, None] == 7, np.inf, m), "3 infinite values"),
    (lambda m: np.full_like(m, np.nan), "no sample without NaN"),
])
def test_magnetometer_input_errors_say_what_is_wrong(bad, message):
    gyr, acc = np.zeros((50, 3)), np.tile([0.0, 0.0, 9.81], (50, 1))
    with pytest.raises(ValueError, match=message):
        estimate(gyr, acc, FS, mag=bad(np.tile(EARTH_FIELD_UT, (50, 1)).astype(float)), gyro_offset=False)


def test_heading_and_tilt_start_in_motion():
    """A recording whose first samples are in vigorous motion (the first accelerometer
    sample is 28° off the vertical): the start-up means of the tilt filter and of the
    heading estimator settle, and no disturbance guard locks onto the bad start."""
    motion = HumanMotion(delta_v=1.0).generate(200.0, FS, seed=1)
    gyr, acc = ImuModel(delta_n=math.radians(0.05), acc_noise=0.002).apply(motion, seed=6)
    start = int(30 * FS)  # cut into the motion
    est = estimate(gyr[start:], acc[start:], FS, mag=motion.mag[start:], gyro_offset=False)
    _, heading, inclination = (np.degrees(e) for e in quaternion_errors(est.quat, motion.quat[start:]))
    settled = int(30 * FS)
    assert inclination[0] > 20.0
    print(f"after 30 s: heading RMS {rms(heading[settled:]):.2f}°, inclination RMS {rms(inclination[settled:]):.2f}°")
    assert rms(heading[settled:]) < 1.0
    assert rms(inclination[settled:]) < 1.0


def test_plot_writes_the_errors_or_without_a_reference_the_estimates_angles(tmp_path, capsys):
    motion = ClosedFormMotion(lambda t: Rotation.from_euler("ZY", np.column_stack([
        0.8 * np.sin(0.5 * t), 0.5 * np.sin(0.3 * t)]))).generate(60.0, FS)
    _broad_like(tmp_path / "a.mat", motion)
    out = tmp_path / "a.png"
    assert main(["plot", str(tmp_path / "a.mat"), "--method", "wiener", "--out", str(out),
                 "--param", "delta_v=2", "--param", "rest_time=3"]) == 0  # the filter's and the offset estimator's
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # with the recording's magnetometer the heading error too, as attitude evaluate measures it
    errors = evaluate_recording(read_recording(tmp_path / "a.mat"), params={"delta_v": 2.0, "rest_time": 3.0})["wiener"]
    assert (f"inclination RMSE {errors['inclination_rmse_deg']:.2f}°, "
            f"heading RMSE {errors['heading_rmse_deg']:.2f}°") in capsys.readouterr().err
    assert main(["plot", str(tmp_path / "a.mat"), "--out", str(out), "--heading", "gyro"]) == 0
    assert "heading RMSE" not in capsys.readouterr().err
    _broad_like(tmp_path / "b.mat", motion, quat_ref=False)
    for flags in ([], ["--heading", "gyro", "--gyro-offset", "off"]):  # three panels, two
        (tmp_path / "b.png").unlink(missing_ok=True)
        assert main(["plot", str(tmp_path / "b.mat"), "--out", str(tmp_path / "b.png"), *flags]) == 0
        assert "no reference to measure errors against: the estimate's roll, pitch and yaw" in capsys.readouterr().err
        assert (tmp_path / "b.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
