"""Earth-frame attitude filters of Rizun (2008) as python-control transfer functions.

Each filter acts on one scalar component of the accelerometer signal expressed in the
gyro-estimated earth frame and returns that component of the gravity estimate.
Frequencies are in rad/s, noise densities one-sided (datasheet style, docs/conventions.md).
"""
from __future__ import annotations

import math

from attitude_fmu.blocks.tuning import STANDARD_GRAVITY  # m/s², the value the project uses for |g|


def omega_g(delta_n: float, delta_v: float, g: float = STANDARD_GRAVITY) -> float:
    """Butterworth break frequency of eq. 25, rad/s.

    delta_n: gyro noise density, rad/s/√Hz; delta_v: slosh (velocity) density, m/s/√Hz.
    """
    _require_positive(delta_n=delta_n, delta_v=delta_v, g=g)
    return math.sqrt(g * delta_n / delta_v)


def butterworth(omega_g: float) -> control.TransferFunction:
    """Eq. 34: the optimal filter for ω_c → ∞, ω_g²/(s² + √2·ω_g·s + ω_g²)."""
    import control
    _require_positive(omega_g=omega_g)
    return control.tf([omega_g**2], [1.0, math.sqrt(2.0) * omega_g, omega_g**2])


def delta_phi(omega_g: float, omega_c: float) -> float:
    """Eq. 27: Δφ = arcsin(Δω_g²/ω_g²) with Δω_g² = ω_g⁴/(2ω_c²) (eq. 25), rad."""
    _require_positive(omega_g=omega_g, omega_c=omega_c)
    if omega_c <= omega_g / math.sqrt(2.0):
        raise ValueError(
            f"omega_c = {omega_c:g} rad/s must exceed omega_g/sqrt(2) = "
            f"{omega_g / math.sqrt(2.0):g} rad/s (the assumption behind eq. 26)"
        )
    return math.asin(omega_g**2 / (2.0 * omega_c**2))


def wiener_band_limited(omega_g: float, omega_c: float) -> control.TransferFunction:
    """Eq. 33: the optimal filter for human motion band-limited at omega_c (rad/s)."""
    import control
    dphi = delta_phi(omega_g, omega_c)
    damping = math.sqrt(2.0) * omega_g * (math.cos(dphi / 2) + math.sin(dphi / 2))
    return control.tf([omega_g**2 / omega_c, omega_g**2], [1.0, damping, omega_g**2])


def first_order(omega_f: float) -> control.TransferFunction:
    """Section 4.2: the filter optimal for white acceleration, ω_f/(s + ω_f)."""
    import control
    _require_positive(omega_f=omega_f)
    return control.tf([omega_f], [1.0, omega_f])


def best_first_order_cutoff(omega_g: float, omega_c: float) -> float:
    """Cut-off (rad/s) minimising the first-order filter's mean-square error, ω_c ≫ ω_g.

    Minimising g²δn²/(4ω_f) + δv²ω_f²ω_c/4 (eq. 41 with eqs. 15 and 20) gives
    ω_f³ = ω_g⁴/(2ω_c).
    """
    _require_positive(omega_g=omega_g, omega_c=omega_c)
    return (omega_g**4 / (2.0 * omega_c)) ** (1.0 / 3.0)


def settle_time(earth_filter: control.TransferFunction) -> float:
    """Ten times the filter's slowest time constant, s: when a start transient has died out."""
    import control
    return 10.0 / float(min(abs(p.real) for p in control.poles(earth_filter)))


def _require_positive(**values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite positive number, got {value!r}")
