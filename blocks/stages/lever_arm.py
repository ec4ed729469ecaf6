"""The lever arm, offline (the batch path's `offline=True`): a sensor turned about a fixed centre.

An IMU on a robot's wrist, a pendulum or a turntable sits at r (m, sensor coordinates) from a
centre of rotation that does not move. Its accelerometer then reads, beside gravity, the
tangential and centripetal accelerations of that point, α×r + ω×(ω×r): a fast turn of a
robot arm 0.3 m out makes 0.5 m/s² that no tilt filter can tell from a tilt while it lasts,
and whose centripetal part keeps one sign in the sensor's frame.

Over the whole recording r is fitted by least squares to the specific force turned into the
frame the gyro integrates (where gravity stands still): in windows of WINDOW_S their mean is
removed (gravity, and the slow turn the gyro's residual drift gives it), and what is left,
R·a, is regressed on R·A, A·r = α×r + ω×(ω×r) (ω and α at each accelerometer sample from the
gyro's mean rates over SPAN_S either side of it: the gyro's noise differenced over one sample at
1 kHz would outweigh a pendulum's α, and bias the fit toward no arm; over 10 ms it is what it is
at 100 Hz). No filter runs for it: one pass of the gyro's
integration and the sums, in the C core (blocks/core/stages/lever_arm.h), then a 3 × 3 system.

It is taken only where it is proven: where the fit explains at least EXPLAINED_MIN of what
the windows leave of the specific force, rotation about a fixed centre is then nearly all the
motion (0.997 on the robot_arm scenario; 0.07–0.76 on BROAD's ten handheld trials, 0.00–0.02 on
simulated human motion with a lever arm and its own translation, where the centre moves: a
fit there removes some accelerations and adds others). The accelerometer is then freed of
A·r before the offline smoother runs; along a single axis of rotation no acceleration shows
the arm, and whatever the fit leaves there moves nothing. Online the gyro-offset stage fits the
arm causally, over the last tau_arm s (blocks.stages.gyro_offset).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from attitude_fmu import _core

WINDOW_S = 10.0  # s: windows whose mean specific force (gravity, and the gyro's drift under it) is removed
SPAN_S = 0.01  # s: ω and α from the gyro's means over this either side of a sample (one sample at 100 Hz)
EXPLAINED_MIN = 0.9  # taken where the fit explains at least this share of the specific force the windows leave
LEFT_MIN = 1e-3  # m/s² RMS: the windows leaving less (a motion in closed form, no noise), there is nothing to remove


@dataclass(frozen=True)
class LeverArm:
    """A fitted lever arm: position (m, sensor coordinates) from the centre of rotation;
    explained, the share of the specific force left by the windows that it accounts for."""

    position: np.ndarray
    explained: float

    def corrected(self, gyr, acc, fs: float) -> np.ndarray:
        """acc (N×3, m/s², at each sample) freed of α×r + ω×(ω×r) as fit takes them, gyr (N×3,
        rad/s, each the mean over the sample time before it) at fs Hz."""
        gyr, acc = (np.ascontiguousarray(a, dtype=float) for a in (gyr, acc))
        out = np.empty_like(acc)
        _core.lever_arm_removed(gyr, acc, 1.0 / fs, _span(fs), self.position, out)
        return out


def _span(fs: float) -> int:
    return max(1, round(SPAN_S * fs))


def fit(gyr, acc, fs: float) -> LeverArm | None:
    """The lever arm over a recording (gyr N×3 rad/s, freed of its offset, each the mean over the
    sample time before it; acc N×3 m/s² at each sample; fs Hz) where it is proven (see above),
    else None (also where the windows leave under LEFT_MIN RMS)."""
    gyr, acc = (np.ascontiguousarray(a, dtype=float) for a in (gyr, acc))
    n = len(gyr)
    if n < 2:
        return None
    normal, moment, total = _core.lever_arm_sums(gyr, acc, 1.0 / fs, _span(fs), max(2, round(WINDOW_S * fs)))
    normal = normal.reshape(3, 3)
    if total <= n * LEFT_MIN**2:
        return None
    position = np.linalg.lstsq(normal, moment, rcond=1e-12)[0]
    explained = float(2.0 * position @ moment - position @ normal @ position) / total
    return LeverArm(position, explained) if explained >= EXPLAINED_MIN else None
