"""ImuSensor.fmu: ideal motion signals in, measured IMU signals out (systems.simulation.sensor_model.ImuModel).

Noise is drawn per step from the noise streams of `seed` (systems.simulation.noise:
SENSOR for the gyro and accelerometer, MAGNETOMETER for the magnetometer), sample k of
the run as sample k of the batch path, so a run equals ImuModel.apply and
ImuModel.apply_mag on the same samples. With a
`latency`, the measured signals are those of the motion that long ago (ImuModel's delay
line; before the first step, the motion of the first step), which needs a fixed step.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.stages.timing import same_step
from attitude_fmu.fmu_src.fmu_support import ProjectSlave
from attitude_fmu.systems.fmi.interface.simulation_variables import imu_sensor
from attitude_fmu.systems.simulation.noise import MAGNETOMETER, SENSOR, NoiseStream
from attitude_fmu.systems.simulation.sensor_model import ImuModel


class ImuSensor(ProjectSlave):
    author = "attitude-fmu"
    description = ("IMU sensor model: gyro noise density, offset, scale and misalignment, accelerometer noise and "
                   "offset, magnetometer noise, hard and soft iron")
    internal_state = ("rng", "mag_rng", "delay", "step_size")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.register_table(imu_sensor())
        self.model = None

    def initialise(self):
        try:
            self.model = ImuModel(
                delta_n=self.delta_n, acc_noise=self.acc_noise,
                gyr_offset=(self.gyr_offset_x, self.gyr_offset_y, self.gyr_offset_z),
                gyr_scale=tuple(tuple(getattr(self, f"gyr_scale_{row}_{c}") for c in "xyz") for row in "xyz"),
                acc_offset=(self.acc_offset_x, self.acc_offset_y, self.acc_offset_z),
                latency=self.latency, mag_noise=self.mag_noise,
                mag_offset=(self.mag_offset_x, self.mag_offset_y, self.mag_offset_z),
                mag_soft_iron=tuple(tuple(getattr(self, f"mag_soft_iron_{row}_{c}") for c in "xyz") for row in "xyz"),
            )
            self.rng, self.mag_rng = NoiseStream(self.seed, SENSOR), NoiseStream(self.seed, MAGNETOMETER)
            self.delay, self.step_size = None, None
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        if not (math.isfinite(step_size) and step_size > 0):
            return self.fail(f"step size must be positive, got {step_size!r}")
        signals = np.array([self.omega_x, self.omega_y, self.omega_z, self.f_x, self.f_y, self.f_z])
        if self.model.latency:
            if self.delay is None:
                try:
                    self.delay, self.step_size = self.model.delay_state(1.0 / step_size, signals), step_size
                except ValueError as exc:  # a latency longer than the delay line holds
                    return self.fail(str(exc))
            elif not same_step(step_size, self.step_size):
                return self.fail(f"latency needs a fixed step: got {step_size!r} s after {self.step_size!r} s")
            self.delay, signals = self.model.delay_step(self.delay, signals, 1.0 / self.step_size)
        gyr, acc = self.model.measure(signals[0:3], signals[3:6], self.rng.next(), 1.0 / step_size)
        self.gyr_x, self.gyr_y, self.gyr_z = (float(v) for v in gyr)
        self.acc_x, self.acc_y, self.acc_z = (float(v) for v in acc)
        mag = self.model.measure_mag((self.m_x, self.m_y, self.m_z), self.mag_rng.next(), 1.0 / step_size)
        self.mag_x, self.mag_y, self.mag_z = (float(v) for v in mag)
        return True
