"""The calibration report states the twin's large signals and what each parameter is."""

import json

import pytest

from trms.calibration.calibrate import CalibrationResult
from trms.calibration.checks import Check
from trms.calibration.report import format_table, parameter_table, shipped_model_tables, write_report
from trms.calibration.static_pitch import static_pitch_curves
from trms.calibration.targets import Targets
from trms.calibration.verify import Verification
from trms.twin import load_spec
from trms.twin.parameters import PARAMETERS, read_parameters


@pytest.fixture(scope="module")
def result():
    curves = static_pitch_curves(load_spec(), [-0.5, -0.1, 0.0, 0.1, 0.5])
    ver = Verification([Check("peak", 0.34, 0.34, "+-0.03 Hz", True, "Hz", seed=101)], seeds=(101,))
    start = {"main_motor_gain": 1.1, "main_motor_lag": 1.1}
    values = read_parameters(load_spec(), start)
    return CalibrationResult(start, values, ver, [], {}, Targets(), static_pitch=curves)


def test_each_parameter_row_says_physical_with_its_departure_or_lumped_with_what_it_stands_for():
    values = read_parameters(load_spec())
    table = parameter_table(values)
    assert [row[0] for row in table.rows] == list(PARAMETERS)
    for row in table.rows:
        p = PARAMETERS[row[0]]
        assert row[1] == p.role and row[3] == f"{p.published:.4g} [{p.source}]"
        if p.role == "lumped":
            assert row[-1] == f"stands for {p.stands_for}"
        if p.published:
            assert row[4] == f"{100 * (values[p.name] / p.published - 1):+.0f} %"
        else:
            assert row[4] == "-"
    assert "[F] Feedback's TRMS manual parameter table" in table.notes[0]


def test_the_printed_report_and_its_json_give_the_static_curve_and_the_roles(result, tmp_path):
    text = format_table(result)
    assert "The twin's static pitch over the main rotor's voltage" in text
    assert "| main_motor_gain | lumped | 1.1 | 3.15 | 1.1 [S] | +186 % |" in text
    js, png = write_report(result, tmp_path)
    data = json.loads(js.read_text())
    assert data["parameters"]["main_motor_gain"]["role"] == "lumped"
    assert data["parameters"]["main_motor_lag"]["departure"] == pytest.approx(result.values["main_motor_lag"] / 1.1 - 1)
    assert data["static_pitch"]["twin"]["on_stop"] == [False, False, False, False, True]
    assert png.stat().st_size > 10_000


def test_the_main_reports_tables_carry_the_curve_and_the_roles(monkeypatch):
    from trms.calibration import evidence

    monkeypatch.setattr(evidence, "measured", lambda spec, side_peaks: (Verification([], seeds=(101,)), None))
    tables, _ = shipped_model_tables(load_spec(), evidence=False)
    titles = [t.title for t in tables]
    assert any(t.startswith("The twin's static pitch") for t in titles)
    assert titles[-1].startswith("The twin's parameters: physical") and len(tables[-1].rows) == len(PARAMETERS)
