"""The headline: verdicts from a cell and the notes it points at, rows read as data, on tables whose answer is known."""

import pytest

from trms.errors import InputError
from trms.experiments.ch7_findings import Finding
from trms.experiments.ch67_lqg import Margins
from trms.experiments.ch67_tables import Chapter67, Compared
from trms.present.sections import Section
from trms.present.tables import ComparisonTable, side_by_side
from trms.reference import TABLE_5_1
from trms.report import AGREES, DIFFERS, EXPLAINED, NOTHING, VERDICT, Chapters, headline, numeric_verdict
from trms.report.headline import agreement, compared_row, reader_summary


def test_numeric_verdicts_on_known_cells():
    assert numeric_verdict(3.0, 3.4, []) == AGREES  # 13 % off
    assert numeric_verdict((5.0, 6.0), 5.5, []) == AGREES  # inside the printed range
    assert numeric_verdict(3.0, 9.0, ["note 1: R = 75, twin: ...; explained by that definition."]) == EXPLAINED
    assert numeric_verdict(3.0, 9.0, ["note 1: ...; not explained (the same run ...)."]) == DIFFERS
    assert numeric_verdict(3.0, 9.0, []) == DIFFERS  # far off and no note: never "explained"
    assert numeric_verdict((5.0, 6.0), "hit the stops", ["note 6: the run hit the stops."]) == EXPLAINED
    assert numeric_verdict("0.1, 0.34", "0.10, 0.33, 0.87", []) == AGREES  # each printed mode found
    assert numeric_verdict("0.1, 0.34", "0.10", []) == DIFFERS
    assert numeric_verdict("rejected", 11.2, []) == AGREES and numeric_verdict("rejected", "diverged", []) == DIFFERS
    assert numeric_verdict("-", 0.6, []) == NOTHING and numeric_verdict(True, 1.0, []) == NOTHING


def _table(title, keys, rows, notes=()):
    t = side_by_side(title, keys)
    t.rows, t.notes = [list(r) for r in rows], list(notes)
    return t


def test_a_row_is_found_by_its_key_columns_and_carries_only_the_twins_cited_notes():
    t = _table(
        "Table 9: x",
        ["channel", "quantity"],
        [["u1", "gain", 1.0, 1.0, 1.0, ""], ["u2", "gain", 2.0, 3.0, 4.0, "note 1, note 3"]],
        [
            "general",
            "note 1: u2 gain, linear model: 3 vs 2.",
            "note 2: other.",
            "note 3: u2 gain, twin: 4; not explained.",
        ],
    )
    row = compared_row(t, {"channel": "u2", "quantity": lambda q: str(q).startswith("ga")})
    assert (row.thesis, row.linear, row.twin, row.notes) == (2.0, 3.0, 4.0, "note 1, note 3")
    assert row.twin_notes == ("note 3: u2 gain, twin: 4; not explained.",)
    with pytest.raises(InputError, match=r"no row of 'Table 9: x' has channel = 'u3'"):
        compared_row(t, {"channel": "u3"})


def _chapters(r1_twin_margins_stable_with_delay=False, missed_explanations=("x = 1: explained by x.",)):
    """Minimal chapters holding every row the headline reads, with known cells."""
    ch3 = Section(
        "ch3",
        tables=[
            _table("Ch. 3, 1-DOF identification", ["quantity"], [["pitch PSD main mode (Hz)", 0.34, 0.33, 0.5, ""]]),
            _table(
                "Table 3.1 / 4.1", ["channel", "quantity"], [["u2->y2", "PSD modes (Hz)", "0.1", "0.10", "0.1", ""]]
            ),
        ],
    )
    ch3.tables[0].rows.append(["ARMAX DC gain (rad/V)", 1.51, 1.5, 2.5, "note 1"])
    ch3.tables[0].notes = ["note 1: ARMAX DC gain, linear model: recovers eq. (3.11)."]
    ch4 = Section(
        "ch4",
        tables=[
            _table(
                "Table 4.2 (1-DOF): a",
                ["command", "mode (Hz)"],
                [["LPF 0.1 Hz", 0.25, 1.0, 1.0, 1.0, ""], ["LPF 0.1 Hz", 0.34, 7.0, 31.0, 34.0, "note 2"]],
                ["note 1: other.", "note 2: LPF 0.1 Hz at 0.34 Hz, twin: 34 dB; explained by an ambient floor."],
            ),
            _table(
                "Table 4.3 (2-DOF): b",
                ["channel", "mode (Hz)", "filter"],
                [["u2->y2", 0.1, "Filter-3", 18.6, 18.8, 17.1, ""]],
            ),
        ],
    )
    ch5 = Section(
        "ch5",
        tables=[
            _table(
                "Table 5.1 and ch. 5 (1-DOF): c",
                ["quantity"],
                [[f"variance of residuals, {k} (rad^2)", v, v, v, ""] for k, v in TABLE_5_1.items()],
            )
        ],
    )
    ch8 = Section(
        "ch8",
        tables=[
            _table(
                "Ch. 8 future work: d",
                ["scenario", "controller", "measure"],
                [
                    ["pitch step", c, "other axis' largest excursion (rad)", "-", 0.6, 0.5, ""]
                    for c in ("MIMO LQG", "two SISO loops")
                ],
            ),
            _table(
                "Robustness: e",
                ["loop", "measure"],
                [["1-DOF CSAS R = 125, LPF 0.2 Hz", "success rate", "-", "settled", "4/4", ""]],
            ),
        ],
    )
    t61 = {
        (75.0, "SAS", "TR"): Compared(3.0, 2.5, 3.5),
        (1.0, "SAS", "TS"): Compared(
            (5.0, 6.0), 5.4, "hit the stops", "note 6", ("note 6: R = 1, twin: the run hit the stops.",)
        ),
        (75.0, "CSAS LPF 0.2 Hz", "TS"): Compared(
            (7.0, 8.0), 6.6, 20.0, "note 3", ("note 3: ...; not explained (...).",)
        ),
    }
    margins = {
        "linear": {1.0: Margins(6.0, 24.4, 0.1, True, False)},
        "twin": {1.0: Margins(3.0, -11.0, -0.1, False, r1_twin_margins_stable_with_delay)},
    }
    shown = Finding("a", "c", True, "m")
    missed = [Finding("b", "c", False, "m", why) for why in missed_explanations]
    findings = {"linear": [shown, shown, missed[0]], "twin": [shown, *missed]}
    ch67 = Chapter67(Section("ch67"), t61, {125.0: Compared("rejected", "-", 11.2)}, margins, findings)
    return Chapters(ch3, ch4, ch5, ch67, ch8)


