"""Gyroscope-offset estimator (the "gyro offset estimator" box of Rizun's Fig. 1).

At rest: the gyro and the accelerometer, each through a short low-pass (tau_short, which
takes the white noise above human motion's band out), must stay close to their values
low-passed over tau_lp (rest_gyr, rest_acc), and the gyro low-passed over tau_lp must
stay small (rest_gyr_abs), for rest_time seconds; then each gyro sample, low-passed over
tau_rest from the rest's start (a rest's last tremor and a turn not quite stopped averaged
out, as vqf measures a rest from its low-passed gyro), measures the offset
with the variance of the gyro's white noise, delta_n²·fs/2, in the same Kalman filter as
the tracking while moving: a first rest after an uncertain start gives the running mean
of the rest's samples, and a long rest settles on a window of delta_n/sigma_motion·
√(tau_motion/2) s (7 s by default), whatever the sample rate. Without the short low-pass
(raw samples, as vqf tests them) a gyro whose white noise alone comes near rest_gyr
(δn·√(3·fs/2), e.g. 0.1 °/s/√Hz at 250 Hz) would seldom or never rest; through it the
noise is δn·√(3/(4·tau_short)), 0.6 °/s for 0.1 °/s/√Hz at any rate. A noisier gyro
(delta_n given) raises the threshold to REST_NOISE_SIGMAS times its per-axis noise
there, δn/√(4·tau_short), so that its own noise does not break every rest (up to
0.125 °/s/√Hz the default rest_gyr is above that floor).

While moving, the offset's effect on the accelerometer is tracked in the gyro frame (the
frame integrated from the corrected gyro; R its sensor → gyro-frame rotation), the way
vqf (Laidig & Seel 2023) does. There the accelerometer is low-passed by eq. 34's
Butterworth at √2/tau_acc, which averages the motion's acceleration out as in Rizun's
filter, and an offset error Δb turns gravity at the rate R·Δb, so the low-passed
direction turns at c = H·Δb with H = Π·LP(R) (Π: the projection across gravity; LP the
same low-pass). A Kalman filter (variance from sigma_init, process noise such that the
variance settles on sigma_motion² and forgets in tau_motion) updates the estimate from
c. Guards, all from the same model:
- while the sensor turns quickly about an axis, LP(R) averages out the offset's
  components across it; directions in which H keeps less than half of them are left
  alone, since a sensor-fixed (e.g. centripetal) acceleration looks the same there;
- innovations are clipped at 4·sigma_init, the fastest turn a plausible offset makes;
- over the first tau_acc the accelerometer's low-pass is the running mean of its samples
  in the gyro frame (as the Wiener filter starts), not a Butterworth from the first
  sample, which in motion can be off by metres per second squared and would turn the
  low-passed direction for several tau_acc after; no update in the first 3·tau_acc,
  while the low-passes forget their start.
The online lever arm (tau_arm; none where tau_motion is 0): a sensor turned about a fixed
centre (a robot's wrist) reads α×r + ω×(ω×r) beside gravity, an acceleration a tilt filter
takes for tilt and whose centripetal part keeps one sign in the sensor's frame. At about
ARM_RATE_HZ (blocks/core/stages/gyro_offset.h) the accelerometer and those terms, both turned
into the gyro frame (ω the corrected gyro's mean over the sample, α its difference) and
high-passed over 10 s (gravity, and the slow turn an offset error gives the frame), feed
least-squares sums that forget over tau_arm; their solution r (m, sensor coordinates) is
removed from the accelerometer handed to the method from the next sample on, where it explains
at least 90 % of what the high-pass leaves, at least 0.05 m/s² RMS of it, is under 3 m, and
what is left is carried by four fit samples or more ((Σ|y|²)²/Σ|y|⁴: a motion's abrupt onset
after a quiet rest, one sample, fits some arm); else nothing is removed (at rest, in hand-held
motion, on a centre that moves itself).
Offline the arm is fitted over the whole recording instead (blocks.stages.lever_arm).
The corrected gyro is the measured one minus the estimate after its sample. Causal: one step
per sample, in the C core (blocks/core/stages/gyro_offset.c); its parameters are
blocks.tuning.GYRO_OFFSET.
"""
from __future__ import annotations

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.control_system import CStep, given, resting, sample_system, with_c_step
from attitude_fmu.blocks.filters.sensor_frame import REST_INPUTS, time_reversed

STATE_NAMES = _core.GYRO_OFFSET_STATE_NAMES  # the state vector's entries: the C core's struct AfGyroOffset


def resolve(overrides=None) -> dict:
    """The estimator's parameters (blocks.tuning.GYRO_OFFSET): the defaults updated by
    overrides, each checked (ValueError: unknown, not a finite number, outside its range)."""
    return _core.resolve_params("gyro_offset", overrides)


def coefficients(params, Ts: float) -> np.ndarray:
    """The estimator's coefficients at the sample time Ts (s) from its parameters (as resolve
    gives them; blocks/core/stages/gyro_offset.h lists them)."""
    return _core.gyro_offset_coefficients(params, Ts)


def initial_state(coef, gyr0, acc0) -> np.ndarray:
    """Low-passes (both) on the first samples gyr0 (rad/s) and acc0 (m/s²), not at rest, no
    offset (variance σ_init²), the gyro frame on the sensor, the low-pass of R settled on I
    (that of the accelerometer starts as the running mean of the first samples)."""
    return _core.gyro_offset_initial_state(coef, np.asarray(gyr0, dtype=float), np.asarray(acc0, dtype=float))


