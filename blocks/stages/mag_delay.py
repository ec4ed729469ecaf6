"""Online estimate of the magnetometer's delay behind the gyro (for blocks.stages.heading).

A homogeneous field seen from a turning sensor obeys ṁ = −ω × m (m freed of hard iron,
sensor frame). A magnetometer late by d sees ṁ(t) = −ω(t − d) × m ≈ −ω × m + d·ω̇ × m.
Both sides low-passed to first order at 1/MAG_SPAN_S (the spans of the batch measurement,
blocks.stages.delays) give y = L[ṁ + ω × m] = d·L[ω̇ × m] = d·J, and d is their least-squares
ratio Σ y·J / Σ |J|², over the field samples the guard accepted, with a memory of
tau_mag_delay. Between two field samples (a slower magnetometer) the rate is summed:
over the interval Δ, ṁ·Δ = m₁ − m₀, ∫ω × m ≈ (∫ω)×(m₀ + m₁)/2 and
∫ω̇ × m ≈ (ω₁ − ω₀)×(m₀ + m₁)/2, with ω the last step's rate.

The residual's standard error takes the low-pass's correlation time 1/a (an upper bound:
the magnetometer's white noise differentiated is bluer): SE² = (2/a)·⟨|r|²⟩/(3·Σ|J|²·Δ).
The delay in use changes only when the estimate lies MAG_DELAY_SIGMAS standard errors
from 0 or more, over MAG_DELAY_MIN_S of samples at least; it is clipped to
[0, MAG_DELAY_REACH_S] and otherwise held (0 at the start), so a rest, which carries no
information, keeps the last value. A hard-iron offset taken or dropped (the field
changes) starts the estimate afresh.
"""
from __future__ import annotations

import math

import numpy as np

from attitude_fmu.blocks.jit import kernel
from attitude_fmu.blocks.params import TIME_S, Param

MAG_SPAN_S = 0.25  # s: the field is compared with the gyro over about this long
MAG_DELAY_REACH_S = 0.1  # s: the largest delay looked for
MAG_DELAY_SIGMAS = 3.0  # a delay is taken only this many standard errors or more from 0
MAG_DELAY_MIN_S = 5.0  # s of accepted field samples in the sums before a delay is taken (a few samples fit any)

PARAMS = (
    Param("tau_mag_delay", 60.0, "s", "memory of the online estimate of the magnetometer's delay (mag_delay unset)",
          **TIME_S),
)
STATE_NAMES = (
    "m_x", "m_y", "m_z",  # the last field sample (sensor frame, hard iron removed)
    "w_x", "w_y", "w_z",  # the rate at it (rad/s)
    "turn_x", "turn_y", "turn_z",  # ∫ω dt since it (rad)
    "since",  # time since it (s)
    "seen",  # 1 once there was one
    "y_x", "y_y", "y_z",  # L[ṁ + ω × m]
    "j_x", "j_y", "j_z",  # L[ω̇ × m]
    "s_yj", "s_jj", "s_yy", "s_t",  # Σy·J·Δ, Σ|J|²·Δ, Σ|y|²·Δ, ΣΔ (forgotten over tau_mag_delay)
    "delay",  # the delay in use (s)
)
LAST_M, LAST_W, TURN, SINCE, SEEN, Y, J, SUMS, DELAY = (
    slice(0, 3), slice(3, 6), slice(6, 9), 9, 10, slice(11, 14), slice(14, 17), slice(17, 21), 21)
STATE_SIZE = len(STATE_NAMES)
COEF_SIZE = 6


def coefficients(params, Ts: float) -> np.ndarray:
    """[Ts (s), a = 1/MAG_SPAN_S (rad/s), 1/tau_mag_delay (1/s), MAG_DELAY_SIGMAS, MAG_DELAY_REACH_S (s),
    MAG_DELAY_MIN_S (s)]."""
    return np.array([Ts, 1.0 / MAG_SPAN_S, 1.0 / params["tau_mag_delay"], MAG_DELAY_SIGMAS, MAG_DELAY_REACH_S,
                     MAG_DELAY_MIN_S])


@kernel(inline=True)
def turn(state, coef, rotation):
    """Every step: add the step's rotation (rad, 3-tuple) to ∫ω dt."""
    for i in range(3):
        state[TURN.start + i] += rotation[i]
    state[SINCE] += coef[0]


@kernel(inline=True)
def restart(state):
    """Forget every sample (a hard-iron offset taken or dropped); the delay in use is reset to 0."""
    state[:] = 0.0


@kernel(inline=True)
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@kernel(inline=True)
def field_sample(state, coef, m, w, use):
    """A field sample m (sensor frame, hard iron removed) with the step's rate w: take the
    interval since the last one into the estimate when use (the guard accepted it)."""
    dt, last_m, last_w, turned = state[SINCE], state[LAST_M], state[LAST_W], state[TURN]
    y_lp, j_lp, sums = state[Y], state[J], state[SUMS]
    if state[SEEN] > 0.0 and dt > 0.0:
        a, lag = coef[1], math.exp(-coef[1] * dt)
        mid = (0.5 * (m[0] + last_m[0]), 0.5 * (m[1] + last_m[1]), 0.5 * (m[2] + last_m[2]))
        carried = _cross((turned[0], turned[1], turned[2]), mid)  # ∫ω × m
        j = _cross((w[0] - last_w[0], w[1] - last_w[1], w[2] - last_w[2]), mid)  # ∫ω̇ × m
        for i in range(3):  # the low-passes, their input constant over the interval
            y_lp[i] = lag * y_lp[i] + (1.0 - lag) * (m[i] - last_m[i] + carried[i]) / dt
            j_lp[i] = lag * j_lp[i] + (1.0 - lag) * j[i] / dt
        if use:
            forget = math.exp(-coef[2] * dt)
            yj = y_lp[0] * j_lp[0] + y_lp[1] * j_lp[1] + y_lp[2] * j_lp[2]
            jj = j_lp[0] * j_lp[0] + j_lp[1] * j_lp[1] + j_lp[2] * j_lp[2]
            yy = y_lp[0] * y_lp[0] + y_lp[1] * y_lp[1] + y_lp[2] * y_lp[2]
            for i, term in enumerate((yj, jj, yy, 1.0)):
                sums[i] = forget * sums[i] + term * dt
            if sums[1] > 0.0 and sums[3] >= coef[5]:
                d = sums[0] / sums[1]
                residual = max(sums[2] - d * sums[0], 0.0) / sums[3]  # ⟨|y − d·J|²⟩
                # |d| ≥ k·SE with SE² = (2/a)·(residual/3)/Σ|J|²Δ
                if d * d * sums[1] * 3.0 * a >= coef[3] * coef[3] * 2.0 * residual:
                    state[DELAY] = min(max(d, 0.0), coef[4])
    for i in range(3):
        last_m[i], last_w[i], turned[i] = m[i], w[i], 0.0
    state[SINCE], state[SEEN] = 0.0, 1.0
