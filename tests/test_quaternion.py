"""The C core's quaternion arithmetic, reached through what Python binds of it (_core.integrate_rates,
carry_forward_rows, interval_ends, the estimators' level start and Euler angles), against
scipy's Rotation."""
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu import METHODS, OnlineEstimator, estimate
from attitude_fmu._core import integrate_rates
from attitude_fmu.blocks.stages.timing import carry_forward_rows, interval_ends, interval_means

RNG = np.random.default_rng(7)


def _same_rotations(q, p):
    """Largest distance of the unit quaternions q (N×4) from p, either sign."""
    return np.minimum(np.abs(q - p).max(axis=1), np.abs(q + p).max(axis=1)).max()


@pytest.mark.parametrize("angle", [1e-9, 1e-4, 0.05, 0.0999, 0.1001, 1.0, 3.0])
def test_one_step_is_scipys_rotation_vector_exponential_on_both_sides_of_the_series(angle):
    """A rotation of angle (rad) about random axes in one step: exp(ω·Ts), below and above the
    angle where the small-angle series takes over, within 1e-15."""
    Ts = 0.01
    for axis in RNG.normal(size=(20, 3)):
        rate = axis / np.linalg.norm(axis) * angle / Ts
        quat = np.empty((1, 4))
        integrate_rates(np.ascontiguousarray(rate[None]), Ts, quat)
        assert _same_rotations(quat, Rotation.from_rotvec(rate * Ts).as_quat(scalar_first=True)[None]) < 1e-15


def test_integrated_rates_are_the_product_of_the_steps():
    """q_k = q_{k−1} ⊗ exp(ω_k·Ts) from the identity: scipy's composition of the same steps."""
    gyr = RNG.normal(scale=4.0, size=(500, 3))
    gyr[::7] *= 30.0  # some steps beyond the series
    quat = np.empty((500, 4))
    integrate_rates(np.ascontiguousarray(gyr), 0.01, quat)
    truth, q = np.empty((500, 4)), Rotation.identity()
    for k, step in enumerate(Rotation.from_rotvec(gyr * 0.01)):
        q = q * step
        truth[k] = q.as_quat(scalar_first=True)
    assert _same_rotations(quat, truth) < 1e-12
    assert np.abs(np.linalg.norm(quat, axis=1) - 1.0).max() < 1e-15


def test_integrated_rates_rebuild_a_closed_form_motion():
    """A closed-form coning motion's gyro (the rotation vector of each sample's interval)
    integrated from the identity gives its orientations relative to the first."""
    from attitude_fmu import profile

    motion = profile("coning").motion().generate(60.0, 100.0)
    quat = np.empty_like(motion.quat)
    integrate_rates(np.ascontiguousarray(motion.gyr[1:]), 0.01, quat[1:])
    quat[0] = (1.0, 0.0, 0.0, 0.0)
    truth = Rotation.from_quat(motion.quat[0], scalar_first=True).inv() * Rotation.from_quat(motion.quat, scalar_first=True)
    assert (Rotation.from_quat(quat, scalar_first=True).inv() * truth).magnitude().max() < 1e-9


def test_carry_forward_is_scipys():
    """q ⊗ exp(ω·L), and the up-vector in the sensor frame L later: exp(ω·L)⁻¹ applied to it."""
    rot = Rotation.random(40, random_state=3)
    gyr, gravity, latency = RNG.normal(scale=3.0, size=(40, 3)), RNG.normal(scale=9.81, size=(40, 3)), 0.004
    quat, up = np.ascontiguousarray(rot.as_quat(scalar_first=True)), gravity.copy()
    carry_forward_rows(quat, up, np.ascontiguousarray(gyr), latency)
    turn = Rotation.from_rotvec(gyr * latency)
    assert _same_rotations(quat, (rot * turn).as_quat(scalar_first=True)) < 1e-15
    assert np.abs(up - turn.inv().apply(gravity)).max() < 1e-13
    # the up-vector and the orientation stay consistent: both give the same earth vector
    assert np.abs(Rotation.from_quat(quat, scalar_first=True).apply(up) - rot.apply(gravity)).max() < 1e-12


def test_interval_ends_turn_a_mean_over_the_step_to_its_end():
    """An accelerometer mean over (t_k−1, t_k] in the sensor frame at t_k: turned back by half
    the step's rotation."""
    gyr, acc, Ts = RNG.normal(scale=3.0, size=(50, 3)), RNG.normal(scale=9.81, size=(50, 3)), 0.01
    out = interval_ends(np.ascontiguousarray(gyr), np.ascontiguousarray(acc), Ts)
    assert np.abs(out - Rotation.from_rotvec(gyr * Ts / 2).inv().apply(acc)).max() < 1e-13


def test_interval_means_are_the_trapezoid_of_point_samples():
    gyr = RNG.normal(size=(30, 3))
    means = interval_means(gyr)
    assert np.array_equal(means[1:], 0.5 * (gyr[:-1] + gyr[1:])) and np.array_equal(means[0], gyr[0])
    assert np.array_equal(interval_means(gyr, before=np.ones(3))[0], 0.5 * (1.0 + gyr[0]))


@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("up", [[0.3, -0.2, 0.9], [1.0, 0.0, 0.0], [0.1, 0.2, -0.97], [1e-9, 0.0, -1.0]])
def test_a_still_sensor_is_held_level_by_the_smallest_rotation_onto_up(method, up):
    """Still, its accelerometer along up (any length): every method's orientation turns up onto
    the vertical by the smallest rotation (the angle between them, about a horizontal axis,
    so heading 0), and its up-vector is up."""
    u = np.asarray(up) / np.linalg.norm(up)
    acc = np.tile(9.81 * u, (50, 1))
    est = estimate(np.zeros((50, 3)), acc, 100.0, method, gyro_offset=False)
    rot = Rotation.from_quat(est.quat[-1], scalar_first=True)
    assert np.abs(rot.apply(u) - [0.0, 0.0, 1.0]).max() < 1e-9
    assert rot.magnitude() == pytest.approx(np.arccos(np.clip(u[2], -1, 1)), abs=1e-7)
    assert abs(rot.as_rotvec()[2]) < 1e-7 and np.abs(est.up[-1] - u).max() < 1e-9


def test_the_euler_angles_are_scipys_zyx_of_the_orientation():
    """roll, pitch, yaw of the online estimator: scipy's Z-Y-X (yaw, pitch, roll) angles of its
    quaternion, while the sensor tumbles through every angle."""
    est = OnlineEstimator(gyro_offset=False)
    gyr = RNG.normal(scale=2.0, size=(800, 3))
    angles = []
    for k, g in enumerate(gyr):
        est.step(g, 9.81 * Rotation.from_rotvec(gyr[:k + 1].sum(axis=0) * 0.01).inv().apply([0, 0, 1]), 0.01)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # gimbal lock
            expected = Rotation.from_quat(est.quat, scalar_first=True).as_euler("ZYX")[::-1]
        angles.append((est.euler, expected))
    got, expected = (np.array(a) for a in zip(*angles))
    assert np.abs(np.angle(np.exp(1j * (got - expected)))).max() < 1e-9
    assert np.ptp(expected, axis=0).min() > 0.5
