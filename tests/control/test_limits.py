"""Limits as deviation pairs: a user's pair checked and broadcast, the end stops from the twin's model."""

import numpy as np
import pytest

from trms.control.limits import limit_pair, output_stop_limits
from trms.errors import InputError
from trms.rigdata import end_stops
from trms.worlds import make_plant


def test_the_end_stops_come_from_the_model():
    lo, hi = output_stop_limits(make_plant("linear", "2dof", 0.1))
    stops = end_stops()
    assert hi.tolist() == [stops["pitch"], stops["yaw"]] == (-lo).tolist()


def test_the_end_stops_are_deviations_from_the_trim():
    plant = make_plant("twin", "1dof", 0.1)
    lo, hi = output_stop_limits(plant)
    trim = plant.operating_point.output_deviation(np.zeros(1))  # minus the trim angle
    stop = end_stops()["pitch"]
    assert hi[0] == pytest.approx(stop + trim[0]) and lo[0] == pytest.approx(-stop + trim[0])


def test_a_pair_broadcasts_scalars_and_keeps_infinite_sides():
    lo, hi = limit_pair("input_limits", (-np.inf, 2.0), 3)
    assert lo.tolist() == [-np.inf] * 3 and hi.tolist() == [2.0] * 3
    lo, hi = limit_pair("input_limits", None, 2)
    assert np.isinf(lo).all() and np.isinf(hi).all()


@pytest.mark.parametrize(
    "value, match",
    [
        ((1.0,), "must be a pair"),
        ("ab", "must be a pair"),
        ((np.nan, 1.0), "input_limits lower"),
        ((-1.0, [1.0, 2.0, 3.0]), r"shape \(2,\), got shape \(3,\)"),
        ((-1.0, "x"), "input_limits upper"),
    ],
)
def test_a_bad_pair_is_refused_in_one_line(value, match):
    with pytest.raises(InputError, match=match) as err:
        limit_pair("input_limits", value, 2)
    assert "\n" not in str(err.value)
