"""The sensor-frame estimator blocks: linearisation, exactness, and one step behind
the continuous block, the discrete block and the batch path."""
import math

import control
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.errors import inclination_error
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.filters.sensor_frame import initial_state, sensor_frame_system, start_gravity
from attitude_fmu.blocks.methods.registry import method
from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.simulation.motion import HumanMotion

FILTERS = {
    "eq34": ef.butterworth(0.13),
    "eq33": ef.wiener_band_limited(0.13, 0.5),
    "first_order": ef.first_order(0.05),
}


@pytest.mark.parametrize("name", FILTERS)
def test_linearising_the_continuous_estimator_at_rest_gives_the_earth_filter_per_axis(name):
    filt = FILTERS[name]
    sys_c = sensor_frame_system(filt)
    lin = control.linearize(sys_c, np.zeros(sys_c.nstates), np.zeros(6))
    for w in np.logspace(-3, 2, 11):
        resp = np.asarray(lin(1j * w))  # 3 outputs × 6 inputs
        expected = complex(filt(1j * w))
        for axis in range(3):
            assert abs(resp[axis, 3 + axis] - expected) < 1e-9
        off = resp.copy()
        off[[0, 1, 2], [3, 4, 5]] = 0
        assert np.abs(off).max() < 1e-9


def _random_imu(n=400, seed=3):
    rng = np.random.default_rng(seed)
    gyr = rng.normal(0, 2.0, (n, 3))
    gyr[::50] *= 20  # a few fast samples beyond the small-angle series
    return gyr, rng.normal(0, 3.0, (n, 3)) + [0, 0, 9.81]


@pytest.mark.parametrize("name", ["wiener", "first_order"])
def test_discrete_block_and_batch_path_are_equal(name):
    fs = 100.0
    gyr, acc = _random_imu()
    filt = method(name).filter()
    block = sensor_frame_system(filt, dt=1 / fs)
    t = np.arange(len(gyr)) / fs
    x0 = initial_state(filt, 1 / fs, start_gravity(gyr[0], acc[0], 1 / fs))
    resp = control.input_output_response(block, t, np.hstack([gyr, acc]).T, X0=x0)
    batch = estimate(gyr, acc, fs, name, {"stationary": 1} if name == "wiener" else None, gyro_offset=False)  # the LTI filter
    assert np.abs(resp.outputs[:3].T - batch.gravity).max() <= 1e-12
    assert np.abs(resp.outputs[3:].T - batch.quat).max() <= 1e-12


def test_pure_rotation_without_acceleration_is_tracked_exactly():
    """For an earth-fixed input and piecewise-constant rate the discrete step is exact (docs/conventions.md, "Discrete steps")."""
    motion = HumanMotion(delta_v=1e-12, rot_rms=3.0, rot_cutoff=5.0).generate(120.0, 100.0, seed=4)
    # the default start (the first sample turned back by the first rotation) is exact
    est = estimate(motion.gyr, motion.acc, 100.0, gyro_offset=False)
    assert np.abs(est.gravity - 9.81 * motion.up).max() < 1e-9
    # the quaternion output carries the same inclination, and heading from the gyro alone
    assert inclination_error(Rotation.from_quat(est.quat, scalar_first=True).apply(est.up),
                             np.tile([0, 0, 1.0], (len(est.up), 1))).max() < 1e-9
    q_err = Rotation.from_quat(est.quat, scalar_first=True) * Rotation.from_quat(motion.quat, scalar_first=True).inv()
    assert q_err.magnitude().max() < 1e-9


def _discrete_vs_continuous(fs, duration=20.0):
    t = np.arange(int(duration * fs) + 1) / fs
    rate = np.array([0.4, -0.3, 0.8])
    orient = Rotation.from_rotvec(np.outer(t, rate))  # constant body rate
    acc_earth = np.column_stack([np.sin(0.7 * t), np.cos(1.3 * t), 0.5 * np.sin(0.4 * t)])
    acc = orient.inv().apply(acc_earth + [0, 0, 9.81])
    gyr = np.tile(rate, (len(t), 1))
    filt = ef.butterworth(0.5)
    cont = control.input_output_response(
        sensor_frame_system(filt), t, np.hstack([gyr, acc]).T, X0=initial_state(filt, 1 / fs, acc[0])[:6],
        solve_ivp_kwargs={"rtol": 1e-10, "atol": 1e-12, "max_step": 1 / fs},
    )
    # discrete sample k covers (t[k-1], t[k]]: start it on the continuous run's state at t[0]
    disc = estimate(gyr[1:], acc[1:], fs, params={"omega_g": 0.5}, initial_gravity=acc[0], gyro_offset=False)
    return np.abs(cont.outputs.T[1:] - disc.gravity).max()


def test_discrete_step_converges_to_the_continuous_block_at_first_order():
    """Smooth rotation and acceleration: the continuous system (RK45, independent of the
    step) and the discrete step agree, with the O(Ts) error of holding acc[k] over a sample."""
    coarse, fine = _discrete_vs_continuous(100.0), _discrete_vs_continuous(200.0)
    assert fine < 1.2e-3
    assert coarse / fine == pytest.approx(2.0, rel=0.1)


def test_bad_input_is_refused_with_a_clear_message():
    gyr, acc = _random_imu(10)
    with pytest.raises(ValueError, match="shape"):
        estimate(gyr[:, :2], acc, 100.0, gyro_offset=False)
    with pytest.raises(ValueError, match="differ in length"):
        estimate(gyr, acc[:5], 100.0, gyro_offset=False)
    bad = acc.copy()
    bad[4, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite.*sample 4"):
        estimate(gyr, bad, 100.0, gyro_offset=False)
    with pytest.raises(ValueError, match="sample rate"):
        estimate(gyr, acc, -5.0, gyro_offset=False)
    with pytest.raises(ValueError, match="sample time"):
        sensor_frame_system(ef.butterworth(0.1), dt=math.inf)
