"""Rizun's Wiener filter with its noise densities estimated locally (the default `wiener`).

Eq. 34 is optimal for stationary noise: ω_g = √(g·δn/δv) (eq. 25). Real motion is not
stationary (rest, slow turns, fast translation) and a real gyro's error is not only white
noise: its scale-factor and misalignment errors S (each element of rms σ_s, datasheet)
add S·ω, which grows with the rotation. This filter keeps eq. 34 carried into the sensor
frame (blocks.sensor_frame) and re-derives ω_g every sample from densities of the same
noise model, measured over the last τ seconds (`tau_noise`):

- gyro: δn_eff² = δn² + σ_s²·S_ω(0), where S_ω(0) = 4·⟨|ω|²⟩/ω_m is the low-frequency
  density of an angular rate band-limited (first order) at ω_m (Rizun eq. 14's shape);
- slosh: δv² = 4·(ω_m + 1/τ_v)/ω_m² · ⟨|v|²⟩/3, with v the velocity residual, the
  accelerometer minus the gravity estimate integrated in the gyro frame and high-passed
  at 1/τ_v: the variance such a high-pass leaves of eq. 14's velocity, solved for δv.
  It is held above delta_v_min (rest).

With σ_s = 0 and a steady motion the estimates settle on the stationary densities and the
filter on eq. 34. The Butterworth runs in the realisation d/dt[ĝ, u] = ω_g·M·[ĝ, u] +
ω_g·[0, 1]·y_a with M = [[0, 1], [−1, −√2]] (u = ω_g·e, e the velocity residual of the
filter), whose zero-order hold has a closed form for every ω_g; e is kept continuous when
ω_g changes. One compiled step serves the python-control block, the batch path and the FMU.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .sensor_frame import filter_rows, level_onto_gravity, turn_rows

STATE_NAMES = (
    "g_x", "g_y", "g_z",  # gravity estimate ĝ, m/s², sensor coordinates
    "u_x", "u_y", "u_z",  # ω_g·e, e the filter's velocity residual (m/s), so m/s²
    "v_x", "v_y", "v_z",  # high-passed velocity residual of the noise estimate, m/s
    "q_w", "q_x", "q_y", "q_z",  # orientation, sensor → earth
    "w2", "v2", "omega_g",  # ⟨|ω|²⟩ (rad²/s²), ⟨|v|²⟩/3 (m²/s²), last break frequency (rad/s)
)
ROWS = slice(0, 9)
QUAT = slice(9, 13)
SQRT2 = math.sqrt(2.0)


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts, g, δn², k_w, k_v, δv_min², a_avg, leak_v]: δn_eff² = δn² + k_w·⟨|ω|²⟩,
    δv² = k_v·⟨|v|²⟩/3, a_avg = 1 − exp(−Ts/τ), leak_v = exp(−Ts/τ_v)."""
    wm, tau_v = params["omega_m"], params["tau_v"]
    return np.array([
        Ts, params["g"], params["delta_n"] ** 2, 4.0 * params["scale_error"] ** 2 / wm,
        4.0 * (wm + 1.0 / tau_v) / wm**2, params["delta_v_min"] ** 2,
        1.0 - math.exp(-Ts / params["tau_noise"]), math.exp(-Ts / tau_v),
    ])


def initial_state(coef, acc0) -> np.ndarray:
    """At rest on acc0 (m/s²): ĝ = acc0, no residuals, q = identity, no motion seen yet."""
    state = np.zeros(len(STATE_NAMES))
    state[0:3] = acc0
    state[QUAT] = (1.0, 0.0, 0.0, 0.0)
    return state


SERIES_WT = 0.02  # below it the Taylor series of exp(M·wt) to wt⁸ is exact to double precision


@kernel(inline=True)
def butterworth_zoh(wt, Ad, Bd):
    """Ad = exp(M·wt), Bd = M⁻¹·(Ad − I)·[0, 1] for wt = ω_g·Ts (rad). M has eigenvalues
    (−1 ± i)/√2, so exp(M·t) = e^(−t/√2)·(cos(t/√2)·I + √2·sin(t/√2)·(M + I/√2)); for
    small wt its Taylor series (Horner form, no transcendental calls) is used instead."""
    if wt < SERIES_WT:
        # columns of I + M·wt·(I + M·wt/2·(I + … (I + M·wt/8))), kept as [[p, q], [r, s]]
        p, q, r, t = 1.0, 0.0, 0.0, 1.0
        for j in range(8, 0, -1):
            c = wt / j
            # I + c·M·X with M·X = [[r, t], [−p − √2·r, −q − √2·t]]
            p, q, r, t = 1.0 + c * r, c * t, -c * (p + SQRT2 * r), 1.0 - c * (q + SQRT2 * t)
        Ad[0, 0], Ad[0, 1], Ad[1, 0], Ad[1, 1] = p, q, r, t
    else:
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
    frame) and return ω_g = √(g·δn_eff/δv), rad/s. Writes the new velocity residual into
    turned[2]."""
    Ts, g, dn2, k_w, k_v, dv2_min, a_avg, leak = (
        coef[0], coef[1], coef[2], coef[3], coef[4], coef[5], coef[6], coef[7])
    v2 = 0.0
    for i in range(3):
        turned[2, i] = leak * turned[2, i] + Ts * (acc[k, i] - turned[0, i])
        v2 += turned[2, i] * turned[2, i]
    w2 = gyr[k, 0] * gyr[k, 0] + gyr[k, 1] * gyr[k, 1] + gyr[k, 2] * gyr[k, 2]
    state[13] += a_avg * (w2 - state[13])
    state[14] += a_avg * (v2 / 3.0 - state[14])
    dv2 = max(k_v * state[14], dv2_min)
    return math.sqrt(g * math.sqrt((dn2 + k_w * state[13]) / dv2))


@kernel()
def run_schedule(state, coef, gyr, acc, gravity, quat, omega_in, omega_out):
    """Over N samples: gravity (N×3, m/s²), quat (N×4) and the break frequency used
    (omega_out, N, rad/s) per sample. omega_in (N, rad/s) imposes the break frequencies
    (the offline smoother's passes); empty, they come from the local densities."""
    Ts = coef[0]
    rows = state[ROWS].reshape((3, 3))
    q = state[QUAT]
    turned = np.empty((3, 3))
    Ad, Bd, C = np.empty((2, 2)), np.empty(2), np.array([1.0, 0.0])
    imposed = omega_in.shape[0] > 0
    for k in range(gyr.shape[0]):
        dq = turn_rows(rows, turned, gyr, k, Ts)
        omega = local_omega_g(state, coef, gyr, acc, k, turned)
        if imposed:
            omega = omega_in[k]
        if state[15] > 0.0:  # keep e = u/ω_g continuous across a change of ω_g
            for i in range(3):
                turned[1, i] *= omega / state[15]
        state[15] = omega
        omega_out[k] = omega
        butterworth_zoh(omega * Ts, Ad, Bd)
        filter_rows(rows, turned, acc, k, Ad, Bd, C, 0.0, gravity)
        for i in range(3):
            rows[2, i] = turned[2, i]
        level_onto_gravity(q, dq, gravity, k)
        quat[k, 0], quat[k, 1], quat[k, 2], quat[k, 3] = q[0], q[1], q[2], q[3]


@kernel()
def run(state, coef, gyr, acc, gravity, quat):
    """The kernel-method interface (blocks.methods.KernelStepper): local break frequencies."""
    run_schedule(state, coef, gyr, acc, gravity, quat, np.empty(0), np.empty(gyr.shape[0]))
