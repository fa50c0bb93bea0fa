"""Why a time-domain fit cannot be trusted, on fits whose verdict is known."""

import numpy as np

from trms.calibration.feasible_start import stop_reached
from trms.calibration.timedomain_fit import _failures, _Fit

TS = 0.05


def test_a_failed_fit_names_a_records_end_stop_contact_as_the_reason_for_no_step():
    fit = _Fit(None, np.ones(4), np.ones((4, 1)), 0, "Terminated after 0 iterations: norm(dx) < tol")
    y = np.column_stack([np.zeros(6), [0.0, 1.0, 2.0, 2.98, 2.5, 1.0]])
    reached = stop_reached(y, np.arange(6) * TS, [(-1.1, 1.1), (-3.0, 3.0)], ["pitch", "yaw"], "rig1.csv")
    (line,) = _failures(fit, {"pitch": [50.0]}, {"pitch": [60.0]}, ["rig3.csv"], "held-out", [reached])
    assert line.startswith("the optimiser took no step (Terminated after 0 iterations: norm(dx) < tol): record ")
    assert "rig1.csv reaches the yaw end stop (+3 rad) at 0.15 s, and its impacts make the residual jump" in line
    (flat,) = _failures(fit, {"pitch": [50.0]}, {"pitch": [60.0]}, ["rig3.csv"], "held-out")
    assert "the residual is flat in the parameters there" in flat
