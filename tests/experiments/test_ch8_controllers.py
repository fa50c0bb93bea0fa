"""LQG, PID, MPC and H-infinity on the same pitch scenarios: every cell flown, the margins and the findings."""

from __future__ import annotations

import math

import pytest

from trms.errors import InputError
from trms.experiments import ch8_controllers as cc


@pytest.fixture(scope="module")
def comparison():
    return cc.compare_controllers(seeds=(0,))


def test_every_controller_flies_every_case_and_the_linear_model_settles_every_step(comparison):
    got = {(c.controller, c.case) for c in comparison.cases}
    assert got == {(n, case) for n in cc.CONTROLLERS for case in cc.CASES}
    linear = [c for c in comparison.cases if c.case == "linear model"]
    assert all(c.status == "flown" and c.unsettled == 0 and c.steps == 4 for c in linear)
    assert all(0.0 <= c.saturated <= 1.0 and c.rms_control > 0 for c in comparison.cases)


def test_the_linear_compensators_have_disk_margins_and_mpc_has_none(comparison):
    for name in ("LQG", "PID", "H-infinity", "H-infinity, robust weight"):
        m = comparison.margins[name]
        assert m is not None and m.stable and m.gain_margin_db > 3.0 and m.phase_margin_deg > 20.0, name
    assert comparison.margins["MPC"] is None


def test_the_push_is_met_by_every_controller_and_mpc_recovers_first(comparison):
    assert set(comparison.push_peak) == set(cc.CONTROLLERS)
    assert all(0.05 < v < 0.5 for v in comparison.push_peak.values())
    assert all(math.isfinite(v) or v == math.inf for v in comparison.push_recovery.values())
    others = ("LQG", "PID", "H-infinity", "H-infinity, robust weight")
    assert comparison.push_recovery["MPC"] <= min(comparison.push_recovery[n] for n in others)


def test_h_infinity_with_its_default_weights_does_not_settle_on_the_twin_and_with_the_robust_weight_does(comparison):
    """A measured finding, kept visible: the default mixed-sensitivity design settles on its model and not on the
    twin; four times the control weight (and a lower crossover) settles every step on the twin too."""
    hinf = {c.case: c for c in comparison.cases if c.controller == "H-infinity"}
    assert hinf["linear model"].unsettled == 0
    assert hinf["twin, moving air"].unsettled == hinf["twin, moving air"].steps
    assert hinf["twin, moving air"].overshoot > 3 * hinf["linear model"].overshoot
    robust = {c.case: c for c in comparison.cases if c.controller == "H-infinity, robust weight"}
    assert all(robust[case].unsettled == 0 for case in ("linear model", "twin, moving air", "twin, still air"))
    assert robust["twin, moving air"].overshoot < 10.0


def test_the_table_has_a_row_per_controller_and_case():
    table = cc.table_controllers(cc.Comparison((), {}, {}, {}, (0,), 0.2))
    assert table.rows == [] and "seeds 0" in table.notes[0]
    nan = float("nan")
    rows = (
        cc.ControllerCase("MPC", "linear model", nan, nan, 0, 0, nan, nan, "not flown: no solver"),
        cc.ControllerCase("PID", "linear model", 5.0, nan, 2, 2, 0.1, 0.0),
    )
    table = cc.table_controllers(cc.Comparison(rows, {}, {}, {}, (0,), 0.2))
    assert table.rows[0][2:5] == ["not flown", "not flown", "not flown: no solver"]  # nothing flown settles nothing
    assert table.rows[1][3:5] == ["none settled", "2/2"]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"seeds": ()}, "seeds must name at least one seed"),
        ({"sample_time": 0.3}, "unknown sample_time 0.3"),
        ({"cases": ["moon"]}, "unknown case 'moon'"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match):
        cc.compare_controllers(**kwargs)
