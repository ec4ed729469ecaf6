"""Motions, sensor model and the closed-loop diagram against exact truth."""
import math

import control
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu import profile
from attitude_fmu.blocks.errors import inclination_error
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.stages import gyro_offset
from attitude_fmu.blocks.stages.heading import with_magnetometer
from attitude_fmu.blocks.stages.timing import carry_forward_rows
from attitude_fmu.systems.simulation.diagram import simulate_closed_loop
from attitude_fmu.systems.simulation.motion import EARTH_FIELD_UT, PROFILES, HumanMotion
from attitude_fmu.systems.simulation.noise import MOTION, SENSOR, normals
from attitude_fmu.systems.simulation.sensor_model import ImuModel


@pytest.mark.parametrize("grid", [None, 1e-3])  # a cell per sample; the profile's grid, 10 cells a sample
def test_human_motion_truth_is_exact_and_has_the_eq14_velocity_spectrum(grid):
    motion = HumanMotion(delta_v=1.5, omega_c=8.0, grid=grid).generate(4000.0, 100.0, seed=2)
    rot = Rotation.from_quat(motion.quat, scalar_first=True)
    # the gyro sample is the rate that turns the orientation over its interval: re-integrating gives the truth
    # (on the grid, to the rounding of the times, 4.5e-13 s at 4000 s, where the cells' ends fall)
    turns = (rot[:-1].inv() * rot[1:]).as_rotvec()
    assert np.abs(turns - motion.gyr[1:] / 100.0).max() < (1e-14 if grid is None else 1e-11)
    # earth-frame specific force minus gravity, integrated, is the velocity: variance δv²ω_c/4
    velocity = np.cumsum(rot.apply(motion.acc) - [0, 0, 9.81], axis=0) / 100.0
    assert np.var(velocity, axis=0) == pytest.approx(np.full(3, 1.5**2 * 8.0 / 4), rel=0.08)
    assert motion.gyr.std(axis=0) == pytest.approx(np.ones(3), rel=0.1)


def test_sensor_model_noise_density_and_offsets():
    motion = HumanMotion().generate(1000.0, 200.0, seed=1)
    dn = math.radians(0.1)
    model = ImuModel(delta_n=dn, gyr_offset=(0.01, -0.02, 0.03), acc_noise=0.002, acc_offset=(1, 1, 1))
    gyr, acc = model.apply(motion)
    for error, density, offset in ((gyr - motion.gyr, dn, [0.01, -0.02, 0.03]), (acc - motion.acc, 0.002, [1, 1, 1])):
        # one-sided density at 200 Hz: per-sample s.d. density·√(fs/2)
        sd = density * math.sqrt(100.0)
        assert error.mean(axis=0) == pytest.approx(offset, abs=4 * sd / math.sqrt(len(error)))
        assert error.std(axis=0) == pytest.approx(np.full(3, sd), rel=0.01)
    with pytest.raises(ValueError):
        ImuModel(delta_n=-1.0)


def test_sensor_model_scale_and_misalignment():
    """Without noise the gyro reads (I + S)·ω: S·ω is exactly what it adds."""
    motion = HumanMotion().generate(10.0, 100.0, seed=2)
    S = ((0.01, -0.002, 0.0), (0.003, 0.0, 0.005), (0.0, 0.0, -0.02))
    gyr, _ = ImuModel(gyr_scale=S).apply(motion)
    for i in range(3):
        added = sum(S[i][j] * motion.gyr[:, j] for j in range(3))
        assert np.abs(gyr[:, i] - motion.gyr[:, i] - added).max() < 1e-15
    with pytest.raises(ValueError, match="gyr_scale"):
        ImuModel(gyr_scale=((0.0, 0.0), (0.0, 0.0)))


def test_steady_lever_arm_closed_form():
    m = profile("lever_arm").motion({"rate": 2.0, "radius": 0.2}, g=9.81).generate(10.0, 100.0)
    rot = Rotation.from_quat(m.quat, scalar_first=True)
    assert np.abs((rot[:-1].inv() * rot[1:]).as_rotvec() - m.gyr[1:] / 100.0).max() < 1e-12
    # specific force in sensor coordinates is constant: gravity plus Ω²r = 0.8 m/s² towards the
    # axis, averaged over each sample interval (a chord of the velocity circle)
    assert np.ptp(m.acc, axis=0).max() < 1e-12
    chord = 0.2 * 2.0 * 2 * math.sin(2.0 * 0.01 / 2) / 0.01
    assert np.linalg.norm(rot.apply(m.acc)[0] - [0, 0, 9.81]) == pytest.approx(chord, rel=1e-12)


def test_incline_motion_has_zero_mean_acceleration_and_the_stated_peak():
    m = profile("incline").motion(g=9.81).generate(10.0, 1000.0)
    earth = Rotation.from_quat(m.quat, scalar_first=True).apply(m.acc) - [0, 0, 9.81]
    assert np.abs(earth.mean(axis=0)).max() < 1e-9
    assert np.linalg.norm(earth, axis=1).max() == pytest.approx(math.sqrt(2) * 9.81, rel=1e-4)
    assert np.allclose(earth[:, 1], 0) and np.allclose(earth[:, 0], earth[:, 2])  # along the 45° slope


