"""A sensor turned about a fixed centre: offline (blocks.stages.lever_arm) and online (the gyro-offset
stage's fit, blocks.stages.gyro_offset). Against a pendulum in closed form (its specific force
Rᵀ·g + α×r + ω×(ω×r), its gyro the exact interval means of its rate), the robot_arm scenario (its
lever arm 0.3 m along x) and vqf on it."""
import math

import numpy as np
import pytest
import vqf
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu import _core
from attitude_fmu.blocks.stages import gyro_offset, lever_arm
from attitude_fmu.systems.evaluation.evaluate import errors_on_movement
from attitude_fmu.systems.simulation.scenarios import LEVER_M, scenario

FS = 100.0  # Hz
G = 9.81  # m/s²
ARM = np.array([0.0, 0.05, -0.4])  # m: the sensor from the pivot, sensor coordinates (x along the pivot's axis)


def _pendulum(duration: float = 120.0, pivot_shake: float = 0.0, seed: int = 0, fs: float = FS,
              gyro_noise: float = 0.01):
    """(gyr, acc, gravity in sensor coordinates) of a pendulum swinging about x, θ(t) = 0.6·sin(2.1·t) +
    0.3·sin(3.7·t) rad, at fs (Hz) with white noise (gyro gyro_noise °/s/√Hz, accelerometer 0.01 m/s² per
    sample); pivot_shake (m/s²): the pivot's own acceleration, three sines in the earth frame."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration * fs)) / fs

    def angle(tt):
        return 0.6 * np.sin(2.1 * tt) + 0.3 * np.sin(3.7 * tt)

    rate = 0.6 * 2.1 * np.cos(2.1 * t) + 0.3 * 3.7 * np.cos(3.7 * t)
    turn = -0.6 * 2.1**2 * np.sin(2.1 * t) - 0.3 * 3.7**2 * np.sin(3.7 * t)
    zero = np.zeros_like(t)
    w, a = np.column_stack([rate, zero, zero]), np.column_stack([turn, zero, zero])
    R = Rotation.from_rotvec(np.column_stack([angle(t), zero, zero]))
    gravity = R.inv().apply([0.0, 0.0, G])
    shake = pivot_shake * np.column_stack([np.sin(1.3 * t), np.sin(2.9 * t + 1.0), np.sin(0.7 * t + 2.0)])
    acc = gravity + np.cross(a, ARM) + np.cross(w, np.cross(w, ARM)) + R.inv().apply(shake)
    gyr = np.column_stack([(angle(t) - angle(t - 1.0 / fs)) * fs, zero, zero])  # the interval means, exactly
    gyr += rng.normal(0.0, math.radians(gyro_noise) * math.sqrt(fs / 2.0), gyr.shape)
    return gyr, acc + rng.normal(0.0, 0.01, acc.shape), gravity


def test_a_pendulum_s_arm_is_found_and_its_accelerations_removed():
    """The arm across the axis within 2 mm (along the axis no acceleration shows it, nor moves it), the fit
    explaining over 99 % of the specific force beside gravity, and what is left of it after the correction,
    over 0.2 s (the white noise the gyro's differences add is no tilt filter's band), under 3 % of the
    swing's accelerations."""
    gyr, acc, gravity = _pendulum()
    found = lever_arm.fit(gyr, acc, FS)
    assert found is not None and found.explained > 0.99
    assert np.abs(found.position[1:] - ARM[1:]).max() < 0.002

    def rms_over(x, samples=round(0.2 * FS)):
        means = np.stack([np.convolve(column, np.ones(samples) / samples, "valid") for column in x.T], axis=1)
        return np.sqrt(np.mean(np.sum(means**2, axis=1)))

    swing, left = rms_over(acc - gravity), rms_over(found.corrected(gyr, acc, FS) - gravity)
    assert swing > 1.0 and left < 0.03 * swing


@pytest.mark.parametrize("fs", [400.0, 1000.0])
def test_a_fast_sampled_pendulum_with_a_consumer_gyro_is_found_as_well(fs):
    """At 400 Hz and 1 kHz with a consumer gyro's noise (0.01 °/s/√Hz): ω and α from the gyro's means over
    10 ms either side of a sample, not one sample's difference, whose noise would outweigh the swing's α
    (over one sample the fit explains 81 % at 400 Hz and 21 % at 1 kHz, and finds 0.81 and 0.21 of the
    arm: nothing is taken). The arm within 3 mm."""
    gyr, acc, _ = _pendulum(fs=fs)
    found = lever_arm.fit(gyr, acc, fs)
    assert found is not None and found.explained > 0.95
    assert np.abs(found.position[1:] - ARM[1:]).max() < 0.003


