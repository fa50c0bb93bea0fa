"""The one Mode type: frequency and damping from eigenvalues and poles, and the oscillatory filter."""

import numpy as np
import pytest

from trms.identification.polynomial import modes_of_poles
from trms.modes import Mode, mode_of_eigenvalue, oscillatory, real_poles


def test_a_known_pole_pair_gives_its_frequency_and_damping():
    f, zeta, ts = 0.342, 0.041, 0.2
    wn = 2 * np.pi * f
    s = complex(-zeta * wn, wn * np.sqrt(1 - zeta**2))
    (m,) = [m for m in modes_of_poles(np.exp(np.array([s, s.conjugate()]) * ts), ts)]
    assert isinstance(m, Mode) and m.frequency_hz == pytest.approx(f) and m.damping == pytest.approx(zeta)
    assert m.eigenvalue == pytest.approx(s)


def test_the_filter_keeps_modes_and_lists_real_and_nyquist_poles_apart():
    ts = 0.1  # Nyquist 5 Hz
    poles = np.array(
        [
            0.5,
            -0.9,
            np.exp(complex(-0.05, 2.0) * ts),
            np.exp(complex(-0.05, -2.0) * ts),
            0.9 * np.exp(1j * 0.9 * np.pi),
            0.9 * np.exp(-1j * 0.9 * np.pi),
        ]
    )
    modes = modes_of_poles(poles, ts)
    kept = oscillatory(modes, ts)
    assert [round(m.frequency_hz, 3) for m in kept] == [round(abs(complex(-0.05, 2.0)) / (2 * np.pi), 3)]
    apart = real_poles(modes, ts)
    assert len(apart) == len(modes) - 1
    assert any(m.damping == 1.0 for m in apart)  # the real pole 0.5
    assert any(m.frequency_hz >= 0.8 * 5.0 for m in apart)  # -0.9 sits at Nyquist; the 4.5 Hz pair near it


def test_continuous_modes_have_no_nyquist_limit():
    assert oscillatory([mode_of_eigenvalue(complex(-1.0, 200.0))]) != []
    assert oscillatory([mode_of_eigenvalue(-3.0)]) == []
