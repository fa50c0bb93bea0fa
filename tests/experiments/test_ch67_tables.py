"""Chapters 6/7 presented: Table 6.1, the margins and the ch. 7 findings, built by the report's own builders.

The twin is being recalibrated: these tests pin what the report claims (orderings, findings, that every
cell more than 30 % off carries a computed note), never the twin's current numbers.
"""

import math
import re

import pytest

from trms.experiments import ch7_findings as cf
from trms.experiments import ch67_chapter as ch
from trms.experiments import ch67_tables as lt
from trms.experiments.ch67_lqg import NARROW_BAND, STATUSES, CaseResult
from trms.present.tables import EXPLAIN_ABOVE, relative_difference
from trms.reference import TABLE_6_1


@pytest.fixture(scope="module")
def built(ch67_results, side_mode_evidence, tmp_path_factory):
    lin, twin, push, weights, margins = ch67_results
    models = {"linear": "eq. (3.11)", "twin": "its linearisation at hover"}
    from trms.worlds import design_model

    folder = tmp_path_factory.mktemp("ch67")
    flight = cf.pci_flight(design_model("1dof"), twin[(75.0, "SAS")])
    evidence = ch.TwinEvidence(side_mode_evidence, flight)
    chapter = ch.chapter(lin, twin, push, margins, models, folder, weights, evidence)
    return chapter.section, ch67_results, chapter


def _rows(table):
    return {tuple(row[:3]): dict(zip(table.columns, row)) for row in table.rows}


def test_table_6_1_holds_the_thesis_rows_and_finite_or_named_cells(built):
    sec, *_ = built
    t61 = sec.tables[0]
    rows = _rows(t61)
    assert {(r, c) for (r, c, _) in rows} == set(TABLE_6_1)
    for row in rows.values():
        for col in ("linear model", "twin"):
            cell = row[col]
            if isinstance(cell, float):
                assert math.isfinite(cell), row
            elif row["measure"] == "control" and cell not in STATUSES:
                # a sensitivity, not a verdict: the square-wave amplitude where the peak control meets the limit
                assert cell.startswith("limit from +-") and float(cell.split("+-")[1].split()[0]) > 0, row
            else:
                assert cell in STATUSES, row
                # a named status always points at its note (the control column is a sensitivity: never a note)
                assert row["notes"] or row["measure"] == "control", row


def test_every_cell_beyond_30_percent_has_a_computed_note(built):
    sec, *_ = built
    t61 = sec.tables[0]
    notes = {n.split(":", 1)[0]: n for n in t61.notes if n.startswith("note ")}
    for row in t61.rows:
        for col in ("linear model", "twin"):
            cell = row[t61.columns.index(col)]
            if isinstance(cell, float) and relative_difference(cell, row[3]) > EXPLAIN_ABOVE:
                refs = [m.strip() for m in row[-1].split(",") if m.strip()]
                assert refs and all(r in notes for r in refs), row
    referenced = {m.strip() for row in t61.rows for m in str(row[-1]).split(",") if m.strip().startswith("note ")}
    assert referenced == set(notes)  # no note without a cell citing it, no citation without its note
    for n in notes.values():
        assert "not explained" in n or "explained by" in n or "band" in n or "the run" in n or "scaled" in n, n


def test_the_twins_cells_carry_a_note_exactly_where_the_run_calls_for_one(built):
    # recomputed from the runs: a failed run, an unsettled step, a cell more than 30 % off, or a settling time
    # read in the wide band carries a note on the twin's cell; every other cell carries none
    _, (lin, twin, *_), chapter = built
    rows = chapter.table_6_1
    assert {(r, c) for r, c, _ in rows} == set(TABLE_6_1) and len(rows) == 3 * len(TABLE_6_1)
    for (r, case, key), row in rows.items():
        res = twin[(r, case)]
        if key == "control":  # a sensitivity, not a verdict: never a note
            called = False
        elif res.status in ("hit the stops", "diverged"):
            called = True
        else:
            value = float(res.summary[key])
            wide = key == "TS" and res.summary["band"] != NARROW_BAND
            called = not math.isfinite(value) or relative_difference(value, row.thesis) > EXPLAIN_ABOVE or wide
        assert bool(row.twin_notes) == called, (r, case, key, row)
        for note in row.twin_notes:
            assert note.split(":", 1)[0] in row.notes.split(", ") and ", twin:" in note.split(";")[0], note


