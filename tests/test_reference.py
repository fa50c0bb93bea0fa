"""The thesis's models as data: the derived figures of TARGETS.md come out of them."""

import control
import numpy as np
import pytest

from trms import reference


def test_eq_3_11_poles_zeros_dc_gain():
    g = reference.eq_3_11()
    assert g.dt == 0.2
    poles = np.sort_complex(g.poles())
    # TARGETS.md: 0.8929 +- 0.4095j, 0.7530, 0.4689; zeros 0.980 +- 1.328j, -1.074; DC gain 1.51 rad/V.
    assert np.allclose(poles, np.sort_complex([0.8929 + 0.4095j, 0.8929 - 0.4095j, 0.7530, 0.4689]), atol=5e-4)
    assert np.allclose(np.sort_complex(g.zeros()), np.sort_complex([0.980 + 1.328j, 0.980 - 1.328j, -1.074]), atol=2e-3)
    assert g.dcgain() == pytest.approx(1.51, abs=0.005)
    lam = np.log(poles[np.argmax(poles.imag)]) / 0.2
    assert abs(lam) / (2 * np.pi) == pytest.approx(0.342, abs=0.002)
    assert -lam.real / abs(lam) == pytest.approx(0.041, abs=0.002)


def test_eq_6_33_is_one_sample_ahead_of_eq_3_11():
    g = reference.eq_3_11()
    s = reference.eq_6_33()
    assert float(np.asarray(s.D)[0, 0]) == pytest.approx(0.0097)
    # Same poles as (3.11) up to the printed rounding (3.007 for 3.0077, -0.341 for 0.3407 moves the
    # real poles by up to 0.011).
    assert np.allclose(np.sort_complex(np.linalg.eigvals(s.A)), np.sort_complex(g.poles()), atol=0.012)
    # Its impulse response leads (3.11)'s by one sample: h633[k] ~ h311[k + 1] (over 2 s; the rounded
    # poles drift apart later).
    _, h311 = control.impulse_response(g, T=np.arange(0, 2, 0.2))
    _, h633 = control.impulse_response(s, T=np.arange(0, 2, 0.2))
    h311 = np.ravel(h311)
    h633 = np.ravel(h633)
    # (3.11) has no direct term, so its first sample is 0; the rest agree within the printed rounding.
    assert h311[0] == 0.0
    assert np.allclose(h633[:-1], h311[1:], rtol=0, atol=0.03 * np.max(np.abs(h311)))


def test_mode_table_and_tables_are_consistent():
    assert {m.frequency_hz for m in reference.MODE_TABLE if m.configuration == "1dof"} == {0.25, 0.34}
    assert set(reference.LQG_WEIGHTS_R) == {75.0, 1.0, 100.0, 125.0}
    assert reference.TABLE_4_2[("LPF 0.1 Hz", 0.34)] == 7.0


def test_the_named_modes_are_table_3_1s_and_the_psds():
    two_dof = {m.frequency_hz for m in reference.MODE_TABLE if m.configuration == "2dof"}
    assert set(reference.TABLE_3_1_MODES_HZ) == two_dof == {reference.SLOW_MODE_HZ, reference.MAIN_MODE_HZ}
    assert reference.SIDE_PEAKS_1DOF_HZ == (0.25, 0.46)
    assert reference.MAIN_MODE_HZ in reference.PSD_MODES_1DOF
    assert abs(reference.EQ_3_11_MODE[0] - reference.MAIN_MODE_HZ) < 0.01
