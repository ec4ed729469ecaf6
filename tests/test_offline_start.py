"""The offline orientation's heading (blocks/core/pipeline/offline.c: offline_smooth): the gyro's,
levelled onto the smoothed gravity row by row. A recording that starts in motion makes the forward
filter's first corrections large; its own orientation (the online estimate's) takes a heading error
from them that the gyro never turned. Against the simulation's reference (scipy's rotations) and vqf's
offline estimate on the results page's tactical_handheld scenario (no rest at its start)."""
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.systems.evaluation.scenarios import score
from attitude_fmu.systems.simulation.scenarios import SCENARIOS


def _heading_errors_deg(quat, rec) -> np.ndarray:
    """The turn about earth up of quat (N×4) against the reference (°; 6D: from an arbitrary north)."""
    error = Rotation.from_quat(quat, scalar_first=True) * Rotation.from_quat(rec.quat_ref, scalar_first=True).inv()
    w, z = error.as_quat(scalar_first=True)[:, [0, 3]].T
    return np.degrees(2.0 * np.arctan2(z, w))


def test_a_start_in_motion_turns_no_heading_into_the_offline_orientation():
    """tactical_handheld, 20 s of motion from its first sample: over the first 0.1 s the online
    orientation's heading error spans more than 5° (the forward filter's first corrections; the offline
    one's spanned 10° there before), the offline one's less than 0.01° (a gyro 0.04 °/s off cannot move
    it more); its inclination that of the smoothed gravity as before."""
    rec = replace(SCENARIOS["tactical_handheld"], duration=20.0).recording("tactical_handheld")
    first = slice(0, int(0.1 * rec.fs))
    online = estimate(rec.gyr, rec.acc, rec.fs).quat
    offline = estimate(rec.gyr, rec.acc, rec.fs, offline=True)
    spans = [np.ptp(_heading_errors_deg(q, rec)[first]) for q in (online, offline.quat)]
    print("spans of the heading error (°), online and offline", spans)
    assert spans[0] > 5.0
    assert spans[1] < 0.01
    up = Rotation.from_quat(offline.quat, scalar_first=True).inv().apply([0.0, 0.0, 1.0])
    np.testing.assert_allclose(up, offline.gravity / np.linalg.norm(offline.gravity, axis=1)[:, None], atol=1e-12)


def test_the_tactical_offline_9d_heading_is_at_or_ahead_of_vqf_offline():
    """tactical_handheld on the results page: offline 9D heading 0.127° before (vqf offline 0.051°),
    nearly all of it from the first 0.1 s; at or below vqf's offline now."""
    cell = score("tactical_handheld")["heading 9D offline"]
    print({k: round(v, 4) for k, v in cell.items()})
    assert cell["ours"] <= cell["vqf"]
