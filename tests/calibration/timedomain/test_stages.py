"""Why a time-domain fit cannot be trusted, on fits whose verdict is known."""

import numpy as np

from trms.calibration.timedomain.feasible_start import stop_reached
from trms.calibration.timedomain.stages import FitOutcome, fit_failures

TS = 0.05


def test_a_failed_fit_names_a_records_end_stop_contact_as_the_reason_for_no_step():
    fit = FitOutcome(None, np.ones(4), np.ones((4, 1)), 0, "norm(gradient) < tol")
    y = np.column_stack([np.zeros(6), [0.0, 1.0, 2.0, 2.98, 2.5, 1.0]])
    reached = stop_reached(y, np.arange(6) * TS, [(-1.1, 1.1), (-3.0, 3.0)], ["pitch", "yaw"], "rig1.csv")
    (line,) = fit_failures(fit, {"pitch": [50.0]}, {"pitch": [60.0]}, ["rig3.csv"], "held-out", [reached])
    assert line.startswith("the optimiser took no step (norm(gradient) < tol): record ")
    assert "rig1.csv reaches the yaw end stop (+3 rad) at 0.15 s (1 sample at a stop), and its impacts make the" in line
    (flat,) = fit_failures(fit, {"pitch": [50.0]}, {"pitch": [60.0]}, ["rig3.csv"], "held-out")
    assert "the residual is flat in the parameters there" in flat


def test_a_fit_that_failed_on_records_at_an_end_stop_names_the_contacts_first_and_asks_for_a_lower_amplitude():
    """A step was taken, the held-out fit is below 0 %: the stderr line (the first) names the stop contacts."""
    fit = FitOutcome(None, np.ones(4), np.ones((4, 1)), 3, "norm(dx) < tol")
    y = np.column_stack([np.zeros(6), [0.0, 1.0, 2.0, 2.98, 2.99, 1.0]])
    reached = stop_reached(y, 12.5 + np.arange(6) * TS, [(-1.1, 1.1), (-3.0, 3.0)], ["pitch", "yaw"], "rig1.csv")
    contact = f"{reached}, its inputs swing u2 up to 0.4 V from its operating point"
    lines = fit_failures(fit, {"yaw": [10.0]}, {"yaw": [-5.0]}, ["rig3.csv"], "held-out", [contact])
    assert lines[0] == (
        "the fitted records reach end stops, where the beam rests on a stop and a fit cannot follow it sample by "
        "sample: record rig1.csv reaches the yaw end stop (+3 rad) at 12.65 s (2 samples at a stop), its inputs "
        "swing u2 up to 0.4 V from its operating point; record the rig again with a lower amplitude, that keeps it "
        "off its end stops"
    )
    assert lines[1].startswith("yaw: the fit on held-out record rig3.csv is -5.0 % after calibration, below 0 %")
    assert fit_failures(fit, {"yaw": [10.0]}, {"yaw": [20.0]}, ["rig3.csv"], "held-out", [contact]) == []
