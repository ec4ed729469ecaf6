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
motion is not trusted alone. One compiled step serves the python-control block, the
batch path and the FMU.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.filters.earth_filters import butterworth, omega_g
from attitude_fmu.blocks.filters.sensor_frame import filter_rows, level_onto_gravity, turn_rows
from attitude_fmu.blocks.jit import kernel

STATE_NAMES = (
    "g_x", "g_y", "g_z",  # gravity estimate ĝ, m/s², sensor coordinates
    "u_x", "u_y", "u_z",  # ω_g·e, e the filter's velocity residual (m/s), so m/s²
    "v_x", "v_y", "v_z",  # band-passed velocity of the noise estimate, m/s
    "f_x", "f_y", "f_z",  # low-passed accelerometer, m/s² (all four rows turn with the gyro)
    "q_w", "q_x", "q_y", "q_z",  # orientation, sensor → earth
    "w2", "v2", "omega_g",  # ⟨|ω|²⟩ (rad²/s²), ⟨|v|²⟩/3 (m²/s²), last break frequency (rad/s)
    "t",  # time since the start (s)
)
ROWS = slice(0, 12)
QUAT = slice(12, 16)
W2, V2, OMEGA, T = 16, 17, 18, 19
SQRT2 = math.sqrt(2.0)


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts, g, δn², k_w, 1/J, δv_min², a_avg, leak_v]: δn_eff² = δn² + k_w·⟨|ω|²⟩,
    δv² = ⟨|v|²⟩/(3·J), a_avg = 1 − exp(−Ts/τ), leak_v = exp(−Ts/τ_v); J =
    ∫₀^∞ x⁴/((1 + x²)²·(1 + x²/c²)) dx / (2π·τ_v) with c = ω_m·τ_v, which partial
    fractions in x² give as c²·(2c + 1)/(8·τ_v·(c + 1)²)."""
    wm, tau_v = params["omega_m"], params["tau_v"]
    c = wm * tau_v
    J = c * c * (2.0 * c + 1.0) / (8.0 * tau_v * (c + 1.0) ** 2)
    return np.array([
        Ts, params["g"], params["delta_n"] ** 2, 4.0 * params["scale_error"] ** 2 / wm, 1.0 / J,
        params["delta_v_min"] ** 2, 1.0 - math.exp(-Ts / params["tau_noise"]), math.exp(-Ts / tau_v),
    ])


def settled_filter(params, rate_ms: float, delta_v: float):
    """Eq. 34 at the break frequency the local densities settle on for stationary motion
    of mean-square angular rate rate_ms (rad²/s², all axes together) and slosh delta_v
    (m/s/√Hz, eq. 14 band-limited at omega_m): the filter whose eq. 41 error the local
    filter has on such motion (tests/test_wiener_local.py)."""
    _, g, dn2, k_w, _, dv2_min, _, _ = coefficients(params, 1.0)
    return butterworth(omega_g(math.sqrt(dn2 + k_w * rate_ms), math.sqrt(max(delta_v**2, dv2_min)), g))


def initial_state(coef, acc0) -> np.ndarray:
    """At rest on acc0 (m/s²): ĝ along acc0 with the magnitude g (coef[1]; the start-up's
    mean then begins with the first sample), no residuals, q = identity, no motion seen."""
    state = np.zeros(len(STATE_NAMES))
    norm = float(np.linalg.norm(acc0))
    state[0:3] = acc0 * (coef[1] / norm) if norm > 0.0 else (0.0, 0.0, coef[1])
    state[9:12] = acc0
    state[QUAT] = (1.0, 0.0, 0.0, 0.0)
    return state


@kernel(inline=True)
def butterworth_zoh(wt, Ad, Bd):
    """Ad = exp(M·wt), Bd = M⁻¹·(Ad − I)·[0, 1] for wt = ω_g·Ts (rad). M has eigenvalues
    (−1 ± i)/√2, so exp(M·t) = e^(−t/√2)·(cos(t/√2)·I + √2·sin(t/√2)·(M + I/√2))."""
    a = wt / SQRT2
    e = math.exp(-a)
    c, s = e * math.cos(a), e * math.sin(a) * SQRT2
    Ad[0, 0], Ad[0, 1] = c + s / SQRT2, s
    Ad[1, 0], Ad[1, 1] = -s, c - s / SQRT2
    # M⁻¹ = [[−√2, −1], [1, 0]] applied to (Ad − I)[:, 1]
    Bd[0] = -SQRT2 * Ad[0, 1] - (Ad[1, 1] - 1.0)
    Bd[1] = Ad[0, 1]


@kernel(inline=True)
def local_omega_g(state, coef, gyr, acc, k, turned):
    """Update the running densities with sample k (turned: the state rows in this sample's
    frame, whose rows 2 and 3, v and the low-passed accelerometer, are updated here) and
    return ω_g = √(g·δn_eff/δv), rad/s."""
    Ts, g, dn2, k_w, inv_J, dv2_min, a_avg, leak = (
        coef[0], coef[1], coef[2], coef[3], coef[4], coef[5], coef[6], coef[7])
    v2 = 0.0
    for i in range(3):
        turned[3, i] += (1.0 - leak) * (acc[k, i] - turned[3, i])
        turned[2, i] = leak * turned[2, i] + Ts * (acc[k, i] - turned[3, i])
        v2 += turned[2, i] * turned[2, i]
    w2 = gyr[k, 0] * gyr[k, 0] + gyr[k, 1] * gyr[k, 1] + gyr[k, 2] * gyr[k, 2]
    state[W2] += a_avg * (w2 - state[W2])
    state[V2] += a_avg * (v2 / 3.0 - state[V2])
    return math.sqrt(g * math.sqrt((dn2 + k_w * state[W2]) / max(inv_J * state[V2], dv2_min)))  # eq. 25


@kernel()
def run_schedule(state, coef, gyr, acc, gravity, quat, omega_in, omega_out):
    """Over N samples: gravity (N×3, m/s²), quat (N×4) and the break frequency used
    (omega_out, N, rad/s) per sample. omega_in (N, rad/s) imposes the break frequencies
    (the offline smoother's passes); empty, they come from the local densities."""
    Ts = coef[0]
    rows = state[ROWS].reshape((4, 3))
    q = state[QUAT]
    turned = np.empty((4, 3))
    Ad, Bd, C = np.empty((2, 2)), np.empty(2), np.array([1.0, 0.0])
    imposed = omega_in.shape[0] > 0
    for k in range(gyr.shape[0]):
        dq = turn_rows(rows, turned, gyr, k, Ts)
        omega = local_omega_g(state, coef, gyr, acc, k, turned)
        if imposed:
            omega = omega_in[k]
        if state[OMEGA] > 0.0:  # keep e = u/ω_g continuous across a change of ω_g
            for i in range(3):
                turned[1, i] *= omega / state[OMEGA]
        state[OMEGA] = omega
        omega_out[k] = omega
        state[T] += Ts
        if state[T] * omega < SQRT2:
            # start-up, within the filter's time constant √2/ω_g: the mean of the
            # accelerometer so far in the gyro frame (no state velocity)
            n = state[T] / Ts
            for i in range(3):
                rows[0, i] = turned[0, i] + (acc[k, i] - turned[0, i]) / n
                rows[1, i] = 0.0
                gravity[k, i] = rows[0, i]
        else:
            butterworth_zoh(omega * Ts, Ad, Bd)
            filter_rows(rows, turned, acc, k, Ad, Bd, C, 0.0, gravity)
        for i in range(3):
            rows[2, i], rows[3, i] = turned[2, i], turned[3, i]
        level_onto_gravity(q, dq, gravity, k)
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q[0], q[1], q[2], q[3]


@kernel()
def run(state, coef, gyr, acc, gravity, quat):
    """The kernel-method interface (blocks.methods.registry.KernelStepper): local break frequencies."""
    run_schedule(state, coef, gyr, acc, gravity, quat, np.empty(0), np.empty(gyr.shape[0]))
