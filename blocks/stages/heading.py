"""Heading from the magnetometer (the "heading estimator" box of Rizun's Fig. 1).

Takes the attitude filter's orientation (heading from the integrated gyro) and turns it
about earth up by ψ_c, which follows the heading of the tilt-compensated field: with q'
= Rz(ψ_c)·q and m_e = R(q')·m, the field should point north (ENU y) in the horizontal
plane, so δψ = atan2(m_e,x, m_e,y) is the heading error's negative and ψ_c += a·clip(δψ) with
a = 1 − exp(−Ts/tau) and the innovation clipped to ±heading_clip (a robust update: a
disturbance that slips through the guard pulls by at most heading_clip/tau_heading per
second). Start-up: over the first tau_heading seconds every sample is used, unclipped,
with the weight 1/n of a running mean, and the reference norm and dip are their running
means (the first samples may come in motion, while the tilt is still settling); ψ_c's
running mean takes each sample's own heading, not the low-passed field's (below), in which
a tilt still settling would linger. The field
the heading follows and the guard judges is the tilt-compensated one (earth frame) through a
first-order low-pass of tau_mag_guard: a field fixed in the earth frame passes unchanged, the
sensor's noise is averaged (a fast, noisy magnetometer's samples would otherwise leave the
tolerances by noise alone, and the clipped innovations would pull less than the error), and a
disturbance is seen within tau_mag_guard. Unset (the default), tau_mag_guard follows the noise
the magnetometer shows: σ², the mean over the axes of (π/2)·(mean |Δ²m|)²/6 over the field's
distinct samples so far (Δ² the second difference in the earth frame; a sample repeating the
last, held, is left out), T their mean spacing, and tau_mag_guard the time that leaves white
noise of σ per sample, σ²·T/(2·tau), the guard's tightest tolerance (min(mag_norm_tol,
mag_dip_tol)·|m|) GUARD_NOISE_MARGIN standard deviations wide: no low-pass for a quiet
magnetometer, none before a second difference. Then
the guard against magnetic disturbances: a sample is used only while the field's norm
and dip stay within tolerance of the reference, which is tracked slowly (tau_reference)
over accepted samples; otherwise the heading is the gyro's. A new reference: a field
outside the reference's tolerance that stays steady (norm and dip within the same
tolerances of their own running mean) for mag_new_time while the sensor turns through
mag_new_angle is taken as proven: the estimator starts afresh from it, with the
start-up's running means. A homogeneous field keeps its norm and dip when the
sensor turns, a field fixed to the sensor (a magnet carried along) does not, so a wrong
reference from a disturbed start, or a move to a place whose field differs (another
room or building), no longer locks the magnetometer out for good. Turning cannot tell a
disturbance fixed in the room (a monitor beside a resting sensor) from the earth's field:
after mag_new_time of turning there it is taken too, and left the same way.
Before all this the field is freed of a hard-iron offset, a field fixed to the sensor,
when a sphere fit proves one (blocks.stages.hard_iron; its parameters are listed here too), and
a magnetometer that trails the gyro by mag_delay seconds (its own filters and sample
time; given, or unset estimated online by blocks.stages.mag_delay) is read against the
orientation it had then, q turned back by mag_delay at the rate of the last step: a
field seen late in a fast turn would otherwise show a heading error and a dip that
changes with the turn (which the guard refuses). Inclination is
untouched: the correction turns about the vertical only.

One step per sample, in the C core (blocks/core/stages/heading.c, hard_iron.c, mag_delay.c);
its parameters are blocks.tuning.HEADING (with the hard-iron fit's and the delay's). Times
count steps, so a slower magnetometer keeps the time constants in seconds.
"""
from __future__ import annotations

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, given, resting, sample_system, with_c_step

STATE_NAMES = _core.HEADING_STATE_NAMES  # the state vector's entries: the C core's struct AfHeading
GUARD_NOISE_MARGIN = _core.GUARD_NOISE_MARGIN  # blocks.tuning's, as the C core has it
REST_INPUTS = (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)  # the stage's natural rest: q the identity, a field north (µT)


