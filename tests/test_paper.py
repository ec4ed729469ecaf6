"""Rizun (2008) reproduced in simulation: Table 1, eq. 42, §4.2, §2.4 and §2.5."""
import math

import numpy as np
import pytest
from scipy import integrate
from scipy.optimize import curve_fit

from attitude_fmu.blocks.filters import accuracy as ac
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.systems.evaluation import experiments as ex


def test_table1_first_row_simulated_within_7_percent_of_eq50():
    (row,) = ex.table1(rows=ex.TABLE1_ROWS[:1], progress=False)
    for cell in row["cells"]:
        assert cell["simulated_deg"] == pytest.approx(cell["analytic_deg"], rel=0.07)


def test_error_is_independent_of_angular_velocity():
    """Same noise streams, the sensor still or turning at 2 rad/s RMS per axis."""
    dn = math.radians(0.1)
    still, turning = (ex.simulate_human(dn, 1.0, duration=8000.0, seed=8, rot_rms=r) for r in (0.0, 2.0))
    assert ex.rms(turning.errors) == pytest.approx(ex.rms(still.errors), rel=0.05)
    assert ex.rms(still.errors) == pytest.approx(ac.rms_attitude_error(dn, 1.0, 1.0, ex.PAPER_G), rel=0.1)


def test_simulated_error_spectrum_follows_eq42():
    dn, dv = math.radians(0.1), 1.0
    run = ex.simulate_human(dn, dv, duration=40000.0, seed=5)
    w, S = ex.simulated_error_spectrum(run, segment_s=1000.0)
    wg = ef.omega_g(dn, dv, ex.PAPER_G)
    band = (w > 0.03 * wg) & (w < 5 * wg)

    def log_model(w, log_level, break_w):
        x = w / break_w
        return log_level + np.log((1 + x**2) / (1 + x**4))

    (log_level, break_w), _ = curve_fit(log_model, w[band], np.log(S[band]), p0=[0.0, 0.1])
    level = ex.PAPER_G * dn * dv
    # level at low frequency and the peak at √(√2−1)·ω_g, each within 20 %
    assert math.exp(log_level) == pytest.approx(level, rel=0.2)
    assert math.sqrt(math.sqrt(2) - 1) * break_w == pytest.approx(ac.butterworth_error_peak(dn, dv, ex.PAPER_G)[0], rel=0.2)
    low = (w > 0.03 * wg) & (w < 0.2 * wg)
    assert S[low].mean() == pytest.approx(level, rel=0.2)
    for lo, hi in [(0.2, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 4.0)]:
        sel = (w >= lo * wg) & (w < hi * wg)
        assert S[sel].mean() == pytest.approx(ac.butterworth_error_spectrum(w[sel], dn, dv, ex.PAPER_G).mean(), rel=0.2)


def test_first_order_filter_is_worse_by_the_cube_root_law():
    """§4.2: at its best cut-off the first-order filter's mean-square error exceeds the
    optimum's by ∝ (ω_c/ω_g)^(1/3); eq. 41 fixes the constant at 3·2^(5/6)/8 ≈ 0.668."""
    results = {wc: ex.first_order_comparison(omega_c=wc, duration=20000.0, seed=2) for wc in (10.0, 80.0)}
    for r in results.values():
        assert r["analytic_ratio"] == pytest.approx(3 * 2 ** (5 / 6) / 8 * r["paper_factor"], rel=0.05)
        assert r["simulated_ratio"] == pytest.approx(r["analytic_ratio"], rel=0.25)
    # eightfold band limit: the ratio doubles, the cube-root law
    assert results[80.0]["simulated_ratio"] / results[10.0]["simulated_ratio"] == pytest.approx(2.0, rel=0.25)


def test_centripetal_acceleration_biases_sensor_frame_lowpass_not_the_estimator():
    r = ex.lever_arm_bias()
    assert r["estimator_mean_deg"] < 0.05
    assert r["estimator_bias_deg"] < 0.05
    # eq. 19: the low-pass keeps the mean centripetal acceleration (0.8 m/s² here)
    assert r["centripetal_m_s2"] == pytest.approx(0.8, rel=1e-4)
    assert r["lowpass_mean_deg"] == pytest.approx(r["eq19_predicted_deg"], rel=0.02)
    assert r["lowpass_mean_deg"] == pytest.approx(math.degrees(math.atan(0.8 / ex.PAPER_G)), rel=0.02)


def test_filtering_the_angle_is_biased_filtering_the_vector_is_not():
    r = ex.incline_angle_bias()
    # closed form: the sensor (x up the 45° slope) sees g/√2·(1 + 2 sin φ) along x and g/√2
    # along z, so its apparent pitch is atan(1 + 2 sin φ), whose mean over a period is not 45°
    mean_apparent = integrate.quad(lambda p: math.atan(1 + 2 * math.sin(p)), 0, 2 * math.pi)[0] / (2 * math.pi)
    assert r["mean_apparent_pitch_deg"] == pytest.approx(math.degrees(mean_apparent), abs=0.05)
    assert r["angle_filter_bias_deg"] == pytest.approx(math.degrees(mean_apparent) - 45.0, abs=0.1)
    assert abs(r["angle_filter_bias_deg"]) > 10.0
    assert abs(r["vector_filter_bias_deg"]) < 0.05
