"""Online estimate of the magnetometer's delay behind the gyro (for blocks.stages.heading).

A homogeneous field seen from a turning sensor obeys ṁ = −ω × m (m freed of hard iron,
sensor frame). A magnetometer late by d sees ṁ(t) = −ω(t − d) × m ≈ −ω × m + d·ω̇ × m.
Both sides low-passed to first order at 1/MAG_SPAN_S (the spans of the batch measurement,
blocks.stages.delays) give y = L[ṁ + ω × m] = d·L[ω̇ × m] = d·J, and d is their least-squares
ratio Σ y·J / Σ |J|², over the field samples the guard accepted, and accepted for
MAG_DELAY_CLEAN_S before (three spans: the low-passes no longer hold a refused field,
whose edge, a disturbance coming or going, would pass for a delay), with a memory of
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

The estimate runs per step in the C core (blocks/core/stages/mag_delay.c), as part of the
heading stage; its parameter is blocks.tuning.MAG_DELAY. The constants below are the core's.
"""
from attitude_fmu._core import MAG_DELAY_CLEAN_S, MAG_DELAY_MIN_S, MAG_DELAY_REACH_S, MAG_DELAY_SIGMAS, MAG_SPAN_S

__all__ = ["MAG_SPAN_S", "MAG_DELAY_REACH_S", "MAG_DELAY_SIGMAS", "MAG_DELAY_MIN_S", "MAG_DELAY_CLEAN_S"]
