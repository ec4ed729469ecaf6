"""The compiled quaternion kernels against scipy's Rotation."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.quaternion import level_quat, quat_multiply, quat_normalized, quat_rotate, rotvec_quat
from attitude_fmu.blocks.stages.timing import carry_forward_rows

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("scale", [1e-9, 1e-4, 0.05, 0.0999, 0.1001, 1.0, 3.0])
def test_rotvec_quat_matches_scipy_across_the_series_threshold(scale):
    for rv in RNG.normal(size=(20, 3)):
        rv = rv / np.linalg.norm(rv) * scale
        expected = Rotation.from_rotvec(rv).as_quat(scalar_first=True)
        assert np.allclose(rotvec_quat(*rv), expected, atol=1e-15, rtol=0)


def test_multiply_rotate_normalize_match_scipy():
    for _ in range(50):
        p, q = Rotation.random(2, random_state=int(RNG.integers(1 << 30)))
        v = RNG.normal(size=3)
        pq = quat_multiply(tuple(p.as_quat(scalar_first=True)), tuple(q.as_quat(scalar_first=True)))
        assert np.allclose(Rotation.from_quat(pq, scalar_first=True).as_matrix(), (p * q).as_matrix(), atol=1e-14)
        assert np.allclose(quat_rotate(tuple(p.as_quat(scalar_first=True)), tuple(v)), p.apply(v), atol=1e-14)
        scaled = tuple(3.7 * p.as_quat(scalar_first=True))
        assert np.allclose(quat_normalized(scaled), p.as_quat(scalar_first=True), atol=1e-15)


@pytest.mark.parametrize("u", [[0.3, -0.2, 0.9], [1.0, 0.0, 0.0], [0.1, 0.2, -0.97], [1e-9, 0.0, -1.0]])
def test_level_quat_is_the_smallest_rotation_onto_up(u):
    u = np.asarray(u) * 2.5  # any length
    norm = np.linalg.norm(u)
    q = np.asarray(level_quat(tuple(u), norm))
    rot = Rotation.from_quat(q / np.linalg.norm(q), scalar_first=True)
    assert np.allclose(rot.apply(u), [0, 0, norm], atol=1e-12)
    # smallest: the rotation angle equals the angle between u and up, about a horizontal axis
    assert np.isclose(rot.magnitude(), np.arccos(np.clip(u[2] / norm, -1, 1)), atol=1e-7)
    assert abs(rot.as_rotvec()[2]) < 1e-12


def test_carry_forward_matches_scipy():
    """blocks.stages.timing: q ⊗ exp(ω·L) and the up-vector in the sensor frame L later."""
    rot = Rotation.random(40, random_state=3)
    gyr, gravity, latency = RNG.normal(scale=3.0, size=(40, 3)), RNG.normal(scale=9.81, size=(40, 3)), 0.004
    quat, up = rot.as_quat(scalar_first=True), gravity.copy()
    carry_forward_rows(quat, up, gyr, latency)
    turn = Rotation.from_rotvec(gyr * latency)
    assert np.abs(quat - (rot * turn).as_quat(scalar_first=True)).max() < 1e-15
    assert np.abs(up - turn.inv().apply(gravity)).max() < 1e-13
    # the up-vector and the orientation stay consistent: both give the same earth vector
    assert np.abs(Rotation.from_quat(quat, scalar_first=True).apply(up) - rot.apply(gravity)).max() < 1e-12


def test_integrated_rates_rebuild_a_closed_form_motion():
    """A closed-form coning motion's gyro (the rotation vector of each sample's interval)
    integrated from the identity gives its orientations relative to the first."""
    from attitude_fmu.blocks.quaternion import integrate_rates
    from attitude_fmu.systems.simulation.motion import coning

    motion = coning().generate(60.0, 100.0)
    quat = np.empty_like(motion.quat)
    integrate_rates(np.ascontiguousarray(motion.gyr[1:]), 0.01, quat[1:])
    quat[0] = (1.0, 0.0, 0.0, 0.0)
    truth = Rotation.from_quat(motion.quat[0], scalar_first=True).inv() * Rotation.from_quat(motion.quat, scalar_first=True)
    assert (Rotation.from_quat(quat, scalar_first=True).inv() * truth).magnitude().max() < 1e-9
