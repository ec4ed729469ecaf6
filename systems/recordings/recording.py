"""An IMU recording as the project reads it: its columns and units, the Recording, notes."""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace

import numpy as np

IMU_COLUMNS = ("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
MAG_COLUMNS = ("mag_x", "mag_y", "mag_z")
REF_COLUMNS = ("ref_q_w", "ref_q_x", "ref_q_y", "ref_q_z")  # optional reference orientation, sensor → earth
MOVEMENT_COLUMN = "movement"  # optional: 1 in the phase the errors are measured over, else 0
KNOWN_COLUMNS = ("t", *IMU_COLUMNS, *MAG_COLUMNS, *REF_COLUMNS, MOVEMENT_COLUMN)  # the names a CSV's header may use
MAT_VARIABLES = ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement", "sampling_rate")  # a .mat's (BROAD's)
GYR_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "mdeg/s": math.pi / 180e3}
G_N = 9.80665  # m/s², standard gravity: the unit g of accelerometers (not the local gravity of the filters)
ACC_UNITS = {"m/s2": 1.0, "g": G_N, "mg": G_N / 1e3}
MAG_UNITS = {"uT": 1.0, "nT": 1e-3, "G": 100.0, "mG": 0.1}  # to µT
T_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}  # to s
PARQUET_SUFFIX = ".parquet"  # a file name ending so is read and written as Parquet; .mat is MATLAB, any other CSV


class RecordingError(ValueError):
    """A recording that cannot be used as it is; the message says why and what to do."""


@dataclass
class Recording:
    """An IMU recording: gyr (rad/s), acc (m/s²), mag (µT) N×3 in sensor coordinates, fs (Hz).

    quat_ref (N×4, sensor → earth, NaN where lost) and movement (N, bool) come with
    reference recordings such as BROAD's. filled (N, bool) marks the rows put into gaps of
    a CSV's time stamps (not in the input; see systems.recordings.reading._fill_gaps); notes say how the input was
    read where a user should know it.
    """

    name: str
    fs: float
    gyr: np.ndarray
    acc: np.ndarray
    t: np.ndarray
    mag: np.ndarray | None = None
    quat_ref: np.ndarray | None = None
    movement: np.ndarray | None = None
    filled: np.ndarray | None = None
    notes: list[str] = field(default_factory=list)

    def evaluated(self) -> np.ndarray:
        """(N, bool) the samples errors are measured on: the movement phase (every sample
        when the recording has no movement flag) where the reference is finite."""
        if self.quat_ref is None:
            raise RecordingError(f"{self.name}: no optical reference (opt_quat, or the CSV columns "
                                 f"{','.join(REF_COLUMNS)}); cannot evaluate")
        phase = np.ones(len(self.gyr), dtype=bool) if self.movement is None else self.movement
        if not phase.any():
            raise RecordingError(f"{self.name}: the movement flag is 0 throughout: no movement phase to measure")
        ok = phase & np.isfinite(self.quat_ref).all(axis=1)
        if not ok.any():
            raise RecordingError(f"{self.name}: the reference has no valid sample"
                                 f"{'' if self.movement is None else ' during movement'}")
        return ok

    def into_movement(self, seconds: float) -> Recording:
        """The recording from `seconds` (≥ 0) after its movement phase begins: no rest
        before it and a first sample in motion."""
        if self.movement is None or not self.movement.any():
            raise RecordingError(f"{self.name}: no movement phase to start in")
        if not (math.isfinite(seconds) and seconds >= 0):
            raise RecordingError(f"start in the movement phase must be a finite non-negative time, got {seconds!r}")
        k = int(np.argmax(self.movement)) + int(round(seconds * self.fs))
        if k >= len(self.gyr):
            raise RecordingError(f"{self.name}: the recording ends before {seconds:g} s into its movement phase")
        cut = lambda a: None if a is None else a[k:]
        return replace(self, gyr=self.gyr[k:], acc=self.acc[k:], t=self.t[k:], mag=cut(self.mag),
                       quat_ref=cut(self.quat_ref), movement=cut(self.movement), filled=cut(self.filled))


def print_notes(notes) -> None:
    """Notes on how a recording was read (None entries skipped), on standard error."""
    for note in notes:
        if note:
            print(f"attitude: note: {note}", file=sys.stderr)
