"""The 2-DOF comparison: every controller flies both scenarios on both worlds, measured; refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch8_controllers_mimo as cm
from trms.experiments.ch8_mimo_lqg import SCENARIOS


@pytest.fixture(scope="module")
def comparison():
    """Short runs (20 s: a step at 0 s and back at 10 s), one seed, both worlds."""
    return cm.compare_controllers_mimo(seeds=(0,), duration=20.0)


def test_every_controller_flies_both_scenarios_on_both_worlds(comparison):
    got = {(c.controller, c.scenario, c.world) for c in comparison.cases}
    assert got == {(n, s, w) for n in cm.CONTROLLERS for s in SCENARIOS for w in cm.WORLDS}
    assert all(c.status == "flown" and c.steps == 2 for c in comparison.cases)
    assert all(c.rms_control > 0 and 0.0 <= c.saturated <= 1.0 and c.cross >= 0.0 for c in comparison.cases)
    assert 0.0 < comparison.gamma < 3.0 and comparison.seeds == (0,) and comparison.duration == 20.0


def test_the_multivariable_designs_hold_the_untracked_axis_better_than_the_decentralised_pid(comparison):
    """u1 moves the yaw (16 rad/V at DC): the PIDs meet it as a disturbance on a slow yaw loop, the 2 x 2 designs
    counter it with u2 as it comes."""
    pitch = {c.controller: c.cross for c in comparison.cases if c.scenario == "pitch step"}
    assert pitch["MIMO PID"] > 0.3
    assert all(pitch[n] < 0.5 * pitch["MIMO PID"] for n in ("MIMO LQG", "MIMO MPC", "MIMO H-infinity"))


def test_every_mimo_design_damps_the_pitch_mode_on_the_design_model(comparison):
    assert set(comparison.damping) == set(cm.CONTROLLERS)
    assert all(d.closed.damping >= 0.1 for d in comparison.damping.values())


def test_the_h_infinity_controller_is_a_stable_two_by_two_loop_on_the_design_model():
    designs = cm.design_controllers_mimo(0.1)
    assert designs.hinf is not None and designs.hinf.discrete_controller.ninputs == 2
    assert designs.hinf.stable_with(designs.model) and designs.hinf.disturbance_weight is not None
    assert len(designs.pid) == 2 and all(g.kp > 0 and g.ki > 0 for g in designs.pid) and designs.pid[0].tm > 0


def test_the_table_has_a_row_per_case_and_says_what_was_not_flown():
    rows = (
        cm.MimoCase(
            "MIMO MPC",
            "yaw step",
            "linear model",
            math.nan,
            math.nan,
            0,
            0,
            math.nan,
            math.nan,
            math.nan,
            "not flown: no solver",
        ),
        cm.MimoCase("MIMO PID", "yaw step", "linear model", 5.0, math.nan, 2, 2, 0.1, 0.0, 0.01),
    )
    table = cm.table_controllers_mimo(cm.MimoComparison(rows, 0.8, (0, 1), 0.1, 80.0))
    assert [r[0] for r in table.rows] == ["MIMO MPC", "MIMO PID"]
    assert "not flown: no solver" in table.rows[0][5] and table.rows[1][4] == "none settled"
    assert table.rows[0][3:5] == ["not flown", "not flown"]  # a row not flown settles nothing: it says so
    assert "seeds 0, 1" in table.notes[0] and "gamma = 0.8" in table.notes[1] and "noise band" in table.notes[0]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"seeds": ()}, "seeds must name at least one seed"),
        ({"worlds": ["moon"]}, "unknown world 'moon'"),
        ({"duration": 1.0}, "duration"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        cm.compare_controllers_mimo(**kwargs)
    assert "\n" not in str(err.value)


def test_the_continuous_design_model_has_the_design_models_gain_and_refuses_a_bad_pade_order():
    g = cm.continuous_design_model()
    assert g.ninputs == g.noutputs == 2 and np.all(np.real(g.poles()) < 1e-9)
    with pytest.raises(InputError, match="pade_order"):
        cm.continuous_design_model(pade_order=9)


def test_disk_margins_are_given_at_each_input_and_the_decentralised_pid_is_offered_only_with_4_db(comparison):
    """Loop-at-a-time disk margins on the design model: every design's loop is stable with margins at both inputs;
    the decentralised PID is offered because it has at least 4 dB at each (on the twin's linearisation too), and a
    PID without that is refused with the measured margin."""
    m = comparison.margins
    for name in cm.CONTROLLERS:
        assert len(m[name]) == 2 and all(d.stable and d.gain_margin_db > 1.0 for d in m[name]), name
    assert all(d.gain_margin_db >= cm.PID_GAIN_MARGIN_DB for d in m["MIMO PID"]) and comparison.refused == {}
    designs = cm.design_controllers_mimo(0.1)
    from trms.control.pid_tuning import channel_model, tune_pid

    eager = tuple(tune_pid(channel_model(designs.model, k, k), Ms=1.7) for k in range(2))
    assert cm.pid_refusal(designs.model, eager).startswith(("disk gain margin", "the decentralised loops are unstable"))
    rows = {(r[0], r[1], r[2]): r[-2] for r in cm.table_controllers_mimo(comparison).rows}
    assert rows[("MIMO LQG", "pitch step", "linear model")].count("dB") == 2


def test_input_disk_margins_refuse_a_feedback_that_does_not_chain():
    import control
    import numpy as np

    from trms.control.margins import input_disk_margins
    from trms.errors import InputError

    g = control.ss([[0.5]], [[1.0, 0.0]], [[1.0]], [[0.0, 0.0]], 0.1)  # 2 inputs, 1 output
    with pytest.raises(InputError, match="the feedback must map the plant's 1 outputs to its 2 inputs"):
        input_disk_margins(g, control.ss([], [], [], np.eye(2), 0.1))
