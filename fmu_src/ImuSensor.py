"""ImuSensor.fmu: ideal motion signals in, measured IMU signals out (systems.simulation.sensor_model.ImuModel).

Noise is drawn per step from the noise streams of `seed` (systems.simulation.noise:
SENSOR for the gyro and accelerometer, MAGNETOMETER for the magnetometer), sample k of
the run as sample k of the batch path, so a run equals ImuModel.apply and
ImuModel.apply_mag on the same samples. With a
`latency`, the measured signals are those of the motion that long ago (ImuModel's delay
line; before the first step, the motion of the first step), and the first step's size is the
sensor's sample time: later steps run on its grid from the start time
(blocks.stages.timing.grid_samples), the samples a step reaches with its inputs held, none
holding the outputs. Before the first step (in Initialization Mode and after it) the outputs are
the sensor's model of its inputs without noise, which a Jacobi master hands on before any step.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.stages.timing import GRID_MAX_SAMPLES, grid_samples
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
            self.model = self._model()
            self.rng, self.mag_rng = NoiseStream(self.seed, SENSOR), NoiseStream(self.seed, MAGNETOMETER)
            self.delay, self.step_size = None, None
        except ValueError as exc:
            self.fail(f"invalid parameter: {exc}")

    def _model(self) -> ImuModel:
        """The sensor of the parameters (ValueError: one refused)."""
        return ImuModel(
            delta_n=self.delta_n, acc_noise=self.acc_noise,
            gyr_offset=(self.gyr_offset_x, self.gyr_offset_y, self.gyr_offset_z),
            gyr_scale=tuple(tuple(getattr(self, f"gyr_scale_{row}_{c}") for c in "xyz") for row in "xyz"),
            acc_offset=(self.acc_offset_x, self.acc_offset_y, self.acc_offset_z),
            latency=self.latency, mag_noise=self.mag_noise,
            mag_offset=(self.mag_offset_x, self.mag_offset_y, self.mag_offset_z),
            mag_soft_iron=tuple(tuple(getattr(self, f"mag_soft_iron_{row}_{c}") for c in "xyz") for row in "xyz"),
        )

    def start_values(self):
        """Before the first step: the sensor's model of its inputs as they are, with no noise (no
        sample is drawn before a step)."""
        try:
            model = self._model()
            NoiseStream(self.seed, SENSOR)  # the seed's check
        except ValueError:
            return None
        gyr, acc = model.measure((self.omega_x, self.omega_y, self.omega_z), (self.f_x, self.f_y, self.f_z),
                                 np.zeros(6), 1.0)
        mag = model.measure_mag((self.m_x, self.m_y, self.m_z), np.zeros(3), 1.0)
        return dict(zip(("gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z", "mag_x", "mag_y", "mag_z"),
                        (float(v) for v in (*gyr, *acc, *mag))))

    def do_step(self, current_time, step_size):
        if self.error is not None:
            return self.refuse_step()
        if not (math.isfinite(step_size) and step_size > 0):
            return self.fail(f"step size must be positive, got {step_size!r}")
        if not self.model.latency:
            return self._sample(step_size)
        if self.delay is None:  # the first step: the sample time, the delay line filled with the inputs
            signals = np.array([self.omega_x, self.omega_y, self.omega_z, self.f_x, self.f_y, self.f_z])
            try:
                self.delay, self.step_size = self.model.delay_state(1.0 / step_size, signals), step_size
            except ValueError as exc:  # a latency longer than the delay line holds
                return self.fail(str(exc))
            return self._sample(step_size)
        n = grid_samples(self.start_time, self.step_size, current_time, step_size)
        if n > GRID_MAX_SAMPLES:
            return self.fail(f"a step of {step_size!r} s reaches {n:.0f} samples of the sensor's sample time "
                             f"{self.step_size!r} s (its first step's); one step runs {GRID_MAX_SAMPLES:.0f} at most")
        return all(self._sample(self.step_size) for _ in range(int(n)))

    def _sample(self, h: float) -> bool:
        """One sample of h (s) of the inputs as they are: the outputs, the delay line stepped (a latency)."""
        signals = np.array([self.omega_x, self.omega_y, self.omega_z, self.f_x, self.f_y, self.f_z])
        if self.model.latency:
            self.delay, signals = self.model.delay_step(self.delay, signals, 1.0 / self.step_size)
        gyr, acc = self.model.measure(signals[0:3], signals[3:6], self.rng.next(), 1.0 / h)
        self.gyr_x, self.gyr_y, self.gyr_z = (float(v) for v in gyr)
        self.acc_x, self.acc_y, self.acc_z = (float(v) for v in acc)
        mag = self.model.measure_mag((self.m_x, self.m_y, self.m_z), self.mag_rng.next(), 1.0 / h)
        self.mag_x, self.mag_y, self.mag_z = (float(v) for v in mag)
        return True
