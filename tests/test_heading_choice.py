"""The heading's time constant chosen from the gyro the scale_error choice found
(blocks.stages.heading_choice): the error variance it minimises is the heading stage's own
(a Monte Carlo run of the C stage), its root is that variance's minimum (scipy), and the
batch path takes it only where it chose scale_error."""
import json
import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from attitude_fmu.blocks.pipeline.batch import estimate
from attitude_fmu.blocks.stages import heading
from attitude_fmu.blocks.stages.heading_choice import time_constant
from attitude_fmu.systems.simulation.recording import SENSORS, simulate_recording

FIELD = np.array([0.0, 20.0, -45.0])  # µT, ENU
DELTA_N, OMEGA_M, DATASHEET = math.radians(0.1), 10.0, 0.005  # the Wiener filter's defaults


def _variance(tau, scale_error, rate_ms, offset_variance, r):
    """J(τ) = P_b·τ² + q·τ/2 + r/(2τ), q = (δn² + 4·σ_s²·⟨|ω|²⟩/ω_m)/2 (the module's model)."""
    q = 0.5 * (DELTA_N**2 + 4.0 * scale_error**2 * rate_ms / OMEGA_M)
    return offset_variance * tau**2 + 0.5 * q * tau + 0.5 * r / tau


@pytest.mark.parametrize("scale_error, rate_ms, offset_variance", [
    (0.0, 5.0, math.radians(0.08) ** 2), (0.002, 1.4, math.radians(0.05) ** 2), (0.0, 17.0, 0.0),
    (0.001, 0.3, math.radians(0.2) ** 2)])
def test_the_time_constant_minimises_the_stated_error_variance(scale_error, rate_ms, offset_variance):
    """r is the one for which tau_heading (10 s) is J's minimum at the datasheet's 0.005 (scipy
    finds it there), and the time constant returned is J's minimum at the scale error chosen;
    with no offset left it is tau_heading·√(q(0.005)/q(σ_s)); at 0.005 it is tau_heading itself."""
    tau_h = heading.resolve()["tau_heading"]
    q = lambda s: 0.5 * (DELTA_N**2 + 4.0 * s**2 * rate_ms / OMEGA_M)
    tau = time_constant(tau_h, 2.0 * q(DATASHEET), 2.0 * q(scale_error), offset_variance)
    r = 4.0 * offset_variance * tau_h**3 + q(DATASHEET) * tau_h**2
    best = lambda s: minimize_scalar(lambda t: _variance(t, s, rate_ms, offset_variance, r), bounds=(0.1, 1e3),
                                     method="bounded", options={"xatol": 1e-9}).x
    print(f"σ_s {scale_error}: τ {tau:.4f} s, scipy's minimum {best(scale_error):.4f} s")
    assert best(DATASHEET) == pytest.approx(tau_h, rel=1e-6)
    assert tau == pytest.approx(best(scale_error), rel=1e-6) and tau >= tau_h
    if offset_variance == 0.0:
        assert tau == pytest.approx(tau_h * math.sqrt(q(DATASHEET) / q(scale_error)), rel=1e-12)
    assert time_constant(tau_h, 2.0 * q(DATASHEET), 2.0 * q(DATASHEET), offset_variance) == tau_h


def _heading_error(tau, fs, seconds, bias, r, seed):
    """The heading stage's error (rad) over a sensor at rest facing north: its orientation input
    drifts in heading as a gyro's integral (white rate noise of one-sided density DELTA_N², a
    constant offset bias rad/s), its magnetometer sees FIELD turned by white heading noise of
    density r (rad²·s); the low-pass before the guard off, the delay given as 0, no hard-iron fit."""
    n, Ts = int(seconds * fs), 1.0 / fs
    rng = np.random.default_rng(seed)
    psi = np.cumsum((DELTA_N * math.sqrt(fs / 2.0) * rng.standard_normal(n) + bias) * Ts)
    quat = np.column_stack([np.cos(psi / 2), np.zeros(n), np.zeros(n), np.sin(psi / 2)])
    noise = math.sqrt(r / Ts) * rng.standard_normal(n)
    mag = np.column_stack([-FIELD[1] * np.sin(noise), FIELD[1] * np.cos(noise), np.full(n, FIELD[2])])
    params = {"tau_heading": tau, "tau_mag_guard": 1e-9, "mag_delay": 0.0, "mag_cal_time": 0.0}
    out, accepted, _, _ = heading.with_magnetometer(quat, mag, fs, params)
    assert accepted[int(3 * tau * fs):].all()
    return np.angle(np.exp(2j * np.arctan2(out[:, 3], out[:, 0])))[int(5 * tau * fs):]  # within ±π


