"""The report's typed records: what a run does, the robustness parts merged, every record picklable."""

import pickle

from trms.experiments.ch8.robustness import LOOPS, samples_of
from trms.present.sections import Section
from trms.present.seeds import OverSeeds
from trms.present.tables import ComparisonTable, side_by_side
from trms.report import Report, RobustnessPart, Settings


def test_quick_settings_reduce_but_keep_every_case():
    full, quick = Settings(), Settings(quick=True)
    assert set(quick.weights) < set(full.weights) and {75.0, 1.0, 125.0} <= set(quick.weights)
    assert quick.samples < full.samples and quick.robustness_parts <= full.robustness_parts
    assert quick.estimator_speeds == () and len(full.estimator_speeds) == 2


def test_every_run_judges_its_twin_cells_over_seeds_of_its_own():
    """The full run's five seeds and the quick run's two, its own first: the seeds of runs at 0, 1 and 3 share none
    (every experiment adds less than the stride to its seed)."""
    assert Settings().seeds == (0, 1000, 2000, 3000, 4000) and Settings(quick=True, seed=3).seeds == (3, 1003)
    runs = [set(Settings(seed=s).seeds) for s in (0, 1, 3)]
    assert all(a.isdisjoint(b) for i, a in enumerate(runs) for b in runs[i + 1 :])


def _row(i):
    loops = {
        n: {"status": "settled" if i % 2 else "diverged", "overshoot": float(i), "settling": 2.0 * i} for n in LOOPS
    }
    return {"index": i, "seed": 100 + i, "parameters": {"mass": 1.0 + i}, "loops": loops}


def test_parts_merge_to_the_batch_of_all_their_rows_in_any_order():
    rows = [_row(i) for i in range(5)]
    nominal = {n: ("settled", 1.0, 2.0) for n in LOOPS}
    parts = [
        RobustnessPart(samples_of(rows[1::2]), None, 1.5),
        RobustnessPart(samples_of(rows[0::2]), nominal, 2.0),
    ]
    merged = RobustnessPart.merge(parts)
    assert merged.batch == samples_of(rows)  # the split does not change the batch
    assert [s.index for s in merged.batch[next(iter(LOOPS))]] == [0, 1, 2, 3, 4]
    assert merged.nominal == nominal and merged.seconds == 3.5


def test_records_survive_the_trip_to_and_from_a_worker():
    part = RobustnessPart(samples_of([_row(0), _row(1)]), {n: ("settled", 1.0, 2.0) for n in LOOPS}, 1.0)
    assert pickle.loads(pickle.dumps(part)) == part
    assert pickle.loads(pickle.dumps(Settings(quick=True, seed=3))) == Settings(quick=True, seed=3)


def test_report_counts_statuses_and_missing_cells_across_its_tables(tmp_path):
    t = side_by_side("T", ["case"])
    t.rows = [
        ["a", 1.0, "hit the stops", float("nan"), ""],
        ["b", 1.0, "settled", OverSeeds(("diverged", 2.0), (0, 1000)), ""],
    ]
    head = ComparisonTable("H", ["quantity", "thesis", "linear model", "twin", "notes"], [["q", 1.0, 1.0, "", ""]])
    report = Report(tmp_path, [Section("S", tables=[t])], head, 1.0)
    assert report.tables() == [head, t]
    assert report.statuses() == {"settled": 1, "not settled": 0, "hit the stops": 1, "diverged": 1}
    assert len(report.missing()) == 2 and report.missing()[0].startswith("H: ")