def test_a_pivot_that_moves_is_not_taken_for_a_fixed_centre():
    """The same pendulum on a pivot shaken at 2 m/s²: the arm no longer explains the motion, and nothing is
    taken (the recording's accelerometer is left as it is)."""
    assert lever_arm.fit(*_pendulum(pivot_shake=2.0)[:2], FS) is None


def test_rest_alone_takes_nothing():
    """At rest (noise only) the windows leave noise that no rotation explains."""
    rng = np.random.default_rng(1)
    gyr = rng.normal(0.0, 1e-3, (6000, 3))
    acc = np.array([0.0, 0.0, G]) + rng.normal(0.0, 0.01, (6000, 3))
    assert lever_arm.fit(gyr, acc, FS) is None


def test_offline_frees_a_robot_wrist_of_its_lever_arm():
    """robot_arm (the IMU 0.3 m out along x): the offline estimate finds the arm within 5 mm and its
    inclination is under half vqf_offline's (without the fit, as on fdb92fb: 0.036° against 0.060°;
    with it 0.010°). The online estimate has no offline fit (its own is the gyro-offset stage's)."""
    rec = scenario("robot_arm").recording(name="robot_arm")
    gyr, acc = (np.ascontiguousarray(a, dtype=float) for a in (rec.gyr, rec.acc))
    est = estimate(gyr, acc, rec.fs, offline=True)
    assert est.lever_arm is not None
    assert np.abs(est.lever_arm.position - [LEVER_M, 0.0, 0.0]).max() < 0.005
    peer = vqf.offlineVQF(gyr, acc, None, 1.0 / rec.fs)["quat6D"]
    ours, theirs = (errors_on_movement(q, rec)["inclination_rmse_deg"] for q in (est.quat, peer))
    assert ours < 0.5 * theirs and ours < 0.02
    assert estimate(gyr, acc, rec.fs).lever_arm is None


@pytest.mark.parametrize("name", ["segment_40hz", "tactical_handheld"])
def test_human_motion_keeps_its_accelerometer(name):
    """Human motion (a lever arm on a centre that moves itself, in tactical_handheld): nothing is taken."""
    rec = scenario(name).recording(name=name, mag=False)
    assert estimate(rec.gyr, rec.acc, rec.fs, offline=True).lever_arm is None


def test_attitude_estimate_offline_says_what_it_took(tmp_path, capsys):
    """`attitude estimate --offline` on the simulated robot_arm prints the arm it took, and online nothing."""
    from attitude_fmu.systems.cli.commands import main

    source, out = tmp_path / "robot.csv", tmp_path / "estimate.csv"
    assert main(["simulate", "--scenario", "robot_arm", "--out", str(source)]) == 0
    assert main(["estimate", str(source), "--offline", "--out", str(out)]) == 0
    assert "lever arm taken: the sensor turns about a fixed centre from which it sits at (0.29" in capsys.readouterr().err
    assert main(["estimate", str(source), "--out", str(out)]) == 0
    assert "lever arm" not in capsys.readouterr().err


def _online(gyr, acc, fs=FS):
    """The gyro-offset stage's causal pass: (the accelerometer it hands on, its lever arm at the end, m)."""
    gyr, acc = (np.ascontiguousarray(a, dtype=float) for a in (gyr, acc))
    coef = gyro_offset.coefficients(gyro_offset.resolve(), 1.0 / fs)
    state, freed = gyro_offset.initial_state(coef, gyr[0], acc[0]), np.empty_like(acc)
    _core.gyro_offset_run(state, coef, gyr, acc, np.empty_like(gyr), np.empty_like(gyr), acc_out=freed)
    names = list(gyro_offset.STATE_NAMES)
    return freed, state[[names.index(f"arm_{a}") for a in "xyz"]]


