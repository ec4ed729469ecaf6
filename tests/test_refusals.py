"""Refusals of bad configurations, in the words users and tests have relied on (worded now
by the C core): every parameter of every method and stage (blocks/tuning.py, the one table)
refused outside its plausible range with the message its table entry implies, Python's
float repr included; unknown methods, parameters and options; bad sample times, designs
and latencies; Mahony's gains where its step diverges (Jury's criterion)."""
import math

import numpy as np
import pytest

from attitude_fmu import OnlineEstimator, estimate
from attitude_fmu.blocks import tuning

STILL = (np.zeros(3), np.array([0.0, 0.0, 9.81]))
NO_FIELD = np.full(3, np.nan)


def _refusal(config: dict, Ts: float = 0.01) -> str | None:
    """The ValueError an online estimator of config raises, made and stepped once at Ts; None if none."""
    try:
        OnlineEstimator(**config).step(*STILL, Ts, NO_FIELD)
    except ValueError as exc:
        return str(exc)
    return None


def _unit(p) -> str:
    return "" if p.unit == "1" else f" {p.unit}"


def _range(p) -> str:
    """The plausible range as the messages write it: "[1e-12, 1] rad/s/√Hz", "[0, 1e+06] s"."""
    low = "0" if p.allow_zero or p.low == 0 else f"{p.low:g}"
    return f"{'[' if p.allow_zero or p.low > 0 else '('}{low}, {p.high:g}]{_unit(p)}"


def expected_refusal(p, value) -> str | None:
    """The message a value of parameter p is refused with (None: taken): not a finite number,
    or not positive (negative where p.allow_zero); not one of p.choices; outside [low, high]."""
    if not (math.isfinite(value) and (value >= 0 if p.allow_zero else value > 0)):
        return (f"parameter {p.name} must be a finite {'non-negative' if p.allow_zero else 'positive'} number "
                f"({_range(p)}), got {value!r}")
    if p.choices is not None and value not in p.choices:
        return f"parameter {p.name} must be {' or '.join(f'{c:g}' for c in p.choices)}, got {value!r} ({p.doc})"
    if not p.low <= value <= p.high:
        return f"parameter {p.name} = {value:g}{_unit(p)} is outside its plausible range {_range(p)} ({p.doc})"
    return None


def _values(p, rng) -> list[float]:
    """Values on both sides of every check of p: signs, zero, non-finite numbers, the range's
    ends and just beyond, far beyond, choices and a value between them, random magnitudes."""
    values = [-1.0, 0.0, -0.0, math.inf, -math.inf, math.nan, p.low, p.high, p.high * (1 + 1e-15), p.high * 10.0,
              1e300, -5e-324, *(-float(x) for x in rng.lognormal(0.0, 8.0, 3))]
    if not p.allow_zero:  # (a positive denormal where 0 is a setting overflows the coefficients: refused otherwise)
        values.append(5e-324)
    if p.low > 0:
        values += [p.low * 0.5, p.low * (1 - 1e-15)]
    if p.choices:
        values += [*p.choices, 0.5 * (p.choices[0] + p.choices[-1])]
    else:
        values.append(p.default if p.default is not None else p.high)
    return values


STAGES = [(f"the method {name}", dict(method=name, gyro_offset=False), params)
          for name, (_, params) in tuning.METHODS.items()]
STAGES += [(label, dict(method="tseng", heading=True, gyro_offset=True), params)
           for label, params in tuning.ESTIMATORS.items()]


@pytest.mark.parametrize("label, config, params", STAGES, ids=[s[0] for s in STAGES])
def test_every_parameter_outside_its_range_is_refused_with_the_message_its_table_entry_implies(label, config, params):
    rng = np.random.default_rng(len(label))
    checked = 0
    for p in params:
        for value in _values(p, rng):
            if p.name in ("omega_c", "omega_g", "omega_f", "delta_v") and expected_refusal(p, value) is None:
                continue  # taken, but a design of their own (eq. 33's omega_c > omega_g/√2): the tests below
            got = _refusal({**config, "params": {p.name: value}}, Ts=1e-5)  # Mahony's gains stable up to their high
            assert got == expected_refusal(p, value), (label, p.name, value)
            checked += got is not None
    assert checked >= 8 * len(params)


