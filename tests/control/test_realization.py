"""Observer canonical realisation: same transfer function, and the printed eq. (6.33) recovered."""

import control
import numpy as np
import pytest

from trms.control.realization import observer_canonical
from trms.errors import InputError
from trms.reference import eq_3_11, eq_6_33


def test_realisation_has_the_transfer_function_of_eq_3_11():
    g = eq_3_11()
    s = observer_canonical(g)
    t = np.arange(60) * 0.2
    _, h_tf = control.impulse_response(g, T=t)
    _, h_ss = control.impulse_response(s, T=t)
    assert h_ss == pytest.approx(h_tf, abs=1e-12)
    assert np.asarray(s.C).tolist() == [[1.0, 0.0, 0.0, 0.0]] and float(s.D[0, 0]) == 0.0


def test_one_sample_ahead_model_gives_the_printed_eq_6_33():
    ahead = observer_canonical(control.tf(control.tf([1, 0], [1], 0.2) * eq_3_11()))
    printed = eq_6_33()
    # The thesis prints 3-4 significant digits: 6e-4 covers its rounding of B (0.02057 -> 0.0205).
    assert np.asarray(ahead.B).ravel() == pytest.approx(np.asarray(printed.B).ravel(), abs=6e-4)
    assert float(ahead.D[0, 0]) == pytest.approx(0.0097, abs=1e-12)
    assert np.asarray(ahead.A)[:, 0] == pytest.approx(np.asarray(printed.A)[:, 0], abs=1e-3)


@pytest.mark.parametrize(
    "system, match",
    [
        (control.ss([[0.5]], [[1]], [[1]], [[0]], 0.2), "must be a python-control TransferFunction"),
        (control.tf([1], [1, 1]), "discrete-time"),
        (control.tf([1, 0, 0], [1, 0.5], 0.2), "proper"),
        (control.tf([[[1], [1]]], [[[1, 0.5], [1, 0.2]]], 0.2), "SISO"),
    ],
)
def test_bad_systems_are_refused(system, match):
    with pytest.raises(InputError, match=match):
        observer_canonical(system)
