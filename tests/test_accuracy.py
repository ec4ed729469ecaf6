"""The paper's analytic results: eqs. 25, 33–34, 41–50 and Table 1's printed figures."""
import math

import numpy as np
import pytest

from attitude_fmu.blocks.filters import accuracy as ac
from attitude_fmu.blocks.filters import earth_filters as ef
from attitude_fmu.blocks.methods.registry import METHODS, method
from attitude_fmu.systems.evaluation.experiments import PAPER_G, TABLE1_ROWS, TABLE1_SLOSH

# Table 1 as printed: 1/ω_g (s) and ΔΩ_RMS (°) for a = 1, 0.5, 2
PRINTED = {
    (0.10, 1.0): (7.6, (0.33, 0.30, 0.44)),
    (0.10, 2.0): (10.8, (0.39, 0.35, 0.52)),
    (0.20, 1.0): (5.4, (0.55, 0.50, 0.73)),
    (0.20, 2.0): (7.6, (0.66, 0.59, 0.87)),
}


@pytest.mark.parametrize("row", TABLE1_ROWS)
def test_table1_analytic_columns_match_the_printed_table(row):
    dn, dv = math.radians(row[0]), row[1]
    inv_wg, rms = PRINTED[row]
    assert round(1 / ef.omega_g(dn, dv, PAPER_G), 1) == inv_wg
    for a, printed in zip(TABLE1_SLOSH, rms):
        assert round(math.degrees(ac.rms_attitude_error(dn, dv, a, PAPER_G)), 2) == printed


def test_eq42_is_eq41_for_the_butterworth_filter_and_peaks_where_the_paper_says():
    dn, dv = math.radians(0.1), 1.0
    wg = ef.omega_g(dn, dv)
    w = np.logspace(-3, 2, 400) * wg
    generic = ac.error_spectrum(ef.butterworth(wg), w, dn, dv)
    assert np.allclose(generic, ac.butterworth_error_spectrum(w, dn, dv), rtol=1e-9)
    peak_w, peak_value = ac.butterworth_error_peak(dn, dv)
    fine = np.linspace(0.2, 2.0, 200001) * wg
    spectrum = ac.butterworth_error_spectrum(fine, dn, dv)
    assert fine[np.argmax(spectrum)] == pytest.approx(peak_w, rel=1e-4)
    assert spectrum.max() == pytest.approx(peak_value, rel=1e-9)
    assert ac.butterworth_error_spectrum(np.array([0.0]), dn, dv)[0] == pytest.approx(9.81 * dn * dv)


@pytest.mark.parametrize("a", [0.5, 1.0, 2.0, 3.0])
def test_eq49_closed_form_equals_integrated_eq41_with_slosh_mismatch(a):
    dn, dv = math.radians(0.2), 1.5
    wg = ef.omega_g(dn, dv)
    numeric = ac.mean_square_error(ef.butterworth(wg), dn, a * dv)
    assert numeric == pytest.approx(ac.mean_square_gravity_error(dn, dv, a), rel=1e-7)


def test_eq33_tends_to_eq34_and_is_optimal_for_band_limited_motion():
    dn, dv = math.radians(0.1), 1.0
    wg = ef.omega_g(dn, dv)
    w = np.logspace(-2, 1, 50) * wg
    far = ef.wiener_band_limited(wg, 1e6 * wg)
    assert np.allclose(far(1j * w), ef.butterworth(wg)(1j * w), rtol=1e-5)
    # at a low band limit, eq. 33 beats eq. 34 on the motion it was designed for
    wc = 2.0 * wg
    assert (ac.mean_square_error(ef.wiener_band_limited(wg, wc), dn, dv, wc)
            < ac.mean_square_error(ef.butterworth(wg), dn, dv, wc))


def test_best_first_order_cutoff_minimises_eq41():
    dn, dv, wc = math.radians(0.1), 1.0, 10.0
    wg = ef.omega_g(dn, dv)
    best = ef.best_first_order_cutoff(wg, wc)
    ms = {f: ac.mean_square_error(ef.first_order(f * best), dn, dv, wc) for f in (0.8, 1.0, 1.25)}
    assert ms[1.0] < ms[0.8] and ms[1.0] < ms[1.25]


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_parameters_are_refused(bad):
    with pytest.raises(ValueError):
        ef.omega_g(bad, 1.0)
    with pytest.raises(ValueError):
        method("wiener").filter({"delta_n": bad})
    with pytest.raises(ValueError, match="omega_c"):
        ef.wiener_band_limited(1.0, 0.5)


def test_methods_document_every_parameter_with_a_unit():
    for m in METHODS.values():
        for p in m.params:
            assert p.unit and p.doc
    with pytest.raises(ValueError, match="unknown parameter"):
        method("wiener").filter({"delta_q": 1.0})
    with pytest.raises(ValueError, match="unknown method"):
        method("kalman")