def offset_system(dt: float, params=None, name: str = "gyro_offset"):
    """Discrete python-control system of the estimator: inputs gyr_raw_x..z (rad/s, the
    measured gyro) and acc_raw_x..z (m/s², the measured accelerometer); outputs gyr_x..z, the
    gyro less the offset estimate after the sample (rad/s), offset_x..z, and acc_x..z, the
    accelerometer less the online lever arm's accelerations (m/s², the measured one where no
    arm is proven). x0: initial_state, or the zero state, with which it starts at rest on its
    first sample. Marked with its C step, "gyro_offset" (the params given, as given)."""
    coef = coefficients(resolve(params), dt)

    def advance(state, u):
        offset, variance, acc = np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3))
        _core.gyro_offset_run(state, coef, u[0:3].reshape(1, 3), u[3:6].reshape(1, 3), offset, variance, acc_out=acc)
        return state, np.concatenate([u[0:3] - offset[0], offset[0], acc[0]])

    def start(u):
        return initial_state(coef, u[0:3], u[3:6])

    def run(state, rows):
        _core.gyro_offset_run(state, coef, np.ascontiguousarray(rows[:, 0:3]), np.ascontiguousarray(rows[:, 3:6]),
                              np.empty((len(rows), 3)), np.empty((len(rows), 3)))

    system = sample_system(advance, [f"{s}_{a}" for s in ("gyr_raw", "acc_raw") for a in "xyz"],
                           [f"{s}_{a}" for s in ("gyr", "offset", "acc") for a in "xyz"], STATE_NAMES, dt, name,
                           start=start)
    return with_c_step(system, CStep("gyro_offset", dt, **given(params), start=True,
                                     rest=lambda u: resting(run, start(u), u, dt), rest_inputs=REST_INPUTS))


def correct(gyr, acc, fs: float, params=None, offline: bool = False):
    """(corrected gyro, offset estimate), both N×3 rad/s, over a whole recording (estimated
    as offset_estimate does)."""
    offset, _ = offset_estimate(gyr, acc, fs, params, offline)
    return np.asarray(gyr, dtype=float) - offset, offset


def _pass(coef, gyr, acc, allowed=None, resting: bool = False, freed: bool = False):
    """One causal pass over contiguous gyr, acc (N×3) from the start at rest on their first row:
    (offset N×3, variance N×3, resting flags N or None, acc freed of the online lever arm N×3 or None),
    the optional outputs only where wanted; allowed as _core.gyro_offset_run takes it."""
    offset, variance = np.empty_like(gyr), np.empty_like(gyr)
    flags = np.empty(len(gyr), dtype=np.bool_) if resting else None
    out = np.empty_like(acc) if freed else None
    _core.gyro_offset_run(initial_state(coef, gyr[0], acc[0]), coef, gyr, acc, offset, variance, allowed, flags,
                          acc_out=out)
    return offset, variance, flags, out


def online_pass(gyr, acc, fs: float, params=None):
    """The estimator's causal pass over a whole recording (gyr N×3 rad/s, acc N×3 m/s², fs Hz):
    (offset estimate N×3 rad/s, its variance per axis N×3 (rad/s)², acc freed of the online
    lever arm's accelerations N×3 m/s², as the causal pipeline hands it to the method)."""
    gyr = np.ascontiguousarray(gyr, dtype=float)
    acc = np.ascontiguousarray(acc, dtype=float)
    offset, variance, _, freed = _pass(coefficients(resolve(params), 1.0 / fs), gyr, acc, freed=True)
    return offset, variance, freed


def offset_estimate(gyr, acc, fs: float, params=None, offline: bool = False):
    """(offset estimate N×3 rad/s, its variance N×3 (rad/s)², per axis) over a whole
    recording: gyr N×3 rad/s, acc N×3 m/s², fs Hz. offline: the estimates of a forward and a
    backward pass in time (whose gyro is blocks.filters.sensor_frame.time_reversed, its offset
    the negative) combined per axis as two independent measurements of one offset that share
    the prior (0 with variance sigma_init²), which is counted once: information
    1/v = 1/v_f + 1/v_b − 1/sigma_init², offset v·(x_f/v_f + x_b/v_b). A pass that learnt
    nothing of an axis (a vertical axis never at rest in its direction of time) then leaves
    it to the other, where an average by inverse variances pulled it back towards 0.
    There a rest's sample measures the offset only where the rest holds rest_time after it as
    well (the detection backward in time), so that a motion's slow onset is not taken for
    rest."""
    gyr = np.ascontiguousarray(gyr, dtype=float)
    acc = np.ascontiguousarray(acc, dtype=float)
    resolved = resolve(params)
    coef = coefficients(resolved, 1.0 / fs)

    def one_pass(g, a, allowed=None):
        return _pass(coef, g, a, allowed, resting=True)[:3]

    if not offline:
        return _pass(coef, gyr, acc)[:2]
    # a rest's sample measures the offset where the rest holds rest_time before and after it: a motion's onset,
    # which the detection still takes for rest, is then no rest backward in time
    backward = time_reversed(gyr), np.ascontiguousarray(acc[::-1])
    resting_back = one_pass(*backward)[2]
    offset, variance, resting = one_pass(gyr, acc, np.ascontiguousarray(resting_back[::-1]))
    back, back_variance, _ = one_pass(*backward, np.ascontiguousarray(resting[::-1]))
    forward_info, back_info = 1.0 / variance, 1.0 / back_variance[::-1]
    # each pass's variance is at most sigma_init² (its forgetting stops there), so the sum stays >= 1/sigma_init²
    combined = 1.0 / (forward_info + back_info - 1.0 / resolved["sigma_init"] ** 2)
    return combined * (forward_info * offset - back_info * back[::-1]), combined