@pytest.mark.parametrize("config, message", [
    (dict(method="kalman"), "unknown method 'kalman'; available: wiener, tseng, tseng_adaptive, luinge, mahony, "
                            "first_order"),
    (dict(method=None), "unknown method None; available: wiener, tseng, tseng_adaptive, luinge, mahony, first_order"),
    (dict(params={"tau_heading": 5.0}),
     "unknown parameter 'tau_heading' (the method wiener: delta_n, delta_v, g, omega_g, omega_c, stationary, "
     "scale_error, omega_m, tau_noise, tau_v, delta_v_min; the gyro-offset estimator: rest_gyr, rest_gyr_abs, "
     "rest_acc, rest_time, tau_lp, tau_short, tau_rest, delta_n, tau_acc, sigma_init, sigma_motion, tau_motion, "
     "tau_arm)"),
    (dict(method="mahony", params={"delta_n": 0.001}, gyro_offset=False),
     "unknown parameter 'delta_n' (the method mahony: k_P, k_I, g)"),
    (dict(method="tseng", params={"k_P": 1.0}, heading=True),
     "unknown parameter 'k_P' (the method tseng: none; the gyro-offset estimator: rest_gyr, rest_gyr_abs, rest_acc, "
     "rest_time, tau_lp, tau_short, tau_rest, delta_n, tau_acc, sigma_init, sigma_motion, tau_motion, tau_arm; "
     "the heading estimator: tau_heading, delta_n, heading_drift, sigma_motion, mag_norm_tol, mag_dip_tol, "
     "tau_mag_guard, tau_reference, heading_clip, mag_new_time, mag_new_angle, mag_delay, mag_cal_time, mag_cal_spread, mag_cal_tol, mag_cal_recent, tau_mag_delay)"),
    (dict(method="mahony", params={"scale_error": 0.0}),
     "unknown parameter 'scale_error' (the method mahony: k_P, k_I, g; the gyro-offset estimator: rest_gyr, "
     "rest_gyr_abs, rest_acc, rest_time, tau_lp, tau_short, tau_rest, delta_n, tau_acc, sigma_init, sigma_motion, "
     "tau_motion, tau_arm)"),
    (dict(params={"delta_n": 1e300}), "parameter delta_n = 1e+300 rad/s/√Hz is outside its plausible range "
                                      "[1e-12, 1] rad/s/√Hz (gyro noise density, one-sided (datasheet))"),
    (dict(params={"stationary": 0.5}),
     "parameter stationary must be 0 or 1, got 0.5 (0: omega_g from noise densities measured over the last tau_noise "
     "s (blocks.methods.wiener_local); 1, or omega_g, omega_c or delta_v given: the stationary filter)"),
    (dict(params={"mag_cal_time": -1.0, "tau_heading": 1e-320}, heading=True),
     "parameter tau_heading = 9.99989e-321 s is outside its plausible range [1e-09, 1e+12] s (time constant of the "
     "pull towards the magnetometer heading (for a gyro of delta_n and no drift))"),
    (dict(method="luinge", params={"tilt_sd": -math.inf}, heading=True, gyro_offset=False),
     "parameter tilt_sd must be a finite positive number ([1e-06, 3.14159] rad), got -inf"),
    (dict(method="wiener", params={"omega_c": 0.05}),
     "omega_c = 0.05 rad/s must exceed omega_g/sqrt(2) = 0.0925248 rad/s (the assumption behind eq. 26)"),
    (dict(method="first_order", params={"omega_c": 1e-300, "omega_g": 1e-300}),
     "parameter omega_g = 1e-300 rad/s is outside its plausible range [0.0001, 100000] rad/s (Wiener break frequency "
     "the best cut-off derives from)"),
    (dict(method="wiener", params={"delta_n": 1e300, "delta_v": 1e-300}),
     "parameter delta_n = 1e+300 rad/s/√Hz is outside its plausible range [1e-12, 1] rad/s/√Hz (gyro noise density, "
     "one-sided (datasheet))"),
    (dict(method="wiener", params={"omega_g": 1e200}),
     "parameter omega_g = 1e+200 rad/s is outside its plausible range [0.0001, 100000] rad/s (break frequency; "
     "default sqrt(g·delta_n/delta_v), eq. 25)"),
    (dict(method="tseng", params={"sigma_motion": 1e200}),
     "parameter sigma_motion = 1e+200 rad/s is outside its plausible range [1e-06, 69.8132] rad/s (uncertainty the "
     "offset tracking while moving settles on (per axis); the heading leaves a drift within it to its pull alone)"),
    (dict(method="tseng", params={"mag_new_time": 1e307}, heading=True, gyro_offset=False),
     "parameter mag_new_time = 1e+307 s is outside its plausible range [1e-09, 1e+12] s (how long a field outside the "
     "reference's tolerance must stay steady to replace it)"),
    (dict(gyr_samples="points"), "gyr_samples must be 'mean' or 'point', got 'points'"),
    (dict(acc_samples="avg"), "acc_samples must be 'point' or 'mean', got 'avg'"),
    (dict(latency=0.6), "latency must be a finite number of seconds within ±0.5, got 0.6"),
    (dict(latency=-3.0), "latency must be a finite number of seconds within ±0.5, got -3.0"),
    (dict(latency=math.nan), "latency must be a finite number of seconds within ±0.5, got nan"),
])
def test_a_bad_configuration_is_refused_in_its_words(config, message):
    assert _refusal(config) == message


