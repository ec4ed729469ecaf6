"""The heading stage sees the tilt-compensated field through the low-pass of tau_mag_guard
(blocks.stages.heading): its step response and its effect on a fast, noisy magnetometer,
against the closed forms of first-order lags."""
import math

import numpy as np

from attitude_fmu import _core
from attitude_fmu.blocks.stages import heading

FIELD = np.array([0.0, 20.0, -45.0])  # µT, ENU
GUARD_OFF = {"tau_mag_guard": 1e-9}  # 1 - exp(-Ts/1 ns) is 1: each sample judged alone
STILL = {"mag_cal_time": 0.0}  # a sensor that does not turn: no hard-iron fit


def _low_passed_field(mag, fs, params):
    """The stage's low-passed field (state m_low_x..z) after each sample of a sensor at rest
    in the identity orientation (sensor frame = earth frame)."""
    names = list(heading.STATE_NAMES)
    low = [names.index(f"m_low_{c}") for c in "xyz"]
    state, coef = heading.initial_state(), heading.coefficients(heading.resolve({**STILL, **params}), 1.0 / fs)
    out = np.empty((len(mag), 3))
    for k, m in enumerate(mag):
        _core.heading_run(state, coef, np.array([[1.0, 0.0, 0.0, 0.0]]), np.array([m]), np.empty((1, 4)),
                          np.empty(1, dtype=np.bool_), np.empty((1, 3)), np.empty(1))
        out[k] = state[low]
    return out


def test_the_field_passes_a_first_order_low_pass_over_missing_samples_too():
    """A field that steps from FIELD to another at sample k0: at each field sample k >= k0 the
    low-passed field is new + (old - new)·exp(-(k - k0 + 1)·Ts/tau_mag_guard), whatever samples
    are missing in between (the pull spans the time since the last one)."""
    fs, tau, k0 = 200.0, 0.05, 100
    new = np.array([5.0, 15.0, -40.0])
    mag = np.tile(FIELD, (200, 1))
    mag[k0:] = new
    mag[[k0 + 3, k0 + 4, k0 + 5, k0 + 20]] = np.nan  # missing samples
    low = _low_passed_field(mag, fs, {"tau_mag_guard": tau})
    assert np.array_equal(low[:k0], np.tile(FIELD, (k0, 1)))
    k = np.arange(k0, len(mag))
    expected = new + np.outer(np.exp(-(k - k0 + 1) / (fs * tau)), FIELD - new)
    sampled = np.isfinite(mag[k0:, 0])
    assert np.abs(low[k0:][sampled] - expected[sampled]).max() < 1e-12
    assert np.array_equal(low[k0 + 3:k0 + 6], np.tile(low[k0 + 2], (3, 1)))  # held over the missing ones


def _jump(fs=1000.0, noise=4.0, jump_deg=8.0, seed=4):
    """60 s of a sensor at rest under FIELD with white noise (µT per axis; 4 µT is 8 % of the
    norm per sample), the orientation given to the stage turned by jump_deg about up at 30 s
    (as a gyro's heading error would be): (time since the jump s, quat, mag)."""
    n, k0 = int(60 * fs), int(30 * fs)
    half = math.radians(jump_deg) / 2.0
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    quat[k0:] = [math.cos(half), 0.0, 0.0, math.sin(half)]
    mag = FIELD + noise * np.random.default_rng(seed).standard_normal((n, 3))
    return (np.arange(n) - k0 + 1) / fs, quat, mag


def test_a_fast_noisy_magnetometer_takes_every_sample_and_the_heading_follows_the_two_lags():
    """At 1000 Hz with 4 µT of noise per axis a sample leaves the guard's 10 % norm or 5° dip by
    noise alone about half the time. Through the low-pass every sample after the start-up is
    taken, and the heading error after the jump is the closed form of the two first-order lags
    in series, jump·(tau_h·exp(-t/tau_h) - tau_g·exp(-t/tau_g))/(tau_h - tau_g), within 0.5°
    (the noise left is 0.16° rms). With the low-pass off, the guard takes about 57 % and the
    clipped innovations pull far less than the error: more than 2° behind that curve."""
    fs, jump = 1000.0, 8.0
    t, quat, mag = _jump(fs, jump_deg=jump)
    defaults = heading.resolve()
    tau_h, tau_g = defaults["tau_heading"], defaults["tau_mag_guard"]
    expected = np.where(t > 0, jump * (tau_h * np.exp(-t / tau_h) - tau_g * np.exp(-t / tau_g)) / (tau_h - tau_g),
                        0.0)
    after_start = slice(int(15 * fs), None)
    for params, taken_least, follows in (({}, 0.999, True), (GUARD_OFF, 0.0, False)):
        out, accepted, _, _ = heading.with_magnetometer(quat, mag, fs, {**STILL, **params})
        error = np.degrees(2.0 * np.arctan2(out[:, 3], out[:, 0])) - expected
        worst = np.abs(error[after_start]).max()
        print(f"{params or 'defaults'}: taken {accepted[after_start].mean():.3f}, worst {worst:.2f}°")
        assert accepted[after_start].mean() >= taken_least
        assert (worst < 0.5) if follows else (worst > 2.0 and accepted[after_start].mean() < 0.8)
