"""The normalised fit of a time-domain calibration, on signals whose fit is known."""

import numpy as np
import pytest

from trms.calibration.timedomain_result import fit_percent


def test_fit_percent():
    y = np.linspace(0, 1, 50)[:, None]
    assert fit_percent(y, y)[0] == 100.0 and fit_percent(y, np.full_like(y, y.mean()))[0] == pytest.approx(0.0)