def _summary(tr, ts, **alternatives):
    """A settled run's summary at the given rise and settling times, read in the 2 % band, peak 1 V of a 9 V room."""
    s = {"TR": tr, "TS": ts, "TR edge": tr, "TR first": tr, "TS narrow": ts, "TS wide": ts, "TS first": ts}
    s.update(band=NARROW_BAND, limit=9.0, peak=1.0, step=0.4, saturated=0.0, wander=1e-3, **alternatives)
    return s


def test_table_6_1_notes_exactly_the_cells_off_the_thesis_on_known_runs():
    at_thesis = {k: CaseResult("settled", _summary(p[0], p[1][0]), None) for k, p in TABLE_6_1.items()}
    twin = dict(at_thesis)
    # 100 % off, 10 % off when timed from the command edge; far off under every definition; a failed run
    twin[(75.0, "SAS")] = CaseResult("settled", _summary(6.0, 12.0, **{"TR edge": 3.3}), None)
    twin[(1.0, "CSAS LPF 0.2 Hz")] = CaseResult("settled", _summary(2.5, 20.0, **{"TS wide": 19.0}), None)
    twin[(1.0, "SAS")] = CaseResult("hit the stops", {}, None)
    rows, notes = lt.rows_6_1(at_thesis, twin)
    assert {k: r.notes for k, r in rows.items() if r.notes} == {
        (75.0, "SAS", "TR"): "note 1",
        (1.0, "SAS", "TR"): "note 2",
        (1.0, "SAS", "TS"): "note 3",
        (1.0, "CSAS LPF 0.2 Hz", "TS"): "note 4",
    }
    assert len(notes) == 4 and all(", twin:" in n.split(";")[0] for n in notes)
    assert notes[0].startswith("note 1: R = 75, SAS, TR, twin: 6 s vs thesis 3 s")
    assert notes[0].endswith("timed from the command edge it is 3.3 s (summarise): explained by that definition.")
    assert notes[1] == "note 2: R = 1, SAS, TR, twin: hit the stops: not explained."  # a status explains nothing
    assert (
        "not explained (the same run at seed 0: in the 5 % band 19 s; first step, from rest (2 % band) 20 s)"
        in (notes[3])
    )
    assert rows[(1.0, "SAS", "TS")].twin == "hit the stops" and rows[(1.0, "SAS", "TS")].twin_notes == (notes[2],)
    assert rows[(75.0, "SAS", "control")].linear == "limit from +-1.8 rad"  # 9 V room / 1 V peak x 0.2 rad
    table = lt.table_6_1(at_thesis, twin)
    assert table.notes[1:] == notes and len(table.notes) == 5
    assert [row[-1] for row in table.rows] == [r.notes for r in rows.values()]
    assert [row[:3] for row in table.rows] == [[r, c, lt.MEASURES_6_1[k]] for r, c, k in rows]


def test_over_seeds_a_definition_explains_a_cell_only_if_it_does_at_every_seed_and_a_planted_split_is_inconclusive():
    from trms.present.seeds import OverSeeds, Seeded

    at_thesis = {k: CaseResult("settled", _summary(p[0], p[1][0]), None) for k, p in TABLE_6_1.items()}
    both = dict(at_thesis)
    both[(75.0, "SAS")] = CaseResult("settled", _summary(6.0, 12.0, **{"TR edge": 3.3}), None)
    one = dict(at_thesis)
    one[(75.0, "SAS")] = CaseResult("settled", _summary(6.0, 12.0), None)  # the edge-timed rise is 6 s here too
    split = dict(at_thesis)
    split[(75.0, "SAS")] = CaseResult("settled", _summary(3.2, 12.0), None)  # agrees at this seed
    rows, notes = lt.rows_6_1(at_thesis, Seeded((0, 1000), (both, one)))
    assert rows[(75.0, "SAS", "TR")].twin == OverSeeds((6.0, 6.0), (0, 1000))
    assert "not explained" in notes[0] and "explained by" not in notes[0]  # the edge timing holds at one seed only
    rows, notes = lt.rows_6_1(at_thesis, Seeded((0, 1000), (both, both)))
    assert notes[0].endswith("3.3 (3.3-3.3; 2 seeds) s at every seed (summarise): explained by that definition.")
    rows, notes = lt.rows_6_1(at_thesis, Seeded((0, 1000), (both, split)))
    assert notes[0].endswith("within 30% at 1 of 2 seeds: inconclusive at 2 seeds.")


