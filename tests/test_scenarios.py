"""systems.simulation.scenarios: each scenario makes its recording (at any duration) and shows the failure
mode it stands for, against independent truth: scipy's rotations of the reference and the earth's field,
the sensor model's drawn errors, the noise densities' per-sample s.d., g."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.simulation.motion import profile
from attitude_fmu.systems.simulation.profile_table import EARTH_FIELD_UT
from attitude_fmu.systems.simulation.recording import DEFAULT_MOTION, SENSORS
from attitude_fmu.systems.simulation.scenarios import SCENARIOS, scenario

UP = np.array([0.0, 0.0, STANDARD_GRAVITY])  # the specific force at rest, level, m/s²


def _short(name, duration=20.0, **changes):
    """The scenario's recording of duration s of motion (its own rest)."""
    return replace(SCENARIOS[name], duration=duration, **changes).recording(name)


def _field(rec) -> np.ndarray:
    """The earth's field in the sensor (N×3, µT), by scipy from the reference."""
    return Rotation.from_quat(rec.quat_ref, scalar_first=True).inv().apply(EARTH_FIELD_UT)


def _earth_acceleration(rec) -> np.ndarray:
    """The accelerometer turned into the earth frame by the reference, less g up (N×3, m/s²)."""
    return Rotation.from_quat(rec.quat_ref, scalar_first=True).apply(rec.acc) - UP


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_every_scenario_makes_its_recording(name):
    """At its rate, its rest (movement 0) then its motion, finite, the reference unit quaternions that the
    gyro turns (within its noise, offset and scale error: at most 5 % of the turn plus the offset's);
    the same seed the same recording."""
    s = SCENARIOS[name]
    rec = _short(name, 10.0)
    still = round(s.rest * s.fs)
    assert rec.fs == s.fs and len(rec.t) == still + round(10.0 * s.fs)
    assert np.count_nonzero(~rec.movement) == still and rec.movement[still:].all()
    assert all(np.isfinite(x).all() for x in (rec.gyr, rec.acc, rec.mag, rec.quat_ref))
    assert np.abs(np.linalg.norm(rec.quat_ref, axis=1) - 1.0).max() < 1e-12
    turn = Rotation.from_quat(rec.quat_ref, scalar_first=True)
    true_rate = (turn[:-1].inv() * turn[1:]).as_rotvec() * s.fs
    offset = np.linalg.norm(s.sensor.model(s.seed).gyr_offset)
    error = np.linalg.norm(rec.gyr[1:] - true_rate, axis=1)
    assert np.median(error) < 0.05 * np.median(np.linalg.norm(true_rate, axis=1)) + offset + 0.01
    again = _short(name, 10.0)
    assert np.array_equal(again.gyr, rec.gyr) and np.array_equal(again.mag, rec.mag)


def test_an_unknown_scenario_is_refused_naming_those_there_are():
    with pytest.raises(ValueError, match=r"unknown scenario 'phone'; available: phone_flat, phone_running, "):
        scenario("phone")


def _rest_mean_matches(rec, s, expected):
    """The gyro's mean over the rest is expected (rad/s, 3) within 4 standard errors of its white noise."""
    still = ~rec.movement
    se = math.radians(s.sensor.gyro_noise_dps) * math.sqrt(s.fs / 2.0) / math.sqrt(np.count_nonzero(still))
    assert np.abs(rec.gyr[still].mean(axis=0) - expected).max() < 4 * se


def test_phone_flat_has_its_offset_on_z_and_soft_iron_in_its_field():
    """At rest the gyro reads 4 °/s on z alone; the phone stays within a few degrees of flat. The
    magnetometer's norm is that of (I + S_m)·m with S_m the drawn symmetric soft iron (element rms
    about 0.06) and m the earth's field by scipy: its mean within 0.05 µT (the noise's bias σ²/|m| is
    0.01 µT), and away from |m| by more than a µT (what the soft iron does)."""
    s = SCENARIOS["phone_flat"]
    rec = _short("phone_flat", 60.0)
    _rest_mean_matches(rec, s, [0.0, 0.0, math.radians(4.0)])
    tilt = np.degrees(np.arccos(Rotation.from_quat(rec.quat_ref, scalar_first=True).inv().apply([0, 0, 1.0])[:, 2]))
    assert tilt.max() < 5.0
    soft = np.array(s.sensor.model(s.seed).mag_soft_iron)
    assert np.array_equal(soft, soft.T) and 0.03 < np.sqrt(np.mean(soft**2)) < 0.1
    m = _field(rec)
    predicted = np.linalg.norm(m @ (np.eye(3) + soft).T, axis=1)
    measured = np.linalg.norm(rec.mag, axis=1)
    assert abs(np.mean(measured - predicted)) < 0.05
    assert abs(np.mean(predicted) - np.linalg.norm(EARTH_FIELD_UT)) > 1.0


