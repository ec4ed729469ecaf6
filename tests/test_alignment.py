"""evaluate --align (systems.evaluation.alignment): a reference given a known lag, mounting rotation,
earth frame (another up axis, another north) is brought back, and scores as the aligned original;
a reference of another motion is refused; heading errors lose the constant offset of another north."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.evaluation.alignment import align, shifted_quaternions
from attitude_fmu.systems.evaluation.evaluate import errors_on_movement, evaluate_recording
from attitude_fmu.systems.recordings.recording import Recording, RecordingError
from attitude_fmu.systems.simulation.motion import EARTH_FIELD_UT
from attitude_fmu.systems.simulation.sensor_model import ImuModel
from tests.motions import ClosedFormMotion

FS = 100.0
LAG = 7.3  # samples the reference lags the IMU by
MOUNTING = Rotation.from_euler("xyz", [30.0, -50.0, 100.0], degrees=True)  # the IMU's frame → the markers'
NORTH = Rotation.from_rotvec([0.0, 0.0, math.radians(40.0)])  # the reference's earth frame, turned about up
Y_UP = Rotation.from_rotvec([-math.pi / 2, 0.0, 0.0])  # a motion capture's earth frame with y up (z-up → y-up)


def _orientation(t):  # turns about every axis, at rates a body segment reaches
    return Rotation.from_euler("ZYX", np.column_stack([1.5 * np.sin(0.31 * t) + 0.4 * np.sin(1.7 * t),
                                                       0.6 * np.sin(0.53 * t + 1.0), 0.5 * np.sin(0.83 * t + 2.0)]))


@pytest.fixture(scope="module")
def recording():
    motion = ClosedFormMotion(_orientation).generate(120.0, FS)
    imu = ImuModel(delta_n=math.radians(0.02), acc_noise=0.002, gyr_offset=(0.002, -0.001, 0.003))
    gyr, acc = imu.apply(motion, seed=3)
    mag = Rotation.from_quat(motion.quat, scalar_first=True).inv().apply(EARTH_FIELD_UT)
    movement = np.arange(len(gyr)) >= 10 * FS
    return Recording("synthetic", FS, gyr, acc, np.arange(len(gyr)) / FS, mag=mag, quat_ref=motion.quat.copy(),
                     movement=movement)


def _misaligned(rec, earth=NORTH):
    """rec's reference, lagging by LAG samples, of markers MOUNTING away, in the earth frame earth."""
    ref = shifted_quaternions(rec.quat_ref, -LAG)
    ok = np.isfinite(ref).all(axis=1)
    out = np.full_like(ref, np.nan)
    out[ok] = (earth * Rotation.from_quat(ref[ok], scalar_first=True) * MOUNTING.inv()).as_quat(scalar_first=True)
    return replace(rec, quat_ref=out)


@pytest.mark.parametrize("earth, up", [(NORTH, (0.0, 0.0, 1.0)), (Y_UP * NORTH, (0.0, 1.0, 0.0))],
                         ids=["z-up", "y-up"])
def test_align_recovers_lag_mounting_and_heading_offset(recording, earth, up):
    est = estimate(recording.gyr, recording.acc, FS, mag=recording.mag).quat
    original, aligned_original = align(recording, est)
    found, aligned = align(_misaligned(recording, earth), est)
    assert abs((found.lag_s - original.lag_s) * FS - LAG) < 1.0  # within a sample
    assert abs(original.lag_s) * FS < 0.5
    mounting_error = Rotation.from_quat(found.mounting_quat, scalar_first=True) * MOUNTING.inv()
    assert math.degrees(mounting_error.magnitude()) < 0.5
    assert np.allclose(found.up_axis, up)
    turn = (found.heading_offset_deg - original.heading_offset_deg + 40.0 + 180.0) % 360.0 - 180.0
    assert abs(turn) < 0.5  # the reference's north 40° away: the estimate's 40° back from it
    scores = [errors_on_movement(est, replace(recording, quat_ref=ref), magnetic_north=False)["inclination_rmse_deg"]
              for ref in (aligned_original, aligned)]
    assert abs(scores[1] - scores[0]) < 0.05 * scores[0]
    misaligned = errors_on_movement(est, _misaligned(recording, earth), magnetic_north=False)["inclination_rmse_deg"]
    assert misaligned > 10 * scores[0]  # what scoring without --align would report


def test_a_reference_of_another_motion_is_refused_with_the_misfit(recording):
    other = ClosedFormMotion(lambda t: _orientation(t[::-1])).generate(120.0, FS)  # the motion played backwards
    est = estimate(recording.gyr, recording.acc, FS).quat
    with pytest.raises(RecordingError, match=r"cannot be aligned: its angular rates do not match the gyro's \(misfit"):
        align(replace(recording, quat_ref=other.quat), est)


def test_heading_error_loses_another_norths_constant_offset_unless_magnetic(recording):
    other_north = replace(recording, quat_ref=(NORTH * Rotation.from_quat(recording.quat_ref, scalar_first=True))
                          .as_quat(scalar_first=True))
    magnetic = evaluate_recording(recording, peers=False, magnetic=True)["wiener"]
    other = evaluate_recording(other_north, peers=False)["wiener"]
    as_magnetic = evaluate_recording(other_north, peers=False, magnetic=True)["wiener"]
    assert other["heading_rmse_deg"] < magnetic["heading_rmse_deg"] + 0.05
    assert abs(as_magnetic["heading_rmse_deg"] - 40.0) < 1.0
    assert other["inclination_rmse_deg"] == pytest.approx(magnetic["inclination_rmse_deg"], rel=1e-9)
