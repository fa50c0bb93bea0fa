"""The spectral stage's search (trms.calibration.coupling.fit_coupling), on a known score surface.

The candidates' scores come from a quadratic bowl instead of the twin's protocol runs, so that the
grid search and the compass search can be checked against a known optimum and a known count of
scored candidates.
"""

import numpy as np
import pytest

from trms.calibration import Targets
from trms.calibration import coupling as coupling_module
from trms.calibration.coupling import COUPLING_GRID, fit_coupling
from trms.twin import load_spec
from trms.twin.parameters import with_parameters

NAMES = ("main_rotor_tilt", "main_rotor_inertia_radius", "tail_reaction")


@pytest.fixture
def bowl(monkeypatch):
    """Score = squared distance (in grid steps) from ``optimum``; every call's candidates are recorded."""
    state = {"optimum": {}, "calls": []}

    def fake(spec, candidates, targets, protocols, counts_per_rev, cluster):
        state["calls"].append(candidates)
        steps = {n: np.min(np.diff(sorted(COUPLING_GRID[n]))) for n in NAMES}
        score = [sum(((c[n] - state["optimum"][n]) / steps[n]) ** 2 for n in NAMES) for c in candidates]
        return np.array(score), np.zeros(len(candidates))

    monkeypatch.setattr(coupling_module, "evaluate_candidates", fake)
    return state


def n_scored(state):
    return sum(len(c) for c in state["calls"])


def test_grid_then_compass_search_reach_the_optimum_and_score_each_candidate_once(bowl):
    # Half a grid step from the coarse grid's best point (0.25, 0.18, 0.003) along every axis.
    bowl["optimum"] = {"main_rotor_tilt": 0.225, "main_rotor_inertia_radius": 0.145, "tail_reaction": 0.0025}
    start = {"main_rotor_tilt": 0.25, "main_rotor_inertia_radius": 0.1, "tail_reaction": 0.0}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES)
    assert fit.values == pytest.approx(bowl["optimum"])
    # The start alone (it does not meet the targets), the 26 other grid points, then one compass move per axis and
    # the confirmation of the centre, each batch holding only the neighbours not scored before.
    sizes = [len(c) for c in bowl["calls"]]
    assert sizes[:2] == [1, 26] and len(sizes) == 6 and sizes[2] == 6 and max(sizes[3:]) <= 6
    assert fit.n_candidates == n_scored(bowl)


def test_a_start_off_the_grid_competes_with_it(bowl):
    start = {"main_rotor_tilt": 0.07, "main_rotor_inertia_radius": 0.2, "tail_reaction": 0.002}
    bowl["optimum"] = {**start, "main_rotor_tilt": 0.0701}  # the start misses it, but is the best point in reach
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES)
    assert fit.values == pytest.approx(start) and fit.score > 0.0
    # the start, the grid, then the compass confirms the start
    assert [len(c) for c in bowl["calls"]] == [1, 27, 6]


def test_a_start_that_meets_every_target_is_kept_though_grid_points_have_more_room(monkeypatch):
    calls = []

    def fake(spec, candidates, targets, protocols, counts_per_rev, cluster):
        calls.append(candidates)  # every candidate meets every target; the grid's have more room than the start
        return np.zeros(len(candidates)), np.array([0.0 if c == start else 1.0 for c in candidates])

    monkeypatch.setattr(coupling_module, "evaluate_candidates", fake)
    start = {"main_rotor_tilt": 0.07, "main_rotor_inertia_radius": 0.2, "tail_reaction": 0.002}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES)
    assert fit.values == pytest.approx(start) and fit.converged and fit.n_candidates == 1 == len(calls)


def test_compass_search_confirms_an_optimum_with_2n_plus_1_candidates(bowl):
    start = {"main_rotor_tilt": 0.075, "main_rotor_inertia_radius": 0.135, "tail_reaction": 0.0015}
    bowl["optimum"] = {**start, "main_rotor_tilt": 0.0751}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES, coarse=False)
    assert fit.values == pytest.approx(start) and fit.n_candidates == 7 == n_scored(bowl)


def test_compass_search_walks_to_a_nearby_optimum(bowl):
    start = {"main_rotor_tilt": 0.3, "main_rotor_inertia_radius": 0.1, "tail_reaction": 0.001}
    # Two half steps away in lean, one in radius.
    bowl["optimum"] = {"main_rotor_tilt": 0.35, "main_rotor_inertia_radius": 0.135, "tail_reaction": 0.001}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES, coarse=False)
    assert fit.values == pytest.approx(bowl["optimum"])
    assert len(bowl["calls"]) == 5  # the start, its neighbours, two more moves, then the confirmation of the centre
    assert fit.n_candidates == n_scored(bowl) < 4 * 7  # neighbours already scored are not run again


def test_compass_search_scores_a_point_reached_from_two_centres_once(bowl):
    # 0.05 + 0.025 - 0.025 is not 0.05 in floating point: the centre the search came from must still be a cache hit.
    start = {"main_rotor_tilt": 0.05, "main_rotor_inertia_radius": 0.18, "tail_reaction": 0.001}
    bowl["optimum"] = {**start, "main_rotor_tilt": 0.075}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES, coarse=False)
    assert fit.values["main_rotor_tilt"] == 0.075
    # the start, its 6 neighbours, then 5 new around the move (its centre and the start already scored).
    assert [len(c) for c in bowl["calls"]] == [1, 6, 5] and fit.n_candidates == 12


def test_compass_search_says_when_it_ran_out_of_moves(bowl):
    from trms.calibration.coupling import MAX_COMPASS_MOVES

    start = {"main_rotor_tilt": 0.0, "main_rotor_inertia_radius": 0.1, "tail_reaction": 0.001}
    # Six half steps away in lean: more moves than the search may make.
    bowl["optimum"] = {"main_rotor_tilt": 0.15, "main_rotor_inertia_radius": 0.1, "tail_reaction": 0.001}
    fit = fit_coupling(with_parameters(load_spec(), start), Targets.thesis(), NAMES, coarse=False)
    assert not fit.converged and len(bowl["calls"]) == MAX_COMPASS_MOVES + 1  # the start alone, then the moves
    assert fit.values["main_rotor_tilt"] == pytest.approx(0.0 + MAX_COMPASS_MOVES * 0.025)
    bowl["calls"].clear()
    near = fit_coupling(with_parameters(load_spec(), fit.values), Targets.thesis(), NAMES, coarse=False)
    assert near.converged and near.values == pytest.approx(bowl["optimum"])
