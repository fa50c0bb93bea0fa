"""End-stop hits and the seeded coarse start, on inputs whose answer is known by construction."""

import numpy as np
import pytest

from trms.calibration.timedomain.feasible_start import STOP_MARGIN, StopHit, best_feasible, latin_hypercube, stop_hit

STOPS = [(-1.1, 1.1), (-3.0, 3.0)]
AXES = ["pitch", "yaw"]
T = np.arange(10) * 0.1


def _path(peak_pitch, peak_yaw=0.5):
    """A rise to the peaks at sample 5 and back: both axes, rad."""
    shape = np.minimum(np.arange(10), 10 - np.arange(10)) / 5.0
    return np.column_stack([peak_pitch * shape, peak_yaw * shape])


def test_a_stop_the_record_stays_away_from_is_a_hit_at_its_first_sample():
    measured = _path(0.5)
    predicted = _path(1.1)  # reaches the margin band at sample 5 (1.1 * 5 / 5), not before (0.88 at sample 4)
    hit = stop_hit(predicted, measured, T, STOPS, AXES, "rig1")
    assert hit == StopHit("pitch", "rig1", pytest.approx(0.5), pytest.approx(1.1), 1.1, (0.0, pytest.approx(0.5)))
    assert "pitch end stop (+1.1 rad) on record rig1 at 0.50 s" in str(hit)


def test_the_margin_band_counts_as_the_stop_and_nothing_short_of_it_does():
    band = STOP_MARGIN * 2.2
    measured = _path(0.2)
    just_in = _path(1.1 - 0.9 * band)  # peak just inside the band
    just_out = _path(1.1 - 1.5 * band)
    assert stop_hit(just_in, measured, T, STOPS, AXES, "r").time == pytest.approx(0.5)
    assert stop_hit(just_out, measured, T, STOPS, AXES, "r") is None


def test_a_stop_the_record_reaches_itself_is_the_rigs_and_no_hit():
    measured = _path(1.1)
    assert stop_hit(_path(1.1), measured, T, STOPS, AXES, "r") is None
    # the other stop of the same axis is still one the record stays away from
    assert stop_hit(_path(-1.1), measured, T, STOPS, AXES, "r").stop == -1.1


def test_the_earliest_hit_over_the_axes_wins_and_an_axis_without_stops_never_hits():
    measured = _path(0.2, 0.2)
    predicted = _path(1.1, 3.0)
    predicted[2:, 1] = 3.0  # yaw on its stop from sample 2, pitch only from sample 5
    hit = stop_hit(predicted, measured, T, STOPS, AXES, "r")
    assert (hit.axis, hit.time, hit.stop) == ("yaw", pytest.approx(0.2), 3.0)
    assert stop_hit(predicted, measured, T, [None, None], AXES, "r") is None


def test_a_prediction_that_is_not_finite_is_a_hit():
    predicted = _path(0.3)
    predicted[7, 0] = np.nan
    hit = stop_hit(predicted, _path(0.3), T, [None, None], AXES, "r")
    assert hit.time == pytest.approx(0.7) and "is not finite at 0.70 s" in str(hit)


def test_latin_hypercube_is_seeded_stratified_and_within_its_stretch():
    x0, lo, hi = np.array([1.0, 0.0, 2.0]), np.array([0.1, -1.0, 1.0]), np.array([10.0, 1.0, 3.0])
    a = latin_hypercube(x0, lo, hi, 8, seed=4)
    assert np.array_equal(a, latin_hypercube(x0, lo, hi, 8, seed=4))
    assert not np.array_equal(a, latin_hypercube(x0, lo, hi, 8, seed=5))
    assert a.shape == (8, 3)
    # log-uniform within a factor 2 of the start, cut to the bounds
    assert np.all((a[:, 0] >= 0.5) & (a[:, 0] <= 2.0)) and np.all((a[:, 2] >= 1.0) & (a[:, 2] <= 3.0))
    # a start at zero is drawn over its whole bounds
    assert np.all(np.abs(a[:, 1]) <= 1.0)
    # Latin hypercube: one candidate in each of the 8 equal strata (in log for the positive parameter)
    strata = np.floor((np.log(a[:, 0]) - np.log(0.5)) / (np.log(4.0) / 8)).astype(int)
    assert sorted(strata) == list(range(8))
    wide = latin_hypercube(x0, lo, hi, 8, seed=4, spread=None)
    assert wide[:, 0].max() > 2.0 and wide[:, 0].min() < 0.5
    assert np.all((wide >= lo) & (wide <= hi))


def test_best_feasible_picks_the_least_sum_of_squares_among_candidates_without_a_hit():
    hit = StopHit("pitch", "r", 1.0, 1.1, 1.1, (-0.5, 0.6))
    assert best_feasible(np.array([0.5, 3.0, 2.0, np.nan]), [hit, None, None, None]) == 2
    assert best_feasible(np.array([0.5, 3.0]), [hit, hit]) is None
    assert best_feasible(np.array([np.inf, 1.0]), [None, hit]) is None