def test_phone_running_has_strong_impacts_and_an_offset_on_every_axis():
    """At rest 4 °/s on each axis; in motion the accelerometer sees impacts of (1 + 2.5) g along the
    vertical at 2.7 steps a second (the strongest line of the vertical acceleration's spectrum)."""
    s = SCENARIOS["phone_running"]
    rec = _short("phone_running", 30.0)
    _rest_mean_matches(rec, s, np.full(3, math.radians(4.0)))
    vertical = _earth_acceleration(rec)[rec.movement, 2]
    assert vertical.max() > 2.3 * STANDARD_GRAVITY and np.linalg.norm(rec.acc, axis=1).max() > 3.2 * STANDARD_GRAVITY
    spectrum = np.abs(np.fft.rfft(vertical - vertical.mean()))
    assert np.fft.rfftfreq(len(vertical), 1.0 / s.fs)[np.argmax(spectrum)] == pytest.approx(2.7, abs=0.05)


def test_tactical_handheld_starts_moving_and_feels_its_lever_arm():
    """No rest: moving from the first sample; a gyro offset of 0.04 °/s. The motion's specific force
    with the 0.3 m lever arm less the one without (the same seed) is ω×(ω×r) + α×r with α the rate's
    finite difference (the rate steps once a sample: grid = 1/fs), to first order in the sample time
    (within 2 % of its scale)."""
    s = SCENARIOS["tactical_handheld"]
    rec = _short("tactical_handheld", 10.0)
    assert rec.movement.all()
    assert np.linalg.norm(s.sensor.model(s.seed).gyr_offset) == pytest.approx(math.radians(0.04), rel=1e-12)
    params = {**DEFAULT_MOTION, **s.motion}
    lever = np.array([params["lever_x"], params.get("lever_y", 0.0), params.get("lever_z", 0.0)])
    assert np.linalg.norm(lever) == pytest.approx(0.3)
    moved = profile("human").motion(params).generate(10.0, s.fs, s.seed)
    fixed = profile("human").motion({**params, "lever_x": 0.0}).generate(10.0, s.fs, s.seed)
    w = moved.gyr
    alpha = np.diff(np.vstack([np.zeros(3), w]), axis=0) * s.fs
    first_order = np.cross(w, np.cross(w, lever)) + np.cross(alpha, lever)
    assert np.abs(moved.acc - fixed.acc - first_order).max() < 0.02 * np.abs(first_order).max()
    assert np.abs(first_order).max() > 1.0  # m/s²: the lever arm shows


def test_robot_arm_turns_fast_with_little_linear_acceleration():
    """At 125 Hz: turns faster than 100 °/s, while the accelerometer turned into the earth frame by the
    reference differs from g up by less than a tenth of g rms (a fifth at most), noise included."""
    rec = _short("robot_arm", 30.0)
    assert rec.fs == 125.0 and np.degrees(np.linalg.norm(rec.gyr, axis=1)).max() > 100.0
    a = np.linalg.norm(_earth_acceleration(rec), axis=1)
    assert np.sqrt(np.mean(a**2)) < 0.1 * STANDARD_GRAVITY and a.max() < 0.2 * STANDARD_GRAVITY


def test_segment_40hz_has_soft_and_hard_iron():
    """At 40 Hz, the consumer sensor; the magnetometer is (I + S_m)·m + b + noise with m the earth's field by
    scipy, S_m (element rms about 0.04) and |b| = 2 µT as drawn: the residual's mean within 4 standard errors
    of 0, its s.d. the noise's per-sample one, mag_noise·√(fs/2), within 5 %."""
    s = SCENARIOS["segment_40hz"]
    rec = _short("segment_40hz", 120.0)
    imu = s.sensor.model(s.seed)
    soft, hard = np.array(imu.mag_soft_iron), np.array(imu.mag_offset)
    assert rec.fs == 40.0 and np.linalg.norm(hard) == pytest.approx(2.0, rel=1e-12)
    assert 0.015 < np.sqrt(np.mean(soft**2)) < 0.08
    residual = rec.mag - _field(rec) @ (np.eye(3) + soft).T - hard
    sd = s.sensor.mag_noise * math.sqrt(s.fs / 2.0)
    assert np.abs(residual.mean(axis=0)).max() < 4 * sd / math.sqrt(len(residual))
    assert residual.std(axis=0) == pytest.approx(np.full(3, sd), rel=0.05)
    assert replace(s.sensor, mag_soft_iron=0.0, mag_hard_iron_ut=0.0) == SENSORS["consumer"]