def resolve(overrides=None) -> dict:
    """The stage's parameters (blocks.tuning.HEADING; mag_delay None: estimated online): the
    defaults updated by overrides, each checked (ValueError: unknown, not a finite number,
    outside its range)."""
    return _core.resolve_params("heading", overrides)


def coefficients(params, Ts: float) -> np.ndarray:
    """The stage's coefficients at the step (IMU sample) time Ts (s) from its parameters (as
    resolve gives them; blocks/core/stages/heading.h lists them)."""
    return _core.heading_coefficients(params, Ts)


def initial_state() -> np.ndarray:
    """The state before any sample (STATE_NAMES; the last step's orientation 0: none yet)."""
    return _core.heading_initial_state()


def heading_system(dt: float, params=None, name: str = "heading"):
    """Discrete python-control system of the heading stage: inputs q_w..z (the attitude
    filter's orientation) and mag_x..z (µT); outputs qh_w..z, the orientation with
    magnetometer heading, and mag_offset_x..z, the hard-iron estimate. x0: initial_state(),
    or the zero state, which stands for it. Marked with its C step, "heading" (the params
    given, as given)."""
    coef = coefficients(resolve(params), dt)

    def advance(state, u):
        out, offset = np.empty((1, 4)), np.empty((1, 3))
        _core.heading_run(state, coef, u[0:4].reshape(1, 4), u[4:7].reshape(1, 3), out, np.empty(1, dtype=np.bool_),
                          offset, np.empty(1))
        return state, np.concatenate([out[0], offset[0]])

    def run(state, rows):
        n = len(rows)
        _core.heading_run(state, coef, np.ascontiguousarray(rows[:, 0:4]), np.ascontiguousarray(rows[:, 4:7]),
                          np.empty((n, 4)), np.empty(n, dtype=np.bool_), np.empty((n, 3)), np.empty(n))

    system = sample_system(advance, [f"q_{c}" for c in "wxyz"] + [f"mag_{c}" for c in "xyz"],
                           [f"qh_{c}" for c in "wxyz"] + [f"mag_offset_{c}" for c in "xyz"],
                           STATE_NAMES, dt, name, start=lambda u: initial_state())
    return with_c_step(system, CStep("heading", dt, **given(params), start=True,
                                     rest=lambda u: resting(run, initial_state(), u, dt), rest_inputs=REST_INPUTS))


def _run_arrays(quat, mag):
    """(quat, mag) contiguous float arrays and the heading stage's outputs allocated for their N
    rows: orientation N×4, accepted N, hard-iron offset N×3, delay N."""
    quat = np.ascontiguousarray(quat, dtype=float)
    n = len(quat)
    outputs = (np.empty((n, 4)), np.empty(n, dtype=np.bool_), np.empty((n, 3)), np.empty(n))
    return quat, np.ascontiguousarray(mag, dtype=float), outputs


def with_magnetometer(quat, mag, fs: float, params=None):
    """(orientation with magnetometer heading N×4, accepted N, hard-iron offset N×3 in the
    field's unit, the magnetometer's delay allowed for N in s) for a whole recording: quat
    N×4 (sensor → earth, the attitude filter's), mag N×3 (a row with a NaN: no field sample)."""
    quat, mag, outputs = _run_arrays(quat, mag)
    _core.heading_run(initial_state(), coefficients(resolve(params), 1.0 / fs), quat, mag, *outputs)
    return outputs


def smoothed_with_magnetometer(quat, mag, fs: float, params=None):
    """with_magnetometer's outputs with the heading smoothed over the whole recording: the
    stage forward, then backward in time, each row's correction the two passes' averaged,
    weighted by what each has seen (blocks/core/pipeline/offline.h: offline_heading); accepted:
    used by either pass; the hard-iron offset and delay the forward pass's. params must give
    mag_delay (s; ValueError otherwise): backward in time the field leads the gyro by it."""
    quat, mag, outputs = _run_arrays(quat, mag)
    _core.heading_smooth(coefficients(resolve(params), 1.0 / fs), quat, mag, *outputs)
    return outputs