@pytest.mark.parametrize("tau", [4.0, 16.0])
def test_the_stated_error_variance_is_the_heading_stages(tau):
    """The model behind the rule, checked on the C stage (20 Hz, 40 000 s): a gyro offset b gives
    the mean error b·τ (the output lags the drift); the gyro's white noise and the magnetometer's give the variance
    q·τ/2 + r/(2τ), q = δn²/2 for the one-sided density δn² (within 8 %)."""
    fs, bias, r = 20.0, math.radians(0.01), math.radians(1.0) ** 2 * 0.05
    error = _heading_error(tau, fs, 40000.0, bias, r, seed=3)
    q = 0.5 * DELTA_N**2
    expected = 0.5 * q * tau + 0.5 * r / tau
    print(f"τ {tau}: mean {math.degrees(error.mean()):.4f}° (bτ {math.degrees(bias * tau):.4f}°), "
          f"variance {error.var():.3e} against {expected:.3e}")
    assert error.mean() == pytest.approx(bias * tau, rel=0.08)
    assert error.var() == pytest.approx(expected, rel=0.08)


def test_the_batch_path_takes_it_where_it_chose_scale_error():
    """A calibrated gyro (0.05 % scale error) with a magnetometer: the batch path chooses
    scale_error 0 and tau_heading by the rule, longer than 10 s; the estimate is the one with
    both given. Given scale_error, or tau_heading, nothing is chosen for the heading."""
    rec = simulate_recording(100.0, 60.0, sensor=SENSORS["calibrated"], seed=2)
    est = estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag)
    print(est.chosen)
    assert est.chosen["scale_error"] == 0.0 and est.chosen["tau_heading"] > 10.0
    again = estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag, params=est.chosen)
    assert again.chosen is None and np.array_equal(again.quat, est.quat)
    assert estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag, params={"scale_error": 0.0}).chosen is None
    held = estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag, params={"tau_heading": 7.0}).chosen
    assert held == {"scale_error": 0.0}
    assert "tau_heading" not in estimate(rec.gyr, rec.acc, rec.fs).chosen


def test_the_command_line_says_what_it_chose(tmp_path, capsys):
    """`attitude estimate` notes tau_heading with the flag that holds it; `attitude evaluate`
    lists it under its table and under "chosen" in its JSON, the value estimate() chose on the
    recording before it was written to CSV."""
    from attitude_fmu.systems.cli.commands import main
    from attitude_fmu.systems.recordings.writing import write_recording

    rec = simulate_recording(100.0, 60.0, sensor=SENSORS["calibrated"], seed=2, name="calibrated")
    path = tmp_path / "calibrated.csv"
    write_recording(path, rec)
    tau = estimate(rec.gyr, rec.acc, rec.fs, mag=rec.mag).chosen["tau_heading"]
    assert main(["estimate", str(path), "--out", str(tmp_path / "out.csv")]) == 0
    assert f"tau_heading {tau:.4g} s chosen from the gyro the scale_error choice found" in capsys.readouterr().err
    assert main(["evaluate", "--workers", "1", "--reference-north", "magnetic", str(path)]) == 0
    assert f"tau_heading chosen from each recording (from the gyro the scale_error choice found; --param " \
           f"tau_heading=V holds one): calibrated {tau:.4g} s" in capsys.readouterr().out
    assert main(["evaluate", "--json", "--workers", "1", "--reference-north", "magnetic", str(path)]) == 0
    chosen = json.loads(capsys.readouterr().out)["chosen"]["calibrated"]
    assert chosen == {"scale_error": 0.0, "tau_heading": pytest.approx(tau, rel=1e-9)}  # the CSV's digits
