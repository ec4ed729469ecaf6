"""The per-sample kernels' closed forms against the matrix algebra they stand for.

The gyro-offset and hard-iron kernels run every sample, so they are written without
LAPACK calls or temporaries: a rank-2 singular value decomposition by hand, Kalman
updates one scalar at a time, a sphere fit by the adjugate. Here each is held to the
textbook form computed with numpy.linalg on random cases.
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.stages.gyro_offset import CLIP_SIGMAS, OBSERVED, motion_update, scalar_update
from attitude_fmu.blocks.stages.hard_iron import STATE_SIZE, SUMS, _accumulate, _fit, _spread


def _joint_motion_update(b, P, old, new, r_lp, rb_lp, Ts, W, clip):
    """The offset's Kalman update from the turn of the low-passed accelerometer as one
    matrix update: H = Π·LP(R), its singular directions by numpy's SVD, the innovation
    clipped per component and projected onto the directions H keeps at least OBSERVED of."""
    n2 = new @ new
    Pi = np.eye(3) - np.outer(new, new) / n2
    H = Pi @ r_lp.reshape(3, 3)
    turn = np.cross(old, new) / (n2 * Ts)
    e = np.clip(turn + Pi @ rb_lp - H @ b, -clip, clip)
    U, sv, Vt = np.linalg.svd(H)
    Uk = U * (sv >= OBSERVED)
    Hk = (Uk * sv) @ Vt
    K = P @ Hk.T @ np.linalg.inv(Hk @ P @ Hk.T + W * np.eye(3))
    return b + K @ (Uk @ (Uk.T @ e)), P - K @ Hk @ P, int((sv >= OBSERVED).sum())


def test_offset_motion_update_equals_the_joint_kalman_update():
    rng = np.random.default_rng(11)
    kept = set()
    for case in range(300):
        # LP(R): the mean of rotations spread by up to `spread` rad, so that H keeps 0 to 2 directions
        spread = rng.uniform(0.0, 3.0)
        r_lp = Rotation.from_rotvec(rng.normal(0.0, spread, (8, 3))).as_matrix().mean(axis=0)
        new = Rotation.random(random_state=case).apply([0.0, 0.0, 9.81])
        old = Rotation.from_rotvec(rng.normal(0.0, 1e-4, 3)).apply(new)
        b, rb_lp = rng.normal(0.0, 0.01, 3), rng.normal(0.0, 0.01, 3)
        A = rng.normal(0.0, 0.01, (3, 3))
        P = A @ A.T + 1e-6 * np.eye(3)
        Ts, W, clip = 0.01, rng.uniform(1e-6, 1e-3), CLIP_SIGMAS * np.radians(0.5) * rng.uniform(0.05, 1.0)
        want_b, want_P, n_kept = _joint_motion_update(b, P, old, new, r_lp.ravel(), rb_lp, Ts, W, clip)
        kept.add(n_kept)
        got_b, got_P = b.copy(), P.copy()
        motion_update(got_b, got_P, tuple(old), new.copy(), r_lp.ravel().copy(), rb_lp.copy(), Ts, W, clip)
        assert np.abs(got_b - want_b).max() <= 1e-12 + 1e-9 * np.abs(want_b - b).max()
        assert np.abs(got_P - want_P).max() <= 1e-9 * np.abs(P).max()
    assert kept == {0, 1, 2}


def test_offset_rest_update_per_axis_equals_the_joint_kalman_update():
    rng = np.random.default_rng(12)
    A = rng.normal(0.0, 0.01, (3, 3))
    P, b, z, r = A @ A.T, rng.normal(0.0, 0.01, 3), rng.normal(0.0, 0.01, 3), 3e-4
    K = P @ np.linalg.inv(P + r * np.eye(3))
    got_b, got_P = b.copy(), P.copy()
    for i in range(3):
        scalar_update(got_b, got_P, tuple(np.eye(3)[i]), z[i], r)
    assert np.abs(got_b - (b + K @ (z - b))).max() <= 1e-15
    assert np.abs(got_P - (P - K @ P)).max() <= 1e-15


def _sums(field):
    state = np.zeros(STATE_SIZE)
    for m in field:
        _accumulate(state[SUMS], tuple(m), 1.0)
    return state[SUMS]


@pytest.mark.parametrize("seed", range(5))
def test_hard_iron_sphere_fit_equals_least_squares(seed):
    rng = np.random.default_rng(seed)
    centre, radius = rng.normal(0.0, 20.0, 3), rng.uniform(20.0, 70.0)
    directions = Rotation.random(500, random_state=seed).apply([1.0, 0.0, 0.0])
    field = centre + radius * directions + rng.normal(0.0, 0.5, (500, 3))
    b, fit_radius, distance, raw_radius, raw_distance = _fit(_sums(field))
    # |m|² = 2·m·b + c in the least-squares sense
    n2 = (field**2).sum(axis=1)
    theta, *_ = np.linalg.lstsq(np.hstack([2.0 * field, np.ones((500, 1))]), n2, rcond=None)
    want_radius = np.sqrt(theta[3] + theta[:3] @ theta[:3])
    residual = n2 - 2.0 * field @ theta[:3] - theta[3]
    assert np.abs(np.array(b) - theta[:3]).max() <= 1e-8 * radius
    assert fit_radius == pytest.approx(want_radius, rel=1e-10)
    assert distance == pytest.approx(np.sqrt(np.mean(residual**2)) / (2.0 * want_radius), rel=1e-6)
    assert raw_radius == pytest.approx(np.sqrt(n2.mean()), rel=1e-12)
    assert raw_distance == pytest.approx(np.sqrt(n2.var()) / (2.0 * raw_radius), rel=1e-6)
    assert np.abs(b - centre).max() < 0.5  # and the fit finds the sphere
    assert _spread(_sums(field)) == pytest.approx(np.sqrt(np.linalg.eigvalsh(np.cov(field.T, bias=True))[0]),
                                                  rel=1e-9)


def test_hard_iron_fit_refuses_a_field_that_covers_one_plane():
    angle = np.linspace(0.0, 2.0 * np.pi, 400)
    field = np.column_stack([40.0 * np.cos(angle), 40.0 * np.sin(angle), np.full_like(angle, -20.0)])
    b, fit_radius, *_ = _fit(_sums(field))
    assert fit_radius == 0.0 and not any(b)
    assert _spread(_sums(field)) == pytest.approx(0.0, abs=1e-6)
