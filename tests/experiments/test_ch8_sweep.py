"""The amplitude sweep: a design holds where its twin overshoot is within 10 points (or the noise) of its design
model's; the largest amplitude up to which it holds; the gap the inversion setting is chosen by."""

import math

import pytest

from trms.errors import InputError
from trms.experiments import ch8_sweep as cs


def _point(scale, overshoot, linear=5.0, noise=2.0, inversion=True, name="PID"):
    return cs.SweepPoint(name, "twin, moving air", scale, inversion, overshoot, 0, 4, linear, noise)


def test_holding_is_within_ten_points_or_the_noise():
    assert _point(1.0, 14.9).holds and not _point(1.0, 15.1).holds
    assert _point(0.1, 30.0, noise=30.0).holds and not _point(1.0, math.nan).holds


def test_the_largest_amplitude_is_the_last_of_an_unbroken_run_from_the_smallest():
    pts = (_point(0.1, 6.0), _point(0.25, 30.0), _point(0.5, 7.0), _point(1.0, 8.0))
    assert cs.largest_valid_scale(cs.Sweep(pts, (0,), 0.2), "PID", "twin, moving air", True) == 0.1
    assert cs.largest_valid_scale(cs.Sweep(pts[2:], (0,), 0.2), "PID", "twin, moving air", True) == 1.0
    assert cs.largest_valid_scale(cs.Sweep((_point(0.1, 40.0),), (0,), 0.2), "PID", "twin, moving air", True) == 0.0


def test_the_gap_and_the_table_say_which_setting_the_measurement_supports():
    pts = (_point(1.0, 9.0), _point(1.0, 25.0, inversion=False))
    sweep = cs.Sweep(pts, (3,), 0.2)
    assert cs.inversion_gap(sweep, True) == 4.0 and cs.inversion_gap(sweep, False) == 20.0
    table = cs.table_sweep(sweep)
    assert [r[2] for r in table.rows] == ["off", "on"] and "(the setting with the smaller gap)" in table.notes[1]


@pytest.fixture(scope="module")
def sweep():
    return cs.amplitude_sweep(seeds=(903,), scales=(0.25, 1.0), other_at=(1.0,))


def test_a_flown_sweep_holds_every_design_at_every_amplitude_in_still_air(sweep):
    still = [p for p in sweep.points if p.case.startswith("twin, still air")]
    assert {p.scale for p in still} == {0.25, 1.0} and all(p.holds and p.unsettled == 0 for p in still if p.inversion)
    assert {(p.scale, p.inversion) for p in still} == {(0.25, True), (1.0, True), (1.0, False)}
    assert cs.inversion_gap(sweep, True) <= cs.inversion_gap(sweep, False)


def test_bad_sweeps_are_refused_in_one_line():
    with pytest.raises(InputError, match="seeds must name at least one seed"):
        cs.amplitude_sweep(seeds=())
    with pytest.raises(InputError, match="scale = 3.0 is outside"):
        cs.amplitude_sweep(scales=(3.0,))