def test_the_linear_model_reproduces_table_6_1_within_30_percent_or_explains_it(built):
    # the linear world is eq. (3.11), the thesis's own simulation: each time cell is within 30 % of the
    # thesis, or its note names the definition that brings it there, or it says "not explained"
    sec, (lin, *_rest), _ = built
    notes = [n for n in sec.tables[0].notes if ", linear model:" in n and "s vs thesis" in n]
    unexplained = [n for n in notes if "not explained" in n]
    assert len(unexplained) <= 1, unexplained  # tolerance: at most one of the 16 linear time cells


def test_thesis_trends_hold_on_the_linear_model(ch67_results):
    lin = ch67_results[0]
    for r in (75.0, 1.0, 125.0):
        sas, lpf2 = lin[(r, "SAS")].summary, lin[(r, "CSAS LPF 0.2 Hz")].summary
        assert lpf2["peak"] < sas["peak"] and lpf2["TV"] < sas["TV"] and lpf2["overshoot"] < sas["overshoot"]
    assert lin[(1.0, "SAS")].summary["TR"] < min(lin[(r, "SAS")].summary["TR"] for r in (75.0, 125.0))
    assert lin[(1.0, "SAS")].summary["peak"] > 5 * lin[(75.0, "SAS")].summary["peak"]


def test_margins_table_covers_every_loop_and_explains_r1(built):
    sec, (*_r, weights, margins), _ = built
    tm = sec.tables[3]
    assert len(tm.rows) == 2 * len(weights)
    r1 = next(row for row in tm.rows if row[0] == 1.0 and row[1].startswith("linear"))
    assert r1[-1] == "unstable" and r1[3] < 30.0  # eq. (3.11): R = 1 fails with one sample of delay


def test_findings_the_report_claims_hold(built):
    # the findings the twin shows (ch. 7): R = 1 fails, R = 125 is the best SAS, every push is rejected
    sec, *_ = built
    tf = sec.tables[4]
    rows = {row[0]: row for row in tf.rows}
    assert len(rows) == 7
    for finding in ("R = 1 SAS unstable on the rig", "R = 125 SAS best", "push rejected by all three controllers"):
        assert rows[finding][3] == "shown", rows[finding]
    # and on eq. (3.11) the R = 1 loop fails by its delay margin, not by its run
    assert rows["R = 1 SAS unstable on the rig"][2] == "shown"
    assert all(row[1] for row in tf.rows)  # every finding states its criterion


def test_findings_follow_their_criterion(ch67_results):
    lin, twin, push, _, margins = ch67_results
    f = {x.name: x for x in cf.findings(twin, push, margins["twin"])}
    over = {r: twin[(r, "SAS")].summary["overshoot"] for r in (75.0, 125.0) if twin[(r, "SAS")].summary}
    assert f["R = 125 SAS best"].shown == (min(over, key=over.get) == 125.0)
    assert f["push rejected by all three controllers"].shown == all(p.status == "recovered" for p in push.values())
    assert not cf.findings(lin, None, margins["linear"])[-1].shown  # no torque input: never claimed


def test_section_figures_are_written(built):
    # known from the inputs: a response figure per (R, case) the section draws whose runs on both worlds have a
    # record, and the push figure when any push run has one; each a PNG on disk with content and a caption
    sec, (lin, twin, push, *_), _ = built
    drawn = [(125.0, "SAS"), (125.0, "CSAS LPF 0.2 Hz"), (75.0, "SAS"), (1.0, "SAS")]
    expected = [
        f"ch67_R{r:g}_{case.lower().replace(' ', '_').replace('.', 'p')}.png"
        for r, case in drawn
        if (r, case) in twin and lin[(r, case)].record is not None and twin[(r, case)].record is not None
    ]
    expected += ["ch7_push_twin.png"] if any(p.record is not None for p in push.values()) else []
    assert len(expected) >= 2  # the fixture's runs have records: the check below is not vacuous
    assert [f.path.name for f in sec.figures] == expected
    for f in sec.figures:
        with open(f.path, "rb") as fh:
            assert fh.read(8) == b"\x89PNG\r\n\x1a\n", f.path
        assert f.path.stat().st_size > 1000 and f.caption, f.path
    assert sec.conclusion[0].startswith(f"The twin shows {sum(r[3] == 'shown' for r in sec.tables[4].rows)} of 7")