@pytest.mark.parametrize("latency", [0.0, 0.5, -0.5, 0.02, -0.4999])
def test_a_latency_within_half_a_second_is_taken(latency):
    assert _refusal(dict(latency=latency)) is None


@pytest.mark.parametrize("Ts", [0.0, -0.01, math.nan, math.inf])
def test_a_sample_time_that_is_not_a_finite_positive_number_is_refused_by_the_step(Ts):
    assert _refusal({}, Ts) == f"sample time must be a finite positive number of seconds, got {Ts!r}"


def test_the_batch_path_refuses_as_the_online_estimator_does():
    gyr, acc = np.zeros((20, 3)), np.tile([0.0, 0.0, 9.81], (20, 1))
    for config, message in ((dict(method="kalman"), _refusal(dict(method="kalman"))),
                            (dict(params={"delta_n": -1.0}), _refusal(dict(params={"delta_n": -1.0}))),
                            (dict(method="mahony", params={"k_P": 250.0}), _refusal(dict(method="mahony",
                                                                                       params={"k_P": 250.0}))),
                            (dict(latency=0.6), _refusal(dict(latency=0.6)))):
        with pytest.raises(ValueError) as refused:
            estimate(gyr, acc, 100.0, **config)
        assert message and str(refused.value) == message


def test_mahonys_gains_are_refused_exactly_where_its_step_diverges():
    """Linearised about the true attitude, Mahony's step (β' = β + k_I·Ts·x, x' = (1 − k_P·Ts)·x
    − Ts·β') is stable where the poles of [[1 − k_P·Ts − k_I·Ts², −1], [k_I·Ts², 1]] lie inside
    the unit circle (numpy's eigenvalues); the estimator takes exactly those gains."""
    rng = np.random.default_rng(3)
    Ts, seen = 0.02, set()
    for _ in range(150):
        k_P, k_I = 10.0 ** rng.uniform(-1, 2.3), rng.choice([0.0, 10.0 ** rng.uniform(-1, 4.0)])
        a, c = k_P * Ts, k_I * Ts * Ts
        stable = np.abs(np.linalg.eigvals([[1 - a - c, -1.0], [c, 1.0]])).max() < 1 - 1e-9
        refusal = _refusal(dict(method="mahony", params={"k_P": k_P, "k_I": k_I}, gyro_offset=False), Ts)
        margin = min(abs(a - 2), abs(c - (4 - 2 * a)))
        assert (refusal is None) == stable or margin < 1e-6 or k_I == 0, (k_P, k_I, refusal)
        seen.add("taken" if refusal is None else "k_P" if a >= 2.0 else "k_I")
        if refusal is not None and a >= 2.0:
            assert refusal == (f"parameter k_P = {k_P:g} 1/s is unstable at the sample time {Ts:g} s: Mahony's step "
                               f"needs k_P·Ts < 2, k_P < {2.0 / Ts:g} 1/s at {1.0 / Ts:g} Hz")
        elif refusal is not None:
            assert refusal == (f"parameter k_I = {k_I:g} 1/s² is unstable with k_P = {k_P:g} 1/s at the sample "
                               f"time {Ts:g} s: Mahony's step needs k_I·Ts² < 4 − 2·k_P·Ts, k_I < "
                               f"{(4.0 - 2.0 * k_P * Ts) / (Ts * Ts):g} 1/s² at {1.0 / Ts:g} Hz")
    assert seen == {"taken", "k_P", "k_I"}