def test_the_headline_reads_every_row_as_data_with_known_verdicts():
    t = headline(_chapters())
    assert t.columns == ["chapter", "quantity", "thesis", "linear model", "twin", VERDICT, "notes"]
    rows = {r[1]: r for r in t.rows}
    assert len(rows) == len(t.rows) == 16
    assert rows["1-DOF pitch PSD main mode (Hz)"][2:6] == [0.34, 0.33, 0.5, DIFFERS]  # 47 % off, no note
    # 66 % off with only the linear model's note: not explained; no calibration given, so the cited note
    assert rows["1-DOF ARMAX DC gain (rad/V)"][5:] == [DIFFERS, "note 1 (Ch. 3, 1-DOF identification)"]
    assert rows["Table 4.2: LPF 0.1 Hz at 0.34 Hz (dB)"][5:] == [EXPLAINED, "note 2 (Table 4.2 (1-DOF))"]
    assert rows["Table 6.1: R = 1 SAS settling (s)"][4:] == ["hit the stops", EXPLAINED, "note 6 (Table 6.1)"]
    assert rows["Table 6.1: R = 75 CSAS LPF 0.2 Hz settling (s)"][5] == DIFFERS  # its twin note says not explained
    assert rows["R = 1: phase margin at the plant input (deg); with one sample of delay"][3:6] == [
        "24; unstable",
        "-11; unstable",
        AGREES,
    ]
    assert rows["ch. 7 findings shown"][2:6] == ["2 findings", "2", "1", EXPLAINED]
    assert rows["push: back within 0.02 rad after (s), R = 125"][4:] == [11.2, AGREES, ""]
    assert rows["robustness: 1-DOF CSAS R = 125 success"][3:5] == ["settled", "4/4"]


def test_the_headline_verdicts_follow_the_typed_results():
    t = headline(_chapters(r1_twin_margins_stable_with_delay=True, missed_explanations=("m: not explained.", "")))
    rows = {r[1]: r for r in t.rows}
    assert rows["R = 1: phase margin at the plant input (deg); with one sample of delay"][4:6] == [
        "-11; stable",
        DIFFERS,
    ]
    assert rows["ch. 7 findings shown"][2:6] == ["3 findings", "2", "1", DIFFERS]
    # a missed finding without any explanation is not explained either
    assert headline(_chapters(missed_explanations=("",))).rows[11][5] == DIFFERS


def test_reader_summary_counts_the_verdicts():
    t = headline(_chapters())
    lines = reader_summary(t)
    agrees = [r for r in t.rows if r[5] == AGREES]
    assert lines[0].startswith(f"The twin agrees with the thesis (within 30%) on {len(agrees)} of ")
    assert any(line.startswith("It differs on 3, each explained") for line in lines)
    assert len(agrees) == 7 and lines[-1].startswith("It differs, not explained, on 3: 1-DOF pitch PSD main mode")


def test_agreement_counts_printed_cells_within_30_percent():
    t = _table("Table 9: x", ["quantity"], [["a", 3.0, 3.0, 3.5, ""], ["b", (5.0, 6.0), 5.0, 9.0, "note 1"]])
    t.notes = ["note 1: b, twin: 9; not explained."]
    other = ComparisonTable("no thesis column", ["a", "b"], [[1, 2]])
    assert agreement(Section("s", tables=[t, other])) == [
        "Table 9: the twin is within 30% of the thesis in 1 of 2 printed cells; 1 are not, each with its note "
        "(1 notes say 'not explained')."
    ]
