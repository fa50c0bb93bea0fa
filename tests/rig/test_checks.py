"""The checks of an export's columns, on cases whose answer is known: grids, sample times, voltages, angles."""

import numpy as np
import pytest

from trms.errors import InputError
from trms.record import Record
from trms.rig.checks import (
    END_STOP_MARGIN,
    JITTER_TOLERANCE,
    ExportLayout,
    beyond_end_stops,
    check_angles,
    check_export_sample_time,
    check_voltages,
    uniform_grid,
)


def _layout(resample=False, units="rad", time_unit="s"):
    return ExportLayout("t", ("V",), ("pitch",), units, time_unit, resample, ("u1",), ("pitch",))


def _row(i):
    return f"row {i + 2}"


def test_jitter_within_the_tolerance_is_snapped_to_the_exact_grid():
    t = np.arange(200) * 0.05 + 0.2 * JITTER_TOLERANCE * 0.05 * np.sin(np.arange(200))
    data = np.column_stack([t, np.ones(200), np.zeros(200)])
    out, ts, origin, notes = uniform_grid(data, _layout(), _row, "")
    assert ts == pytest.approx(0.05, abs=1e-12) and abs(origin) < 1e-5
    np.testing.assert_allclose(out[:, 0], origin + np.arange(200) * ts, rtol=0, atol=1e-12)
    assert len(notes) == 1 and "snapped to the grid" in notes[0]


def test_a_lost_sample_is_refused_unless_resampled_and_a_ramp_comes_back_exactly():
    t = np.delete(np.arange(100) * 0.05, 40)
    data = np.column_stack([t, 2.0 + t, np.zeros(99)])
    with pytest.raises(InputError, match=r"row 42, column 't': sample interval 0.1 s differs"):
        uniform_grid(data, _layout(), _row, "")
    out, ts, _, notes = uniform_grid(data, _layout(resample=True), _row, "")
    assert out.shape[0] == 100 and ts == 0.05 and "99 rows -> 100 samples" in notes[0]
    np.testing.assert_allclose(out[:, 1], 2.0 + np.arange(100) * 0.05, rtol=0, atol=1e-12)


def test_a_sample_time_in_ms_read_as_s_says_time_unit_ms():
    with pytest.raises(InputError, match=r"sample time 50 s .* outside the rig's range .*--time-unit ms"):
        check_export_sample_time(50.0, _layout(), "")
    assert check_export_sample_time(0.05, _layout(), "") is None
    assert "cannot resolve the rig's" in check_export_sample_time(2.0, _layout(), "")


def test_voltages_beyond_the_drives_are_noted_and_beyond_plausible_refused():
    assert check_voltages(np.array([[1.0], [9.0]]), _layout(), _row, "") == []
    (note,) = check_voltages(np.array([[1.0], [12.0]]), _layout(), _row, "")
    assert "voltage reaches 12 V, beyond the drives' +-10 V" in note
    with pytest.raises(InputError, match=r"row 3, column 'V': 1000 V is beyond the plausible \+-100 V"):
        check_voltages(np.array([[1.0], [1000.0]]), _layout(), _row, "")


def test_degrees_labelled_radians_are_refused_with_the_unit_that_fits():
    y = np.array([[0.0], [20.0], [40.0]])  # pitch in degrees: 40 rad is far beyond the 1.1 rad stop
    with pytest.raises(InputError, match=r"pitch 40 rad is beyond pitch's end stops .*say units='deg'"):
        check_angles(y, 0.5, _layout(), _row, "")
    assert check_angles(y, 0.5, _layout(units="deg"), _row, "") == []


def test_beyond_end_stops_uses_the_margin_for_measured_data_and_none_for_a_model():
    stop = 1.1
    r = Record(np.arange(2) * 0.1, np.zeros(2), [0.0, stop * (1 + END_STOP_MARGIN / 2)], ("u1",), ("pitch",))
    assert beyond_end_stops(r) is None
    assert beyond_end_stops(r, margin=0.0) == "pitch reaches 1.21 rad (end stops +-1.1 rad)"
