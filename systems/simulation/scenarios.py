"""Scenarios (issue "any-sensor"): simulated recordings that reproduce failure modes seen on other
labs' recordings, each a motion profile with overrides (systems/simulation/profile_table.py) measured by
a sensor (recording.Sensor) at a rate, after a rest, from a seed: `attitude simulate --scenario NAME`, or
SCENARIOS[NAME].recording(). Like the sensors' table, it loads without python-control."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from attitude_fmu.systems.recordings.recording import Recording
from attitude_fmu.systems.simulation.recording import SENSORS, STANDARD_G, Sensor, simulate_recording

LEVER_M = 0.3  # m: the tactical IMU's and the robot's lever arm, along the sensor's x


@dataclass(frozen=True)
class Scenario:
    """A simulated recording's recipe: description (one line); profile, the motion profile's name, with
    motion, its parameters' overrides (the human motion's on top of recording.DEFAULT_MOTION); sensor;
    fs (Hz); duration of the motion and rest before it (s); seed."""

    description: str
    profile: str
    sensor: Sensor
    fs: float
    duration: float
    rest: float
    seed: int
    motion: dict = field(default_factory=dict)

    def recording(self, name: str = "simulated", mag: bool = True, motion: dict | None = None) -> Recording:
        """The recording (simulate_recording; with mag, its magnetometer), motion's overrides on top of the
        scenario's (dataclasses.replace changes any other field)."""
        return simulate_recording(self.fs, self.duration, self.rest, self.sensor, {**self.motion, **(motion or {})},
                                  self.seed, mag=mag, name=name, motion_profile=self.profile)


SCENARIOS = {
    "phone_flat": Scenario(
        "a phone (mostly) flat on a table or a hand: gyro offset 4 °/s on z only, an OS-calibrated noisy "
        "magnetometer with soft iron (0.06 rms), undisturbed field",
        "phone_flat",
        Sensor(gyro_noise_dps=0.01, acc_noise=150e-6 * STANDARD_G, gyro_scale_error=0.005, gyro_offset_dps=4.0,
               gyro_offset_direction=(0.0, 0.0, 1.0), gyro_range_dps=2000.0, acc_range_g=8.0, mag_noise=0.1,
               mag_soft_iron=0.06),
        fs=100.0, duration=120.0, rest=10.0, seed=1),
    "phone_running": Scenario(
        "a raw phone gyro (4 °/s offset on every axis) on a runner: impacts of 2.5 g at 2.7 steps a second",
        "running",
        Sensor(gyro_noise_dps=0.01, acc_noise=150e-6 * STANDARD_G, gyro_scale_error=0.01,
               gyro_offset_dps=4.0 * math.sqrt(3.0), gyro_offset_direction=(1.0, 1.0, 1.0), gyro_range_dps=2000.0,
               acc_range_g=16.0, mag_noise=0.1),
        fs=100.0, duration=120.0, rest=5.0, seed=2),
    "tactical_handheld": Scenario(
        f"a calibrated tactical-grade IMU carried by hand, no rest at the start, {LEVER_M:g} m from the motion's "
        "centre of rotation",
        "human",
        Sensor(gyro_noise_dps=0.005, acc_noise=20e-6 * STANDARD_G, gyro_scale_error=0.0005, gyro_offset_dps=0.04,
               gyro_range_dps=450.0, acc_range_g=10.0, mag_noise=0.05),
        fs=200.0, duration=120.0, rest=0.0, seed=3,
        motion={"rot_rms": 0.5, "rot_cutoff": 2.0, "grid": 0.005, "lever_x": LEVER_M}),
    "robot_arm": Scenario(
        f"an industrial robot's wrist: smooth fast turns of 90° with little linear acceleration, the IMU "
        f"{LEVER_M:g} m from the wrist",
        "robot_arm", SENSORS["calibrated"], fs=125.0, duration=120.0, rest=5.0, seed=4,
        motion={"lever_x": LEVER_M}),
    "segment_40hz": Scenario(
        "a body-segment IMU at 40 Hz in human motion: consumer gyro, magnetometer with soft iron (0.04 rms) and "
        "2 µT of hard iron",
        "human", replace(SENSORS["consumer"], mag_soft_iron=0.04, mag_hard_iron_ut=2.0),
        fs=40.0, duration=300.0, rest=10.0, seed=5),
}


def scenario(name: str) -> Scenario:
    """The scenario of that name (SCENARIOS), else ValueError naming the ones there are."""
    try:
        return SCENARIOS[name]
    except KeyError:
        raise ValueError(f"unknown scenario {name!r}; available: {', '.join(SCENARIOS)}") from None
