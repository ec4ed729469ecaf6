"""Rizun's Wiener filter with its noise densities estimated locally (the default `wiener`).

Eq. 34 is optimal for stationary noise: ω_g = √(g·δn/δv) (eq. 25). Real motion is not
stationary (rest, slow turns, fast translation) and a real gyro's error is not only white
noise: its scale-factor and misalignment errors S (each element of rms σ_s, datasheet)
add S·ω, which grows with the rotation. This filter keeps eq. 34 carried into the sensor
frame (blocks.filters.sensor_frame) and re-derives ω_g every sample from densities of the same
noise model, measured over the last τ seconds (`tau_noise`):

- gyro: δn_eff² = δn² + σ_s²·S_ω(0), where S_ω(0) = 4·⟨|ω|²⟩/ω_m is the low-frequency
  density of an angular rate band-limited (first order) at ω_m (Rizun eq. 14's shape);
- slosh: δv² = ⟨|v|²⟩/(3·J), with v the accelerometer band-passed into a velocity in
  the gyro frame (minus its own low-pass at 1/τ_v, then integrated with the same leak):
  gravity and any error of the filter's own estimate are constant or slow there and drop
  out, so the statistic does not feed back on the filter. J = (1/2π)∫ (ωτ_v)⁴/(1+ω²τ_v²)²
  /(1+ω²/ω_m²) dω is the variance this band-pass leaves of eq. 14's velocity per unit
  density. δv is held above delta_v_min (rest).

With σ_s = 0 and a steady motion the estimates settle on the stationary densities and the
filter on eq. 34. The Butterworth runs in the realisation d/dt[ĝ, u] = ω_g·M·[ĝ, u] +
ω_g·[0, 1]·y_a with M = [[0, 1], [−1, −√2]] (u = ω_g·e, e the velocity residual of the
filter), whose zero-order hold has a closed form for every ω_g; e is kept continuous when
ω_g changes. Start-up: while the time since the start is below the time constant √2/ω_g,
ĝ is the mean of the accelerometer so far in the gyro frame (u = 0); a first sample in
motion is not trusted alone. The step is the C core's (blocks/core/methods/wiener_local.h),
which serves the python-control block, the batch path and the FMU.
"""
from __future__ import annotations

import math

from attitude_fmu import _core
from attitude_fmu.blocks.filters.earth_filters import butterworth, omega_g


def gyro_density(params, rate_ms: float) -> float:
    """δn_eff² = δn² + σ_s²·4·⟨|ω|²⟩/ω_m ((rad/s)²/Hz, one-sided, per axis): the gyro's density the
    local densities count at mean-square angular rate rate_ms (rad²/s², all axes together).
    params: the method's resolved parameters."""
    _, _, dn2, k_w, _, _, _, _ = _core.wiener_local_coefficients(params, 1.0)
    return dn2 + k_w * rate_ms


def settled_filter(params, rate_ms: float, delta_v: float):
    """Eq. 34 at the break frequency the local densities settle on for stationary motion
    of mean-square angular rate rate_ms (rad²/s², all axes together) and slosh delta_v
    (m/s/√Hz, eq. 14 band-limited at omega_m): the filter whose eq. 41 error the local
    filter has on such motion. params: the method's resolved parameters."""
    _, g, _, _, _, dv2_min, _, _ = _core.wiener_local_coefficients(params, 1.0)
    return butterworth(omega_g(math.sqrt(gyro_density(params, rate_ms)), math.sqrt(max(delta_v**2, dv2_min)), g))
