"""Chapters 6 and 7 assembled over the twin's seeds: Table 6.1's cells, the push and the findings at every seed."""

import pytest

from trms.experiments import ch67_chapter as ch
from trms.experiments.ch67_lqg import CaseResult, PushResult
from trms.present.seeds import OverSeeds, Seeded


@pytest.fixture(scope="module")
def seeded_chapter(ch67_results, tmp_path_factory):
    lin, twin, push, weights, margins = ch67_results
    other = {k: CaseResult(c.status, c.summary, None) for k, c in twin.items()}
    # a planted seed at which R = 125's push is not rejected
    other_push = {
        r: PushResult("not recovered", p.peak, float("nan"), None) if r == 125.0 else p for r, p in push.items()
    }
    models = {"linear": "eq. (3.11)", "twin": "its linearisation at hover"}
    folder = tmp_path_factory.mktemp("ch67_seeds")
    return ch.chapter(
        lin, Seeded((0, 1000), (twin, other)), Seeded((0, 1000), (push, other_push)), margins, models, folder, weights
    )


def test_the_twins_cells_push_and_findings_are_read_at_every_seed(seeded_chapter, ch67_results):
    _, twin, push, *_ = ch67_results
    row = seeded_chapter.table_6_1[(75.0, "SAS", "TR")]
    assert row.twin == OverSeeds((twin[(75.0, "SAS")].summary["TR"],) * 2, (0, 1000))
    back = seeded_chapter.push[125.0].twin
    assert isinstance(back, OverSeeds) and back.values[1] == "not recovered"
    tf = seeded_chapter.section.tables[4]
    rows = {r[0]: r for r in tf.rows}
    assert rows["push rejected by all three controllers"][3] == "shown at 1 of 2 seeds"
    assert "at every one of its 2 seeds (0, 1000), 1 at some only" in tf.notes[0]
    assert seeded_chapter.section.conclusion[0].count("Shown at some seeds only: push rejected") == 1
