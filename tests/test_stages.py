"""The stages around the method, against the algebra they stand for (through their public
functions, the C core behind them): the hard-iron fit is the least-squares sphere of the field
it has seen, and refuses a field that covers one plane only; the gyro-offset estimator holds
its estimate while moving unless told to track it."""
import math

import numpy as np
import pytest

from attitude_fmu import HumanMotion, ImuModel
from attitude_fmu.blocks.stages.gyro_offset import correct
from attitude_fmu.blocks.stages.heading import with_magnetometer
from tests.motions import turning

FS = 100.0
HARD_IRON = np.array([12.0, -7.0, 4.0])  # µT


def _least_squares_centre(field):
    """The centre b of the sphere |m − b|² = r² that fits the samples in the least-squares
    sense of |m|² = 2·m·b + c (numpy's lstsq)."""
    n2 = (field**2).sum(axis=1)
    theta, *_ = np.linalg.lstsq(np.hstack([2.0 * field, np.ones((len(field), 1))]), n2, rcond=None)
    return theta[:3]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_hard_iron_fit_is_the_least_squares_sphere_of_the_field(seed):
    """A tumbling sensor's field (every direction) with hard iron and 0.3 µT/√Hz of noise; the
    fit forgetting nothing (mag_cal_time 10⁶ s): its estimate at the end is the centre of the
    least-squares sphere through every field sample (and so the hard iron)."""
    motion = HumanMotion(delta_v=0.2, rot_rms=1.5).generate(120.0, FS, seed=seed)
    mag = ImuModel(mag_noise=0.3, mag_offset=tuple(HARD_IRON)).apply_mag(motion, seed=seed)
    _, accepted, offset, _ = with_magnetometer(motion.quat, mag, FS, {"mag_cal_time": 1e6, "mag_delay": 0.0})
    centre = _least_squares_centre(mag)
    print(f"seed {seed}: fit {offset[-1]}, least squares {centre} µT")
    assert np.abs(centre - HARD_IRON).max() < 0.1
    assert np.abs(offset[-1] - centre).max() < 1e-4
    assert accepted[-1000:].mean() > 0.9


def test_a_field_that_covers_one_plane_fits_no_sphere():
    """Level, turning about the vertical only: the field covers a circle, whose sphere is not
    determined; no hard-iron offset is taken, ever."""
    motion = turning(lambda t: np.column_stack([1.5 * np.sin(0.3 * t), 0 * t, 0 * t])).generate(200.0, FS)
    mag = ImuModel(mag_noise=0.3, mag_offset=tuple(HARD_IRON)).apply_mag(motion, seed=1)
    _, _, offset, _ = with_magnetometer(motion.quat, mag, FS, {"mag_cal_time": 30.0})
    assert not offset.any()


def _rest_then_motion(seed):
    """10 s at rest, then 60 s of human motion, with a gyro offset: (gyr, acc, offset rad/s)."""
    offset = np.array([0.01, -0.02, 0.005])
    imu = ImuModel(delta_n=math.radians(0.05), acc_noise=0.01, gyr_offset=tuple(offset))
    parts = [imu.apply(HumanMotion(delta_v=1e-12 if k == 0 else 0.5, rot_rms=0.0 if k == 0 else 1.0).generate(
        duration, FS, seed=seed + k), seed=seed + 10 + k) for k, duration in enumerate((10.0, 60.0))]
    return np.vstack([p[0] for p in parts]), np.vstack([p[1] for p in parts]), offset


@pytest.mark.parametrize("tau_motion", [0.0, 100.0])
def test_the_offset_is_tracked_while_moving_only_when_told(tau_motion):
    """After the rest, tau_motion 0 holds the rest's estimate through the motion; the default
    tracks it (the estimate moves, and stays near the offset)."""
    gyr, acc, offset = _rest_then_motion(4)
    _, estimate = correct(gyr, acc, FS, {"tau_motion": tau_motion, "rest_time": 1.0})
    moving = estimate[int(12 * FS):]
    assert np.abs(estimate[int(9 * FS)] - offset).max() < math.radians(0.05)  # the rest found it
    if tau_motion == 0.0:
        assert np.ptp(moving, axis=0).max() == 0.0
    else:
        assert np.ptp(moving, axis=0).max() > 0.0
        assert np.abs(moving - offset).max() < math.radians(0.1)
