"""Recordings made by the simulator (`attitude simulate`): a rest, then human motion
(systems.simulation.motion.HumanMotion) or another motion profile, measured by a sensor of a
datasheet's figures at any rate, with the motion's exact orientation as the reference, so that
`attitude evaluate` scores them as it scores a lab's recordings. The sensors' table loads without
python-control (the command line's help lists it); the simulation loads it when it runs."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from attitude_fmu.systems.recordings.recording import Recording

if TYPE_CHECKING:
    from attitude_fmu.systems.simulation.sensor_model import ImuModel

STANDARD_G = 9.80665  # m/s² in a g, as datasheets give accelerometer ranges
# the seed's streams of numpy's generator for the drawn errors
SCALE_STREAM, OFFSET_STREAM, SOFT_IRON_STREAM, HARD_IRON_STREAM = 2, 3, 4, 5
MAX_SCALE_ERROR = 0.5  # rms scale and misalignment error: 50 % is no gyro's
DEFAULT_MOTION = {"delta_v": 0.1, "grid": 0.02}  # a person moving about: 5 m/s² rms per axis at any rate


@dataclass(frozen=True)
class Sensor:
    """A simulated IMU's figures, as a datasheet gives them.

    gyro_noise_dps: gyro white noise, °/s/√Hz; acc_noise: accelerometer white noise,
    m/s²/√Hz; gyro_scale_error: rms of each element of the gyro's scale-factor and
    misalignment matrix (1 = 100 %), the matrix drawn from the seed; gyro_offset_dps: the
    norm of the gyro's constant offset, °/s; gyro_offset_direction: its direction (3, any
    length but 0; None: drawn from the seed); gyro_range_dps
    (°/s) and acc_range_g (g): the full scale of each axis, beyond which a sample reads the
    full scale (inf: none); mag_noise: magnetometer white noise, µT/√Hz; mag_soft_iron: rms
    of each element of the magnetometer's symmetric soft-iron matrix S_m (1 = 100 %), drawn
    from the seed; mag_hard_iron_ut: the norm of its hard iron, µT, its direction drawn from
    the seed.
    """

    gyro_noise_dps: float = 0.02
    acc_noise: float = 0.002
    gyro_scale_error: float = 0.0
    gyro_offset_dps: float = 0.0
    gyro_range_dps: float = math.inf
    acc_range_g: float = math.inf
    mag_noise: float = 0.1
    gyro_offset_direction: tuple | None = None
    mag_soft_iron: float = 0.0
    mag_hard_iron_ut: float = 0.0

    def __post_init__(self):
        for what, value, top in (("gyro noise", self.gyro_noise_dps, math.inf),
                                 ("accelerometer noise", self.acc_noise, math.inf),
                                 ("gyro scale error", self.gyro_scale_error, MAX_SCALE_ERROR),
                                 ("gyro offset", self.gyro_offset_dps, math.inf),
                                 ("magnetometer noise", self.mag_noise, math.inf),
                                 ("magnetometer soft iron", self.mag_soft_iron, MAX_SCALE_ERROR),
                                 ("magnetometer hard iron", self.mag_hard_iron_ut, math.inf)):
            if not (math.isfinite(value) and 0.0 <= value < top):
                raise ValueError(f"{what} must be finite, non-negative"
                                 f"{'' if top == math.inf else f' and below {top:g}'}, got {value!r}")
        for what, value in (("gyro range", self.gyro_range_dps), ("accelerometer range", self.acc_range_g)):
            if not (value > 0.0):  # inf allowed: no range
                raise ValueError(f"{what} must be a positive number (inf: none), got {value!r}")
        if self.gyro_offset_direction is not None:
            direction = np.asarray(self.gyro_offset_direction, dtype=float)
            if direction.shape != (3,) or not np.isfinite(direction).all() or not direction.any():
                raise ValueError(f"gyro offset direction must be 3 finite numbers, not all 0, "
                                 f"got {self.gyro_offset_direction!r}")

    def model(self, seed: int = 0) -> ImuModel:
        """The sensor model with its scale-factor matrix, soft iron and the directions not
        given (gyro offset, hard iron) drawn from seed."""
        from attitude_fmu.systems.simulation.sensor_model import ImuModel

        def rng(stream):
            return np.random.default_rng((seed, stream))

        def along(norm, direction):
            return tuple(norm * direction / np.linalg.norm(direction))

        scale = rng(SCALE_STREAM).normal(0.0, self.gyro_scale_error, (3, 3))
        direction = (rng(OFFSET_STREAM).normal(size=3) if self.gyro_offset_direction is None
                     else np.asarray(self.gyro_offset_direction, dtype=float))
        soft = np.triu(rng(SOFT_IRON_STREAM).normal(0.0, self.mag_soft_iron, (3, 3)))
        return ImuModel(delta_n=math.radians(self.gyro_noise_dps), acc_noise=self.acc_noise,
                        gyr_scale=tuple(map(tuple, scale)), gyr_offset=along(math.radians(self.gyro_offset_dps),
                                                                             direction),
                        mag_noise=self.mag_noise, mag_offset=along(self.mag_hard_iron_ut,
                                                                   rng(HARD_IRON_STREAM).normal(size=3)),
                        mag_soft_iron=tuple(map(tuple, soft + np.triu(soft, 1).T)))


# sensors of three kinds, with figures typical of their datasheets
SENSORS = {
    "consumer": Sensor(gyro_noise_dps=0.007, acc_noise=180e-6 * STANDARD_G, gyro_scale_error=0.005,
                       gyro_offset_dps=0.5, gyro_range_dps=2000.0, acc_range_g=16.0, mag_noise=0.1),
    "low_range": Sensor(gyro_noise_dps=0.005, acc_noise=400e-6 * STANDARD_G, gyro_scale_error=0.01,
                        gyro_offset_dps=1.0, gyro_range_dps=250.0, acc_range_g=2.0, mag_noise=0.3),
    "calibrated": Sensor(gyro_noise_dps=0.004, acc_noise=60e-6 * STANDARD_G, gyro_scale_error=0.0005,
                         gyro_offset_dps=0.05, gyro_range_dps=450.0, acc_range_g=8.0, mag_noise=0.05),
}


def simulate_recording(fs: float, duration: float, rest: float = 10.0, sensor: Sensor = SENSORS["consumer"],
                       motion: dict | None = None, seed: int = 0, mag: bool = True,
                       name: str = "simulated", motion_profile: str = "human") -> Recording:
    """A recording at fs (Hz): rest seconds still in the pose the motion starts from (level
    for the human motion), then duration seconds of the motion profile motion_profile (its
    parameters updated by motion; the human motion's first by DEFAULT_MOTION), measured by sensor
    (its errors drawn from seed; the motion's noise from its stream of seed, the sensor's
    and the magnetometer's from theirs of seed + 1). The reference is the motion's orientation, the movement flag
    0 over the rest; with mag, the magnetometer sees the simulation's earth field. Samples
    beyond the sensor's range read its full scale; notes count them per sensor."""
    from scipy.spatial.transform import Rotation

    from attitude_fmu.systems.simulation.motion import Motion, profile

    defaults = DEFAULT_MOTION if motion_profile == "human" else {}
    moves = profile(motion_profile).motion({**defaults, **(motion or {})})
    still = round(rest * fs)
    moving = moves.generate(duration, fs, seed)
    start = Rotation.from_quat(moves.start_quat(), scalar_first=True)
    truth = Motion(fs, np.vstack([np.tile(start.as_quat(scalar_first=True), (still, 1)), moving.quat]),
                   np.vstack([np.zeros((still, 3)), moving.gyr]),
                   np.vstack([np.tile(start.inv().apply([0.0, 0.0, moves.g]), (still, 1)), moving.acc]))
    imu = sensor.model(seed)
    gyr, acc = imu.apply(truth, seed + 1)
    notes = []
    for what, values, full, unit in (("gyro", gyr, math.radians(sensor.gyro_range_dps), "°/s"),
                                     ("accelerometer", acc, sensor.acc_range_g * STANDARD_G, "m/s²")):
        beyond = np.abs(values) > full
        if beyond.any():
            np.clip(values, -full, full, out=values)
            shown = math.degrees(full) if unit == "°/s" else full
            notes.append(f"{name}: {np.count_nonzero(beyond.any(axis=1))} {what} samples beyond its range "
                         f"±{shown:g} {unit} read the full scale")
    return Recording(name, fs, gyr, acc, truth.t, mag=imu.apply_mag(truth, seed + 1) if mag else None,
                     quat_ref=truth.quat, movement=np.arange(len(gyr)) >= still, notes=notes)
