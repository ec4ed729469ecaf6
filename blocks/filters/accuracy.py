"""Analytic accuracy of earth-frame attitude filters (Rizun 2008, section 3.4).

Spectra are two-sided in angular frequency ω (rad/s), so that a mean square is
(1/2π)∫_{-∞}^{∞} S(ω) dω, with the one-sided densities delta_n (rad/s/√Hz) and
delta_v (m/s/√Hz) of docs/conventions.md.
"""
from __future__ import annotations

import math

import control
import numpy as np
from scipy import integrate

from attitude_fmu.blocks.filters.earth_filters import STANDARD_GRAVITY
from attitude_fmu.blocks.filters.earth_filters import omega_g as _omega_g


def gravity_signal_spectrum(omega, delta_n: float, g: float = STANDARD_GRAVITY):
    """Eq. 20: spectrum of one gravity component in the gyro-estimated frame, (m/s²)²/(rad/s)."""
    omega = np.asarray(omega, dtype=float)
    return g**2 * (delta_n**2 / 2.0) / omega**2


def acceleration_spectrum(omega, delta_v: float, omega_c: float | None = None):
    """Eq. 15 (eq. 16 when omega_c is None): spectrum of one acceleration component."""
    omega = np.asarray(omega, dtype=float)
    spectrum = (delta_v**2 / 2.0) * omega**2
    if omega_c is not None:
        spectrum = spectrum / (1.0 + (omega / omega_c) ** 2)
    return spectrum


def error_spectrum(
    filt: control.TransferFunction,
    omega,
    delta_n: float,
    delta_v: float,
    omega_c: float | None = None,
    g: float = STANDARD_GRAVITY,
):
    """Eq. 41 for any earth-frame filter: rejected signal plus accepted acceleration.

    delta_v is the slosh of the motion (which may differ from the one the filter was
    designed for: the mismatch a of eq. 47).
    """
    omega = np.asarray(omega, dtype=float)
    response = np.asarray(filt(1j * omega))
    gain2 = np.abs(response) ** 2
    rejected = np.abs(1.0 - response) ** 2 * gravity_signal_spectrum(omega, delta_n, g)
    return rejected + gain2 * acceleration_spectrum(omega, delta_v, omega_c)


def butterworth_error_spectrum(omega, delta_n: float, delta_v: float, g: float = STANDARD_GRAVITY):
    """Eq. 42: g·δn·δv·(1 + (ω/ω_g)²)/(1 + (ω/ω_g)⁴) for the optimal filter of eq. 34."""
    x = np.asarray(omega, dtype=float) / _omega_g(delta_n, delta_v, g)
    return g * delta_n * delta_v * (1.0 + x**2) / (1.0 + x**4)


def butterworth_error_peak(delta_n: float, delta_v: float, g: float = STANDARD_GRAVITY):
    """Frequency (rad/s) and value of the maximum of eq. 42: √(√2−1)·ω_g and ½(1+√2)·g·δn·δv."""
    return (
        math.sqrt(math.sqrt(2.0) - 1.0) * _omega_g(delta_n, delta_v, g),
        0.5 * (1.0 + math.sqrt(2.0)) * g * delta_n * delta_v,
    )


def mean_square_gravity_error(delta_n: float, delta_v: float, a: float = 1.0, g: float = STANDARD_GRAVITY):
    """Eq. 49 (eq. 46 for a = 1): ⟨Δg²⟩ per component, (m/s²)², with slosh mismatch a = δv'/δv."""
    if not (math.isfinite(a) and a >= 0):
        raise ValueError(f"slosh mismatch a must be finite and non-negative, got {a!r}")
    return (3.0 + a**2) / (4.0 * math.sqrt(2.0)) * g * delta_n * delta_v * _omega_g(delta_n, delta_v, g)


def rms_attitude_error(delta_n: float, delta_v: float, a: float = 1.0, g: float = STANDARD_GRAVITY) -> float:
    """Eq. 50: RMS attitude error, rad, of the optimal filter for slosh delta_v under slosh a·delta_v."""
    return math.sqrt(2.0 * mean_square_gravity_error(delta_n, delta_v, a, g) / g**2)


def mean_square_error(
    filt: control.TransferFunction,
    delta_n: float,
    delta_v: float,
    omega_c: float | None = None,
    g: float = STANDARD_GRAVITY,
) -> float:
    """Eq. 43 evaluated numerically from eq. 41 for any filter, (m/s²)² per component."""
    def integrand(w):
        return float(error_spectrum(filt, np.array([w]), delta_n, delta_v, omega_c, g)[0])

    # the integrand is even in ω; split at a few decades for quad's sake
    poles = np.abs(np.asarray(control.poles(filt)))
    edges = [0.0, *sorted({*poles[poles > 0], *( [omega_c] if omega_c else [] )}), np.inf]
    total = 0.0
    for lo, hi in zip(edges[:-1], edges[1:]):
        lo = max(lo, 1e-12)
        value, _ = integrate.quad(integrand, lo, hi, limit=400)
        total += value
    return 2.0 * total / (2.0 * math.pi)


def smoother_mean_square_gravity_error(delta_n: float, delta_v: float, a: float = 1.0,
                                       g: float = STANDARD_GRAVITY) -> float:
    """⟨Δg²⟩ per component of the offline smoother (eq. 34 forward, then backward).

    Forward–backward, the Butterworth's response is |H|² = ω_g⁴/(ω_g⁴ + ω⁴), the
    non-causal Wiener filter S_g/(S_g + S_a) of eqs. 16 and 20. Eq. 41 then gives
    S_Δg = (δv²ω_g⁴/2)·ω²(ω⁴ + a²ω_g⁴)/(ω_g⁴ + ω⁴)², and with ∫x²/(1+x⁴)² = π/(4√2),
    ∫x⁶/(1+x⁴)² = 3π/(4√2): ⟨Δg²⟩ = (3 + a²)/(16√2)·g·δn·δv·ω_g, a quarter of eq. 49.
    """
    return mean_square_gravity_error(delta_n, delta_v, a, g) / 4.0


def smoother_rms_attitude_error(delta_n: float, delta_v: float, a: float = 1.0,
                                g: float = STANDARD_GRAVITY) -> float:
    """RMS attitude error (rad) of the offline smoother: half of eq. 50."""
    return math.sqrt(2.0 * smoother_mean_square_gravity_error(delta_n, delta_v, a, g) / g**2)


def smoother_error_spectrum(filt: control.TransferFunction, omega, delta_n: float, delta_v: float,
                            omega_c: float | None = None, g: float = STANDARD_GRAVITY):
    """Eq. 41 for a filter applied forward and backward (zero phase, response |H|²)."""
    omega = np.asarray(omega, dtype=float)
    response = np.abs(np.asarray(filt(1j * omega))) ** 2
    return ((1.0 - response) ** 2 * gravity_signal_spectrum(omega, delta_n, g)
            + response**2 * acceleration_spectrum(omega, delta_v, omega_c))