def _explained_by_measurement(why: str) -> bool:
    """The explanation ends in the verdict "explained" or "explained in part" (not "not explained") and quotes a
    measured number."""
    return bool(re.search(r"(^|[:.] )explained\b", why)) and "not explained" not in why and bool(re.search(r"\d", why))


def test_the_explanation_check_tells_explained_from_not_explained():
    assert _explained_by_measurement("peak 0.3 of the limit: explained by the command amplitude.")
    assert _explained_by_measurement("at 0.25 Hz ... mode's). explained: the finding needs the 0.25 Hz mode.")
    assert not _explained_by_measurement("the overshoot is 4.0 %: not explained by the command amplitude.")
    assert not _explained_by_measurement("no torque input: not explained.")
    assert not _explained_by_measurement("explained by the command amplitude.")  # no measured number
    assert not _explained_by_measurement("-")


def test_a_missing_finding_carries_its_measured_explanation(built, side_mode_evidence):
    sec, (lin, twin, push, _, margins), chapter = built
    tf = sec.tables[4]
    why = tf.columns.index("why the twin does not show it (measured in this run)")
    typed = chapter.findings["twin"]
    typed = typed.first  # one seed here
    assert [row[0] for row in tf.rows] == [f.name for f in typed] and len(typed) == 7
    for row, f in zip(tf.rows, typed):
        assert row[3] == ("shown" if f.shown else "not shown"), row
        if f.shown:
            assert row[why] == "-" and not f.explanation, row
        else:
            # a finding the twin does not show is explained, whole or in part, by a measurement of this run (with
            # its number); "not explained" would be a miss the report admits, which this test does not tolerate
            assert row[why] == f.explanation and (f.explained or f.partly), row
            assert _explained_by_measurement(row[why]), row
    # the low-pass explanation reports each plant by the finding's own criterion
    rig = [r for r in (75.0, 100.0, 125.0) if (r, "SAS") in twin]
    f = {x.name: x for x in cf.findings(twin, push, margins["twin"], side_mode_evidence)}[
        "LPF 0.3 Hz worse than LPF 0.2 Hz"
    ]
    if not f.shown:
        for name in side_mode_evidence.results:
            shown = cf._lpf_worse(side_mode_evidence.results[name], rig)[0]
            assert f"on {name} (" in f.explanation
            assert (
                f.explanation.split(f"on {name} (", 1)[1]
                .split("): ", 1)[1]
                .startswith("shown" if shown else "not shown")
            )


def test_table_6_1_control_is_a_sensitivity_to_the_limit_and_the_estimator():
    """Read at the PCI set-up's +-2.5 V a loop meets the limit at a smaller command than at +-10 V, in the ratio of
    their rooms about the trim; a faster estimator asks more control per radian of command than a slower one."""
    from trms.experiments.ch67_lqg import ESTIMATOR_SPEEDS, PCI_LIMIT, lqg_cases, pitch_plant

    trim = 0.5
    plant = pitch_plant(trim=trim)
    runs = {k: lqg_cases(plant, plant.system, [75.0], ["SAS"], estimator=k) for k in (1.0, *ESTIMATOR_SPEEDS)}
    table = lt.table_6_1_control({"linear": runs}, trim)
    row = dict(zip(table.columns, next(r for r in table.rows if r[:2] == [75.0, "SAS"])))
    wide, narrow = row["+-10 V from (rad)"], row[f"+-{PCI_LIMIT:g} V from (rad)"]
    assert narrow < wide and narrow / wide == pytest.approx((PCI_LIMIT - trim) / (10.0 - trim), rel=1e-9)
    slow, fast = (row[f"V/rad, Qe x{k:g}"] for k in sorted(ESTIMATOR_SPEEDS))
    assert fast > row["V/rad, Qe x1"] > slow > 0
    assert row["thesis"] == TABLE_6_1[(75.0, "SAS")][2]
