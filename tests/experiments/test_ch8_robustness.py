"""The ch. 8 controllers over the parameter spread: the stated weight covers the sampled twins, the LTI certificate is
measured and said with its scope, the batch judges each controller's flights, and "robust" needs all three."""

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch8_designs as cd
from trms.experiments import ch8_robustness as cr
from trms.worlds import make_plant


@pytest.fixture(scope="module")
def controllers():
    return cd.controllers_for(cd.designs_at(0.2), make_plant("linear", "1dof"))[0]


def test_the_stated_weight_lies_above_the_sampled_twins_uncertainty():
    w, bound = cr.input_uncertainty(3)
    weight = np.abs(cd.input_uncertainty_weight(**cd.SPREAD_WEIGHT)(1j * w))
    assert np.all(weight >= bound)
    assert bound[0] < 0.3 < 1.0 < bound.max()  # the gain spread at low frequency, more than 100 % near Nyquist
    fitted = cr.fit_weight(w, bound)
    assert all(fitted[k] <= cd.SPREAD_WEIGHT[k] for k in ("r0", "tau", "r_inf"))


def test_no_design_that_damps_the_mode_holds_the_unstructured_certificate_and_the_cancelling_one_does(controllers):
    """Measured, not assumed: the certificate with this W_I forbids loop gain at the resonance."""
    peaks = cr.robust_stability(controllers, cd.input_uncertainty_weight(**cd.SPREAD_WEIGHT))
    assert set(peaks) == set(cd.CONTROLLERS) and all(p is not None and p > 1.0 for p in peaks.values())
    peak, damping = cr.cancelling_certificate()
    assert peak < 1.0 and damping < cd.DESIGN_DAMPING / 2


def test_the_batch_judges_each_controller_on_the_same_twins_and_the_verdict_names_what_failed():
    result = cr.controller_robustness(1, controllers=["PID", "H-infinity"])
    pid, hinf = result.controllers
    assert pid.statuses == hinf.statuses == ("settled",)
    assert 0.0 < pid.overshoot[0] < 40.0 and 0.0 < hinf.overshoot[0] < 40.0
    table = cr.table_robustness(result, {"PID": "", "H-infinity": "moving air: 2/8 steps unsettled"})
    rows = {r[0]: r for r in table.rows}
    assert rows["PID"][1] == "1/1" and rows["PID"][9] == "no" and rows["PID"][10].startswith("no: LTI certificate")
    assert "twin (moving air: 2/8 steps unsettled)" in rows["H-infinity"][10]
    assert "W_I(s) = (1.35 s + 0.22)" in table.notes[1] and "linear, time-invariant" in table.notes[1]
    assert any("cancelling the mode" in n for n in table.notes)


def test_robust_is_said_only_when_the_certificate_the_spread_and_the_twin_all_hold():
    ok = cr.ControllerSpread("X", ("settled", "settled"), (5.0, 6.0), (9.0, 8.0), 0.9)
    assert cr.robust_verdict(ok, "") == "robust"
    assert cr.robust_verdict(ok, None) == "no: twin (not judged)"
    assert cr.robust_verdict(cr.ControllerSpread("X", ("settled",), (5.0,), (9.0,), None), "") == (
        "no: LTI certificate"
    )


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_samples": 0}, "n_samples"),
        ({"n_samples": 1, "controllers": ["moon"]}, "unknown controller 'moon'"),
        ({"n_samples": 1, "sample_time": 0.3}, "unknown sample_time 0.3"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match):
        cr.controller_robustness(**kwargs)


def test_a_success_whose_earlier_step_never_settled_says_so():
    row = cr.ControllerSpread("H-infinity, robust weight", ("settled",), (15.0,), (float("nan"),), 0.95, (0.1,))
    (cells,) = cr.table_robustness(cr.Robustness((row,), dict(cd.SPREAD_WEIGHT), 1, 0, 0.2, 0.2)).rows
    assert cells[1] == "1/1" and cells[5:8] == ["an earlier step unsettled"] * 3
    none = cr.ControllerSpread("PID", ("not settled",), (90.0,), (float("nan"),), 2.3, (0.3,))
    (cells,) = cr.table_robustness(cr.Robustness((none,), dict(cd.SPREAD_WEIGHT), 1, 0, 0.2, 0.2)).rows
    assert cells[1] == "0/1" and cells[2:8] == ["no success"] * 6
