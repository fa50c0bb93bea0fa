"""Fault tolerance on the twin: the calibrated test stays quiet without a fault, finds each fault, and the
re-designed loop estimates the thrust it lost and tracks better than the nominal one."""

from __future__ import annotations

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments.ch8 import fault_tolerance as ft


@pytest.fixture(scope="module")
def study():
    return ft.fault_tolerance((0, 1, 2, 3), (10, 11), (20,), list(ft.SCENARIOS))


def test_without_a_fault_the_calibrated_test_stays_quiet_and_nothing_is_re_designed(study):
    assert study.false_alarm_rate <= 5 * ft.FALSE_ALARM_RATE
    assert study.wrong_switches == 0 and study.n_false_alarm_runs == 2
    assert study.detector.threshold > 0 and study.detector.window == ft.WINDOW


def test_the_thrust_losses_are_found_fast_and_estimated_and_the_loop_re_designed(study):
    runs = {r.scenario: r for r in study.runs}
    heavy, light = runs["main rotor thrust -50 %"], runs["main rotor thrust -30 %"]
    assert heavy.delay < 2.0 and light.delay < 10.0
    # eq. (3.11)'s gain differs from the twin's by a few per cent: the estimate is the product of both
    assert 0.4 < heavy.effectiveness < 0.6 and 0.6 < light.effectiveness < 0.95
    assert heavy.rms_reconfigured < 0.95 * heavy.rms_nominal
    assert light.rms_reconfigured < light.rms_nominal
    assert heavy.rms_nominal > light.rms_nominal > heavy.rms_healthy  # the bigger the loss, the worse the nominal


def test_an_encoder_dropout_is_taken_for_a_dead_sensor_not_for_an_actuator_fault(study):
    dropout = next(r for r in study.runs if r.scenario.startswith("pitch encoder"))
    # the innovation test sees it only when the reading resumes (a frozen reading is predicted well) ...
    assert 9.0 <= dropout.delay <= 11.0
    # ... the reconfiguring loop sees the reading stand still, runs on its model, and re-designs nothing
    assert dropout.sensor_delay == pytest.approx((ft.FROZEN - 1) * 0.2, abs=0.25)
    assert dropout.effectiveness == 1.0
    assert all(np.isnan(r.sensor_delay) for r in study.runs if r.scenario.startswith("main rotor"))


def test_the_table_has_a_row_per_scenario_and_states_the_measured_false_alarms(study):
    table = ft.table_fault_tolerance(study)
    assert [row[0] for row in table.rows] == list(ft.SCENARIOS)
    assert all(row[1] == "1/1" for row in table.rows)
    assert any("unseen fault-free runs" in note and "alarms per sample" in note for note in table.notes)
    assert any(f"calibrated on {study.n_train_runs} fault-free runs" in note for note in table.notes)
    assert not table.missing()


@pytest.mark.parametrize(
    "args, match",
    [
        (((0, 1), (1,), (2,), ()), "must be disjoint sets"),
        (((0,), (), (), ["wing loss"]), r"unknown scenarios \['wing loss'\]"),
        (((), (), (), ()), "train_seeds must name at least one calibration run"),
        (((0,), (), (), "main rotor thrust -50 %"), "scenarios must be a list of names"),
    ],
)
def test_bad_studies_are_refused_in_one_line(args, match):
    with pytest.raises(InputError, match=match):
        ft.fault_tolerance(*args)


def test_the_scenarios_start_at_the_stated_time():
    assert all(f.at == ft.FAULT_AT for faults in ft.SCENARIOS.values() for f in faults)
    assert np.isclose(ft.FAULT_AT % 20.0, 10.0)  # mid-way through a half-period of the square wave
