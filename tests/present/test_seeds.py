"""A cell over seeds and its verdict: planted cells whose answer is known."""

import math

import pytest

from trms.present.seeds import (
    AGREES,
    DIFFERS,
    OverSeeds,
    Seeded,
    agreeing,
    inconclusive,
    over_seeds,
    seed_agrees,
    seeded,
    verdict,
)
from trms.present.tables import format_cell, note_far_cells, side_by_side

SEEDS = (0, 1000, 2000, 3000, 4000)


@pytest.mark.parametrize(
    "values, expected",
    [
        ((3.1, 3.3, 2.8, 3.5, 2.9), AGREES),  # every seed within 30 % of 3
        ((2.2, 3.8, 3.0, 3.0, 3.0), AGREES),  # 27 % under and 27 % over: still within at every seed
        ((9.0, 8.0, 12.0, 10.0, 9.5), DIFFERS),  # every seed beyond it
        ((1.0, 9.0, 1.5, 8.0, 2.0), DIFFERS),  # on both sides of it, but beyond it at every seed
        ((3.1, 9.0, 3.3, 3.0, 2.9), inconclusive(5)),  # one seed off: a seed-dependent cell
    ],
)
def test_a_cell_agrees_only_at_every_seed_differs_only_at_every_seed(values, expected):
    assert verdict(3.0, OverSeeds(values, SEEDS)) == expected


def test_the_seed_dependent_cell_of_table_5_1_is_inconclusive():
    # Table 5.1's NARX-RBF variance: 7.86e-6 at seed 0 (22 % off 6.42e-6), 1.66e-5 and 1.1e-5 at seeds 1 and 3
    cell = OverSeeds((7.86e-6, 1.66e-5, 1.1e-5), (0, 1, 3))
    assert verdict(6.42e-6, cell) == "inconclusive at 3 seeds"
    assert agreeing(6.42e-6, cell) == (1, 3)
    assert verdict(6.42e-6, 7.86e-6) == AGREES  # one seed alone would have said "agrees"


def test_a_printed_range_words_modes_and_a_push():
    assert verdict((5.0, 6.0), OverSeeds((5.5, 6.2, 7.7), (0, 1, 2))) == AGREES  # 7.7 is 28 % over 6
    assert verdict((5.0, 6.0), OverSeeds(("hit the stops",) * 3, (0, 1, 2))) == DIFFERS  # a word never agrees
    assert verdict((5.0, 6.0), OverSeeds(("hit the stops", 5.5), (0, 1))) == inconclusive(2)
    assert verdict("0.1, 0.34", OverSeeds(("0.10, 0.33", "0.34"), (0, 1))) == inconclusive(2)
    assert verdict("0.1", OverSeeds(("0.10", "0.09"), (0, 1))) == AGREES
    assert verdict("rejected", OverSeeds((9.8, 11.2), (0, 1))) == AGREES
    assert verdict("rejected", OverSeeds((9.8, "not recovered"), (0, 1))) == inconclusive(2)
    assert verdict("high", OverSeeds((1.0, 2.0), (0, 1))) is None and seed_agrees("-", 1.0) is None
    assert not seed_agrees(3.0, float("nan"))


def test_a_cell_prints_its_median_range_and_seeds_and_serialises():
    cell = OverSeeds((30.1, 34.0, 28.2, 29.0, 31.5), SEEDS)
    assert str(cell) == "30.1 (28.2-34; 5 seeds)" == format_cell(cell)
    assert cell.to_dict() == {"median": 30.1, "range": [28.2, 34.0], "values": list(cell.values), "seeds": list(SEEDS)}
    assert str(OverSeeds((-11.0, -9.0), (0, 1))) == "-10 (-11 to -9; 2 seeds)"
    nan = OverSeeds((float("nan"), 2.0), (0, 1))
    assert str(nan) == "2 (2-2; 2 seeds; not reached at 1)" and nan.to_dict()["values"][0] == "nan"
    assert math.isnan(OverSeeds(("diverged",), (0,)).median)
    with pytest.raises(ValueError, match="one value per seed"):
        OverSeeds((1.0,), (0, 1))


def test_results_by_seed_read_each_cell_at_every_seed():
    runs = Seeded(SEEDS[:3], ({"a": 1.0}, {"a": 2.0}, {"a": 4.0}))
    assert runs.first == {"a": 1.0}
    assert runs.cell(lambda r: r["a"]) == OverSeeds((1.0, 2.0, 4.0), SEEDS[:3])
    assert seeded({"a": 1.0}).cell(lambda r: r["a"]) == 1.0 and over_seeds([1.0], [7]) == 1.0
    with pytest.raises(ValueError, match="one result per seed"):
        Seeded((0,), ())


def test_a_seed_dependent_cell_gets_an_inconclusive_note_and_a_differing_one_its_reason():
    t = side_by_side("T", ["q"])
    t.rows = [
        ["planted", 3.0, 3.0, OverSeeds((3.1, 9.0, 3.0), (0, 1, 2)), ""],
        ["far", 3.0, 3.0, OverSeeds((9.0, 8.0, 10.0), (0, 1, 2)), ""],
        ["near", 3.0, 3.0, OverSeeds((3.1, 3.2, 2.9), (0, 1, 2)), ""],
    ]
    note_far_cells(t, lambda row, col, v, th: f"{format_cell(v)} vs {format_cell(th)}; not explained.")
    assert t.notes == [
        "note 1: planted, twin: 3.1 (3-9; 3 seeds) vs thesis 3: within 30% at 2 of 3 seeds: inconclusive at 3 seeds.",
        "note 2: far, twin: 9 (8-10; 3 seeds) vs 3; not explained.",
    ]
    assert [r[-1] for r in t.rows] == ["note 1", "note 2", ""]