def test_online_a_pendulum_s_arm_is_found_and_its_accelerations_removed():
    """Causally (the fit's sums forgetting over tau_arm, 30 s): after two minutes the arm across the axis
    within 5 mm; over the last minute what is left of the accelerations beside gravity, over 0.2 s, under
    5 % of the swing's (ω and α from one sample's difference: its noise is no tilt filter's band)."""
    gyr, acc, gravity = _pendulum()
    freed, arm = _online(gyr, acc)
    assert np.abs(arm[1:] - ARM[1:]).max() < 0.005
    last = slice(-round(60 * FS), None)

    def rms_over(x, samples=round(0.2 * FS)):
        means = np.stack([np.convolve(column, np.ones(samples) / samples, "valid") for column in x.T], axis=1)
        return np.sqrt(np.mean(np.sum(means**2, axis=1)))

    swing, left = rms_over((acc - gravity)[last]), rms_over((freed - gravity)[last])
    assert swing > 1.0 and left < 0.05 * swing


@pytest.mark.parametrize("case", ["moving pivot", "rest with an offset", "abrupt onset"])
def test_online_nothing_is_taken_where_no_fixed_centre_shows(case):
    """The pendulum on a pivot shaken at 2 m/s²; five minutes at rest with a gyro offset of 0.2 °/s
    (the frame the gyro integrates turns slowly under gravity, a drift no arm explains; a fit taking it
    found an arm of 2 km); a calibrated sensor's quiet rest, then human motion from one sample to the next
    (the fit on that one sample found an arm of 2.2 m, and removed up to 294 m/s² after): the
    accelerometer is handed on exactly as measured."""
    if case == "moving pivot":
        gyr, acc, _ = _pendulum(pivot_shake=2.0)
    elif case == "abrupt onset":
        from attitude_fmu.systems.simulation.recording import SENSORS, simulate_recording

        rec = simulate_recording(FS, 120.0, 10.0, SENSORS["calibrated"], seed=0, mag=False)
        gyr, acc = rec.gyr, np.ascontiguousarray(rec.acc, dtype=float)
    else:
        rng = np.random.default_rng(3)
        gyr = np.radians([0.2, -0.1, 0.15]) + rng.normal(0.0, 1e-3, (30000, 3))
        acc = np.array([0.0, 0.0, G]) + rng.normal(0.0, 0.01, (30000, 3))
    freed, arm = _online(gyr, acc)
    assert np.array_equal(freed, acc) and np.array_equal(arm, np.zeros(3))


def test_online_a_robot_wrist_is_ahead_of_vqf_in_every_cell():
    """robot_arm, scored as the results page scores it: online inclination, 6D and 9D heading at or ahead
    of vqf's. On 8b5f3f5 (no online arm; a rest's offset measured from each raw gyro sample) 0.19° against
    0.18°, 0.47° against 0.05° and 0.05° against 0.04°."""
    from attitude_fmu.systems.evaluation.scenarios import score

    cells = score("robot_arm")
    print({column: {k: round(v, 4) for k, v in cell.items()} for column, cell in cells.items()})
    for column in ("inclination online", "heading 6D", "heading 9D"):
        assert cells[column]["ours"] <= cells[column]["vqf"], column


def test_the_core_refuses_what_it_cannot_fit():
    """The C core's entry points check their inputs before use: rows that disagree, no row, a sample time
    that is no positive number, a span or a window of no sample, an output of another length."""
    from attitude_fmu import _core

    gyr, acc = np.zeros((4, 3)), np.tile([0.0, 0.0, G], (4, 1))
    with pytest.raises(ValueError, match="acc"):
        _core.lever_arm_sums(gyr, acc[:3], 0.01, 1, 2)
    with pytest.raises(ValueError, match="a sample or more"):
        _core.lever_arm_sums(gyr[:0], acc[:0], 0.01, 1, 2)
    for Ts in (0.0, -0.01, math.nan, math.inf):
        with pytest.raises(ValueError, match="Ts must be"):
            _core.lever_arm_sums(gyr, acc, Ts, 1, 2)
        with pytest.raises(ValueError, match="Ts must be"):
            _core.lever_arm_removed(gyr, acc, Ts, 1, np.zeros(3), np.empty((4, 3)))
    with pytest.raises(ValueError, match="window"):
        _core.lever_arm_sums(gyr, acc, 0.01, 1, 0)
    with pytest.raises(ValueError, match="span"):
        _core.lever_arm_sums(gyr, acc, 0.01, 0, 2)
    with pytest.raises(ValueError, match="span"):
        _core.lever_arm_removed(gyr, acc, 0.01, 0, np.zeros(3), np.empty((4, 3)))
    with pytest.raises(ValueError, match="out"):
        _core.lever_arm_removed(gyr, acc, 0.01, 1, np.zeros(3), np.empty((3, 3)))
