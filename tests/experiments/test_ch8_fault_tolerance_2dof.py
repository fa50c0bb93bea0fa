"""The stuck tail rotor under the MIMO LQG: found, its effectiveness estimated near 0, the tail rotor dropped and the
loop re-designed to hold the pitch; the design, the yaw's reach through u1, and the refusals."""

from __future__ import annotations

import control
import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch8_fault_tolerance_2dof as ft2
from trms.experiments.ch8_mimo_lqg import controllers
from trms.worlds import design_model


@pytest.fixture(scope="module")
def study():
    return ft2.fault_tolerance_2dof((0,), (10,), (20,), ["pitch step"], duration=40.0)


def test_the_stuck_tail_rotor_is_found_estimated_near_zero_and_dropped(study):
    (run,) = study.runs
    assert 0.0 < run.delay < 5.0  # u2 cancels u1's reaction torque all the time
    assert run.estimated[1] == pytest.approx(0.0, abs=0.2) and run.estimated[0] == pytest.approx(1.0, abs=0.2)
    assert run.effectiveness[1] == 0.0 and run.switch_delay > run.delay
    assert run.yaw_reachable  # the main rotor's reaction torque still reaches the yaw (controllable subspace)


def test_the_table_counts_where_the_re_designed_loop_holds_an_axis_better_and_the_yaw_suffers(study):
    (run,) = study.runs
    assert run.rms_nominal[1] > 5 * run.rms_healthy[1]  # the yaw suffers from the stuck tail rotor
    table = ft2.table_fault_tolerance_2dof(study)
    cell = table.rows[0][table.columns.index("reconfigured better than nominal, pitch / yaw (runs)")]
    better = (run.rms_reconfigured[0] < run.rms_nominal[0], run.rms_reconfigured[1] < run.rms_nominal[1])
    assert cell == f"{int(better[0])}/1 / {int(better[1])}/1"


def test_without_a_fault_nothing_is_re_designed_and_the_table_states_it(study):
    assert study.wrong_switches == 0 and study.n_false_alarm_runs == 1 and study.n_train_runs == 1
    assert study.false_alarm_rate <= 0.05
    table = ft2.table_fault_tolerance_2dof(study)
    assert [row[:2] for row in table.rows] == [["pitch step", "1/1"]] and _dropped(table) == "1/1"
    assert any("unseen fault-free runs" in note for note in table.notes)
    assert not table.missing()


def _dropped(table):
    return table.rows[0][table.columns.index("u2 dropped (runs)")]


def test_the_design_is_ch8s_mimo_lqg_and_one_input_keeps_the_pitch_integrator():
    m = design_model("2dof")
    assert np.array_equal(ft2.design(m).K, controllers(m)["MIMO LQG"].design.K)
    lost = control.ss(m.A, np.asarray(m.B) * [1.0, 0.0], m.C, m.D, m.dt, states=list(m.state_labels))
    d = ft2.design(lost)
    assert d.tracked == (ft2.KEPT_OUTPUT,) and np.all(d.K[1] == 0.0)
    assert np.max(np.abs(d.regulator_poles)) < 1.0


def test_the_yaw_is_out_of_reach_without_both_rotors():
    m = design_model("2dof")
    frozen_main = np.asarray(m.B) * [0.0, 1.0]
    assert ft2.reaches_yaw(m) and ft2.reaches_yaw(
        control.ss(m.A, frozen_main, m.C, m.D, m.dt, states=list(m.state_labels))
    )
    assert not ft2.reaches_yaw(control.ss(m.A, 0.0 * frozen_main, m.C, m.D, m.dt, states=list(m.state_labels)))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"train_seeds": (0, 1), "false_alarm_seeds": (1,)}, "must be disjoint sets"),
        ({"scenarios": ["roll square wave"]}, r"unknown scenarios \['roll square wave'\]"),
        ({"train_seeds": ()}, "train_seeds must name at least one calibration run"),
        ({"duration": 20.0}, r"duration = 20.0 s is outside the allowed range \[35.0 s, 80.0 s\]"),
    ],
)
def test_bad_studies_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match):
        ft2.fault_tolerance_2dof(**kwargs)
