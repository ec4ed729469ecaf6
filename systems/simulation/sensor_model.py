"""IMU sensor model: ideal motion signals in, measured signals out (Rizun eqs. 1–2), by the
simulation's C core (systems/simulation/core: sensor.c, delay_line.c)."""
from __future__ import annotations

from dataclasses import dataclass, field

import control
import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, with_c_step
from attitude_fmu.blocks.tuning import STANDARD_GRAVITY
from attitude_fmu.systems.simulation.motion import AXES, Motion
from attitude_fmu.systems.simulation.noise import MAGNETOMETER, SENSOR, normals


def _rows(a, width: int) -> np.ndarray:
    """a (…×width) as a C-contiguous float array of rows."""
    return np.ascontiguousarray(a, dtype=float).reshape(-1, width)


@dataclass(frozen=True)
class ImuModel:
    """Gyro y_g = (I + S)·ω + n + b, accelerometer y_a = f + n_a + acc_offset, magnetometer
    y_m = (I + S_m)·m + n_m + mag_offset.

    delta_n: gyro white-noise density, rad/s/√Hz (one-sided; per-sample s.d.
    delta_n·√(fs/2)); gyr_offset: constant gyro offset b, rad/s (3); gyr_scale: the gyro's
    scale-factor and misalignment error S (3×3, row i: what axis i adds of each true
    rate component; 1 = 100 %); acc_noise:
    accelerometer white-noise density, m/s²/√Hz; acc_offset: constant accelerometer
    offset, m/s² (3); latency: how long the measured gyro and accelerometer lag the motion,
    s (see delay_step; blocks.stages.timing compensates it); mag_noise: magnetometer white-noise
    density, µT/√Hz; mag_offset: hard iron, a field fixed to the sensor, µT (3; the
    magnetometer has no latency); mag_soft_iron: soft iron S_m (3×3, row i: what axis i adds
    of each true field component; 1 = 100 %). Noise enters as unit-normal samples, 6 per sample (gyro,
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
    mag_soft_iron: tuple = ((0.0, 0.0, 0.0),) * 3
    vector: np.ndarray = field(init=False, repr=False, compare=False)  # the fields as the C core takes them

    def __post_init__(self):
        parts = []  # the C core checks the values (and words the refusal of a vector's shape)
        for name, shape in (("delta_n", ()), ("gyr_offset", (3,)), ("gyr_scale", (3, 3)), ("acc_noise", ()),
                            ("acc_offset", (3,)), ("latency", ()), ("mag_noise", ()), ("mag_offset", (3,)),
                            ("mag_soft_iron", (3, 3))):
            value = np.asarray(getattr(self, name) if shape else float(getattr(self, name)), dtype=float)
            if value.shape != shape:
                _core.imu_refuse_vector(name, getattr(self, name))
            parts.append(value.ravel())
        vector = np.concatenate(parts)
        _core.imu_check(vector)
        object.__setattr__(self, "vector", vector)

    def measure(self, omega, f, noise, fs: float):
        """Measured (gyr, acc) from ideal rate omega, specific force f (…×3) and unit-normal
        noise (…×6: gyro, then accelerometer) at sample rate fs (Hz)."""
        omega = np.asarray(omega, dtype=float)
        gyr, acc = np.empty((omega.size // 3, 3)), np.empty((omega.size // 3, 3))
        _core.imu_measure(self.vector, fs, _rows(omega, 3), _rows(f, 3), _rows(noise, 6), gyr, acc)
        return gyr.reshape(omega.shape), acc.reshape(omega.shape)

    def measure_mag(self, m, noise, fs: float) -> np.ndarray:
        """Measured field (…×3, µT) from the true field m (…×3, µT, sensor coordinates) and
        unit-normal noise (…×3) at sample rate fs (Hz)."""
        m = np.asarray(m, dtype=float)
        mag = np.empty((m.size // 3, 3))
        _core.imu_measure_mag(self.vector, fs, _rows(m, 3), _rows(noise, 3), mag)
        return mag.reshape(m.shape)

    def delay_state(self, fs: float, first) -> np.ndarray:
        """The delay line's state at sample rate fs (Hz) before the first sample: the past
        (ω, f) rows (6 each, flat, newest first), all equal to first (the motion before it began)."""
        return _core.delay_state(self.latency, fs, np.asarray(first, dtype=float))

    def delay_step(self, state, signals, fs: float) -> tuple[np.ndarray, np.ndarray]:
        """(next state, signals latency seconds ago) for this sample's true (ω, f) (6).
        Both are means over the sample time (systems.simulation.motion), constant within each: the
        mean over an interval latency = (m + φ)/fs earlier is (1 − φ)·x[k − m] + φ·x[k − m − 1]."""
        return _core.delay_step(self.latency, fs, np.asarray(state, dtype=float), np.asarray(signals, dtype=float))

    def delayed(self, omega, f, fs: float, before=None) -> tuple[np.ndarray, np.ndarray]:
        """The true rate and specific force (N×3 each) latency seconds ago, through the
        delay line at fs (Hz); before (ω, f; 6): the motion before the first sample (default
        that sample)."""
        signals = np.hstack([omega, f]).astype(float)
        if self.latency:
            before = signals[0] if before is None else np.asarray(before, dtype=float)
            _core.delay_run(self.latency, fs, before, signals, signals)
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
        outputs gyr_*, acc_*; with a latency, states the delay line's (x0: delay_state).
        Marked with its C step, "imu" (numbers: vector); at rest on ω = 0, f = g·ẑ, no noise."""
        def output(t, x, u, params):
            signals = self.delay_step(x, u[0:6], fs)[1] if self.latency else u[0:6]
            gyr, acc = self.measure(signals[0:3], signals[3:6], u[6:12], fs)
            return np.concatenate([gyr, acc])

        update = (lambda t, x, u, params: self.delay_step(x, u[0:6], fs)[0]) if self.latency else None
        states = len(self.delay_state(fs, np.zeros(6))) if self.latency else None
        system = control.nlsys(
            update, output, name=name, dt=1.0 / fs, states=states,
            inputs=[f"{s}_{a}" for s in ("omega", "f", "n", "na") for a in AXES],
            outputs=[f"gyr_{a}" for a in AXES] + [f"acc_{a}" for a in AXES],
        )
        return with_c_step(system, CStep("imu", 1.0 / fs, numbers=(*self.vector, float(fs)),
                                         rest=(lambda u: self.delay_state(fs, u[0:6])) if self.latency else None,
                                         rest_inputs=(0.0,) * 5 + (STANDARD_GRAVITY,) + (0.0,) * 6))