@pytest.mark.parametrize("method", ["wiener", "luinge"])
def test_closed_loop_diagram_equals_the_batch_pipeline(method):
    motion = HumanMotion()
    imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.01, 0.0, -0.01), acc_noise=0.01)
    fs = 100.0
    noise, resp = simulate_closed_loop(motion, imu, fs, duration=5.0, method=method, seed=3, gyro_offset=False)
    assert np.array_equal(noise, np.hstack([normals(3, MOTION, 500), normals(3, SENSOR, 500)]))
    truth = motion.generate(5.0, fs, seed=3)  # the motion of the same noise
    gyr, acc = imu.apply(truth, seed=3)
    est = estimate(gyr, acc, fs, method, initial_gravity=[0, 0, motion.g], gyro_offset=False)
    up = truth.up
    assert np.abs(resp.outputs[1:4].T - est.gravity).max() <= 1e-12
    assert np.abs(resp.outputs[4:8].T - est.quat).max() <= 1e-12
    assert np.abs(resp.outputs[0] - inclination_error(est.gravity, up)).max() <= 1e-12


@pytest.mark.parametrize("params, latency, mag_errors", [
    ({}, 0.0, {}),
    ({"delta_n": math.radians(0.3), "rest_time": 1.0, "tau_heading": 2.0}, 0.015,
     {"mag_noise": 0.5, "mag_offset": (8.0, -3.0, 12.0)}),
])
def test_closed_loop_diagram_with_offset_and_heading_blocks_equals_the_stages_run_one_by_one(params, latency,
                                                                                              mag_errors):
    """motion → sensor → gyro-offset estimator → wiener → heading stage (fed by the
    magnetometer block, ideal or with noise and hard iron) → latency stage, interconnected
    python-control blocks: the same numbers as each stage run alone in turn over the
    sensor's samples (the offset estimator's block, its low-passes at rest on g·ẑ as the
    diagram starts it; the batch path; with_magnetometer; carry_forward_rows), with the
    defaults and with parameters of every stage; with a latency, the sensor's delay line (at
    rest, level before the start) as well."""
    motion = HumanMotion()
    imu = ImuModel(delta_n=math.radians(0.1), gyr_offset=(0.01, 0.0, -0.01), acc_noise=0.01, latency=latency,
                   **mag_errors)
    fs = 100.0
    noise, resp = simulate_closed_loop(motion, imu, fs, duration=5.0, params=params, seed=3, heading=True,
                                       latency=latency)
    noise_density = {k: v for k, v in params.items() if k == "delta_n"}  # the filter's and the offset estimator's
    offset_params = {**noise_density, **{k: v for k, v in params.items() if k == "rest_time"}}
    heading_params = {k: v for k, v in params.items() if k == "tau_heading"}
    truth = motion.generate(5.0, fs, seed=3)  # the motion of the same noise
    signals = imu.delayed(truth.gyr, truth.acc, fs, before=[0.0, 0.0, 0.0, 0.0, 0.0, motion.g])
    gyr, acc = imu.measure(*signals, noise[:, 6:12], fs)
    dt, t = 1.0 / fs, np.arange(len(gyr)) / fs  # the offset estimator alone, started as the diagram starts it
    x0 = gyro_offset.initial_state(gyro_offset.coefficients(gyro_offset.resolve(offset_params), dt), np.zeros(3),
                                   [0.0, 0.0, motion.g])
    offset = control.input_output_response(gyro_offset.offset_system(dt, offset_params), t, np.hstack([gyr, acc]).T,
                                           X0=x0).outputs[3:6].T
    est = estimate(gyr - offset, acc, fs, params=noise_density, initial_gravity=[0, 0, motion.g], gyro_offset=False)
    mag = imu.measure_mag(Rotation.from_quat(truth.quat, scalar_first=True).inv().apply(EARTH_FIELD_UT),
                          noise[:, 12:15], fs)
    quat, _, mag_offset, _ = with_magnetometer(est.quat, mag, fs, heading_params)
    out = dict(zip(resp.output_labels, resp.outputs))
    assert np.abs(np.column_stack([out[f"ghat_{c}"] for c in "xyz"]) - est.gravity).max() <= 1e-12
    assert np.abs(np.column_stack([out[f"qh_{c}"] for c in "wxyz"]) - quat).max() <= 1e-12
    assert np.abs(np.column_stack([out[f"mag_offset_{c}"] for c in "xyz"]) - mag_offset).max() == 0.0
    assert np.abs(quat - est.quat).max() > 1e-3  # the heading stage turned the estimate
    if latency:
        gravity = est.gravity.copy()
        carry_forward_rows(quat, gravity, gyr - offset, latency)
        assert np.abs(np.column_stack([out[f"ql_{c}"] for c in "wxyz"]) - quat).max() <= 1e-12
        assert np.abs(np.column_stack([out[f"ghatl_{c}"] for c in "xyz"]) - gravity).max() <= 1e-12
    else:
        assert "ql_w" not in out


@pytest.mark.parametrize("samples", [2.0, 0.8, 3.3])
def test_a_late_sensor_measures_the_motion_that_long_ago(samples):
    """ImuModel's delay line: a whole number of samples late, the signals are the motion's
    shifted by that many samples, exactly; between samples, within 1e-4 rad/s and 1e-3 m/s²
    of the closed-form motion's means over the interval that long ago (the line takes
    them constant within each sample)."""
    fs = 100.0
    closed = PROFILES["sine_rotation"].motion({"inclination_deg": 20.0})
    motion = closed.generate(30.0, fs)
    latency = samples / fs
    gyr, acc = ImuModel(latency=latency).delayed(motion.gyr, motion.acc, fs)
    if samples.is_integer():
        n = int(samples)
        assert (gyr[n:] == motion.gyr[:-n]).all() and (acc[n:] == motion.acc[:-n]).all()
        assert (gyr[:n] == motion.gyr[0]).all()  # before the start: the first sample
    t = np.arange(1, len(motion.gyr) + 1) / fs
    late_gyr, late_acc, _ = closed.at(t - latency, 1.0 / fs)
    start = int(np.ceil(samples)) + 1
    assert np.abs(gyr[start:] - late_gyr[start:]).max() < 1e-4
    assert np.abs(acc[start:] - late_acc[start:]).max() < 1e-3
