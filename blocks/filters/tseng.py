"""Tseng et al.'s complementary filter: sensor models, low/high-pass pairs, compensation,
and the Euler angles of gravity and magnetic field.

Sensor dynamics (eqs. 6–8): accelerometer G_A (improper: exact here, for frequency
responses; `accelerometer_model` realises it with far poles for simulation),
magnetometer G_M, gyro G_G. Filters (eqs. 9–11): G_LA, G_LM low-pass, G_H high-pass.
The chain sensor × filter of each pair, T = G_L·G_S + G_H·G_G, is compensated by its
inverse C = 1/T ("the inverse transfer function of Figures 6 and 7"); every zero of T
lies in the left half-plane, so C is stable and proper.

As a project estimator the complementary filter runs in the gyro-estimated earth frame:
there the gyro branch integrates to a constant that the high-pass removes, and what is
left is the accelerometer branch C·G_LA, carried into the sensor frame like the Wiener
filter (gimbal-lock free).
"""
from __future__ import annotations

import numpy as np

from attitude_fmu import _core

FAR_POLE = 1000.0  # rad/s: poles that make G_A proper for simulation, far above its zeros (10, 20 rad/s)


def accelerometer() -> control.TransferFunction:
    """Eq. 6: G_A = (0.1s + 1)(0.05s + 1), exact (improper)."""
    import control
    return control.tf(np.polymul([0.1, 1.0], [0.05, 1.0]), [1.0])


def accelerometer_model(far_pole: float = FAR_POLE) -> control.TransferFunction:
    """G_A with two poles at far_pole (rad/s), proper, for simulation."""
    import control
    return accelerometer() * control.tf([far_pole**2], np.polymul([1.0, far_pole], [1.0, far_pole]))


def magnetometer() -> control.TransferFunction:
    """Eq. 7: G_M = 50.265/(s + 50.265)."""
    import control
    return control.tf([50.265], [1.0, 50.265])


def gyroscope() -> control.TransferFunction:
    """Eq. 8: G_G = (s + 0.0185)/s, the integrated gyro's angle over the true angle."""
    import control
    return control.tf([1.0, 0.0185], [1.0, 0.0])


def lowpass_acc() -> control.TransferFunction:
    """Eq. 9: G_LA = 1/(0.063s³ + 0.475s² + 1.1937s + 1)."""
    import control
    return control.tf([1.0], [0.063, 0.475, 1.1937, 1.0])


def lowpass_mag() -> control.TransferFunction:
    """Eq. 10: G_LM = 1/(0.3979s + 1)."""
    import control
    return control.tf([1.0], [0.3979, 1.0])


def highpass_gyro() -> control.TransferFunction:
    """Eq. 11: G_H = s²/(s² + 0.6s + 0.09)."""
    import control
    return control.tf([1.0, 0.0, 0.0], [1.0, 0.6, 0.09])


def chain(pair: str = "acc") -> control.TransferFunction:
    """Uncompensated response to a true angle: G_L·G_S + G_H·G_G (Figs. 6 and 7).

    pair: "acc" (accelerometer and gyro) or "mag" (magnetometer and gyro).
    """
    import control
    if pair == "acc":
        low = lowpass_acc() * accelerometer()
    elif pair == "mag":
        low = lowpass_mag() * magnetometer()
    else:
        raise ValueError(f"pair must be 'acc' or 'mag', got {pair!r}")
    return control.minreal(low + highpass_gyro() * gyroscope(), verbose=False)


def compensation(pair: str = "acc") -> control.TransferFunction:
    """The inverse of the pair's chain, C = 1/T."""
    import control
    return control.minreal(1 / chain(pair), verbose=False)


def compensated_chain(pair: str = "acc") -> control.TransferFunction:
    """Sensor models × filters × compensation: the complementary filter's response."""
    import control
    return control.minreal(compensation(pair) * chain(pair), verbose=False)


def earth_filter() -> control.TransferFunction:
    """The project's `tseng` filter in the gyro-estimated earth frame: C·G_LA."""
    import control
    return control.minreal(compensation("acc") * lowpass_acc(), verbose=False)


def euler_from_gravity_mag(up, mag=None):
    """Roll, pitch (Tseng eqs. 3–4) and yaw (eq. 5), rad, Z-Y-X, in this project's frames.

    up: unit up-vector(s) in sensor coordinates (…×3); mag: magnetic field (…×3, µT) or
    None (yaw 0). ENU earth frame: yaw 0 when the sensor x axis points east. Singular
    where pitch reaches ±90° (gimbal lock).
    """
    up = np.asarray(up, dtype=float)
    up = up / np.linalg.norm(up, axis=-1, keepdims=True)
    pitch = np.arcsin(np.clip(-up[..., 0], -1.0, 1.0))
    roll = np.arctan2(up[..., 1], up[..., 2])
    if mag is None:
        return roll, pitch, np.zeros_like(roll)
    m = np.asarray(mag, dtype=float)
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    # the field levelled by pitch and roll is Rz(yaw)ᵀ·(0, B_north, B_up) = B_north·(sin yaw, cos yaw, ·)
    levelled_x = cp * m[..., 0] + sp * (sr * m[..., 1] + cr * m[..., 2])
    levelled_y = cr * m[..., 1] - sr * m[..., 2]
    return roll, pitch, np.arctan2(levelled_x, levelled_y)


def euler_complementary(gyr, acc, fs: float):
    """Tseng's complementary filter on Euler angles, for comparison only (not a project
    method): roll and pitch from the accelerometer (eqs. 3–4) and from the gyro rates
    integrated through the Z-Y-X Euler kinematics (singular at pitch ±90°), combined as
    C·(G_LA·θ_acc + G_H·θ_gyro). Returns roll, pitch (rad) per sample."""
    import control

    from attitude_fmu.blocks.filters.sensor_frame import DiscreteFilter

    gyr, acc = np.asarray(gyr, dtype=float), np.asarray(acc, dtype=float)
    roll_acc, pitch_acc, _ = euler_from_gravity_mag(acc)
    Ts = 1.0 / fs
    roll_gyr, pitch_gyr = _core.euler_rates(gyr, Ts, roll_acc[0], pitch_acc[0])
    low = DiscreteFilter.from_lti(control.minreal(compensation("acc") * lowpass_acc(), verbose=False), Ts)
    high = DiscreteFilter.from_lti(control.minreal(compensation("acc") * highpass_gyro(), verbose=False), Ts)
    # the high-pass branch starts at rest on zero: its input is the gyro angle's change
    roll = low.apply(roll_acc) + high.apply(roll_gyr - roll_gyr[0])
    pitch = low.apply(pitch_acc) + high.apply(pitch_gyr - pitch_gyr[0])
    return roll, pitch
