"""IMU sensor model: ideal motion signals in, measured signals out (Rizun eqs. 1–2)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import control
import numpy as np

from attitude_fmu.systems.simulation.motion import AXES, Motion
from attitude_fmu.systems.simulation.noise import MAGNETOMETER, SENSOR, normals


@dataclass(frozen=True)
class ImuModel:
    """Gyro y_g = (I + S)·ω + n + b, accelerometer y_a = f + n_a + acc_offset, magnetometer
    y_m = m + n_m + mag_offset.

    delta_n: gyro white-noise density, rad/s/√Hz (one-sided; per-sample s.d.
    delta_n·√(fs/2)); gyr_offset: constant gyro offset b, rad/s (3); gyr_scale: the gyro's
    scale-factor and misalignment error S (3×3, row i: what axis i adds of each true
    rate component; 1 = 100 %); acc_noise:
    accelerometer white-noise density, m/s²/√Hz; acc_offset: constant accelerometer
    offset, m/s² (3); latency: how long the measured gyro and accelerometer lag the motion,
    s (see delay_step; blocks.stages.timing compensates it); mag_noise: magnetometer white-noise
    density, µT/√Hz; mag_offset: hard iron, a field fixed to the sensor, µT (3; the
    magnetometer has no latency). Noise enters as unit-normal samples, 6 per sample (gyro,
    acc), and 3 for the magnetometer (measure_mag).
    """

    delta_n: float = 0.0
    gyr_offset: tuple = (0.0, 0.0, 0.0)
    gyr_scale: tuple = ((0.0, 0.0, 0.0),) * 3
    acc_noise: float = 0.0
    acc_offset: tuple = (0.0, 0.0, 0.0)
    latency: float = 0.0
    mag_noise: float = 0.0
    mag_offset: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name in ("delta_n", "acc_noise", "latency", "mag_noise"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be finite and non-negative, got {value!r}")
        for name in ("gyr_offset", "acc_offset", "mag_offset"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (3,) or not np.isfinite(v).all():
                raise ValueError(f"{name} must be 3 finite numbers, got {getattr(self, name)!r}")
        S = np.asarray(self.gyr_scale, dtype=float)
        if S.shape != (3, 3) or not np.isfinite(S).all():
            raise ValueError(f"gyr_scale must be 3×3 finite numbers, got {self.gyr_scale!r}")

    def measure(self, omega, f, noise, fs: float):
        """Measured (gyr, acc) from ideal rate omega, specific force f (…×3) and unit-normal
        noise (…×6: gyro, then accelerometer) at sample rate fs (Hz)."""
        noise = np.asarray(noise)
        scale = math.sqrt(fs / 2.0)
        omega = np.asarray(omega)
        gyr = (omega + omega @ np.asarray(self.gyr_scale).T + self.delta_n * scale * noise[..., 0:3]
               + np.asarray(self.gyr_offset))
        acc = np.asarray(f) + self.acc_noise * scale * noise[..., 3:6] + np.asarray(self.acc_offset)
        return gyr, acc

    def measure_mag(self, m, noise, fs: float) -> np.ndarray:
        """Measured field (…×3, µT) from the true field m (…×3, µT, sensor coordinates) and
        unit-normal noise (…×3) at sample rate fs (Hz)."""
        return (np.asarray(m) + self.mag_noise * math.sqrt(fs / 2.0) * np.asarray(noise)
                + np.asarray(self.mag_offset))

    def delay_state(self, fs: float, first) -> np.ndarray:
        """The delay line's state at sample rate fs (Hz) before the first sample: the past
        (ω, f) rows (6 each, flat), all equal to first (the motion before it began)."""
        return np.tile(np.asarray(first, dtype=float), int(math.floor(self.latency * fs)) + 1)

    def delay_step(self, state, signals, fs: float) -> tuple[np.ndarray, np.ndarray]:
        """(next state, signals latency seconds ago) for this sample's true (ω, f) (6).
        Both are means over the sample time (systems.simulation.motion), constant within each: the
        mean over an interval latency = (m + φ)/fs earlier is (1 − φ)·x[k − m] + φ·x[k − m − 1]."""
        m, phase = divmod(self.latency * fs, 1.0)
        rows = np.concatenate([np.asarray(signals, dtype=float), state]).reshape(-1, 6)  # x[k], x[k−1], …
        return rows[:-1].ravel(), (1.0 - phase) * rows[int(m)] + phase * rows[int(m) + 1]

    def delayed(self, omega, f, fs: float, before=None) -> tuple[np.ndarray, np.ndarray]:
        """The true rate and specific force (N×3 each) latency seconds ago, through the
        delay line at fs (Hz); before (ω, f; 6): the motion before the first sample (default
        that sample)."""
        signals = np.hstack([omega, f])
        if self.latency:
            state = self.delay_state(fs, signals[0] if before is None else before)
            for k, row in enumerate(signals):
                state, signals[k] = self.delay_step(state, row, fs)
        return signals[:, 0:3], signals[:, 3:6]

    def apply(self, motion: Motion, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Measured (gyr, acc) of a motion, with noise drawn from a fixed seed (the noise
        stream SENSOR of systems.simulation.noise; with a latency, of the motion that long
        ago: delayed)."""
        noise = normals(seed, SENSOR, len(motion.gyr))
        return self.measure(*self.delayed(motion.gyr, motion.acc, motion.fs), noise, motion.fs)

    def apply_mag(self, motion: Motion, seed: int = 1) -> np.ndarray:
        """Measured field (N×3, µT) of a motion, noise from the magnetometer's own stream
        (MAGNETOMETER of systems.simulation.noise), so that the gyro's and the accelerometer's
        noise do not depend on the magnetometer's settings."""
        return self.measure_mag(motion.mag, normals(seed, MAGNETOMETER, len(motion.gyr)), motion.fs)

    def system(self, fs: float, name: str = "imu"):
        """Discrete python-control system: inputs omega_*, f_*, n_*, na_* (unit normal);
        outputs gyr_*, acc_*; with a latency, states the delay line's (x0: delay_state)."""
        def output(t, x, u, params):
            signals = self.delay_step(x, u[0:6], fs)[1] if self.latency else u[0:6]
            gyr, acc = self.measure(signals[0:3], signals[3:6], u[6:12], fs)
            return np.concatenate([gyr, acc])

        update = (lambda t, x, u, params: self.delay_step(x, u[0:6], fs)[0]) if self.latency else None
        states = len(self.delay_state(fs, np.zeros(6))) if self.latency else None
        return control.nlsys(
            update, output, name=name, dt=1.0 / fs, states=states,
            inputs=[f"{s}_{a}" for s in ("omega", "f", "n", "na") for a in AXES],
            outputs=[f"gyr_{a}" for a in AXES] + [f"acc_{a}" for a in AXES],
        )
