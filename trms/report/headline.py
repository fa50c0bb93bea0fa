"""The report's headline: one row per chapter's key figure, with the twin's verdict against the thesis.

:func:`headline` reads each figure from the chapter sections' rows as data: chapters 6 and 7 from the typed rows
of :class:`~trms.experiments.ch67_chapter.Chapter67`, the other chapters from their tables' rows found by the
values of their key columns. A twin cell is measured at every seed of the run, and :func:`numeric_verdict` judges it
over them (:func:`trms.present.seeds.verdict`): it agrees only when it agrees at every seed, differs only when it
differs at every seed, and is otherwise "inconclusive at N seeds"; a cell that differs is "explained" only when every
note on it gives an explanation computed in the run whose own check passed, "explained in part" when one of them is
partial. :func:`reader_summary` turns the verdicts into a few lines for a reader in a hurry.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping

import numpy as np

from trms.calibration import Verification
from trms.errors import InputError
from trms.experiments.ch7_findings import Finding, shown_at, why_missing
from trms.experiments.ch67_lqg import RECOVERY_BAND
from trms.experiments.ch67_tables import TABLE_6_1_NAME, Compared, stability
from trms.measurement.protocol import THESIS_PROTOCOLS
from trms.present.sections import Section
from trms.present.seeds import AGREES, DIFFERS, OverSeeds, Seeded, inconclusive, seeded, verdict
from trms.present.tables import EXPLAIN_ABOVE, SOURCE, ComparisonTable, side_by_side
from trms.reference import PRINTED, TABLE_5_1
from trms.report.results import Chapters

__all__ = [
    "VERDICT",
    "AGREES",
    "EXPLAINED",
    "PARTLY",
    "DIFFERS",
    "NOTHING",
    "numeric_verdict",
    "reader_summary",
    "agreement",
    "compared_row",
    "headline",
]

#: The headline's verdict column, and its values beside :data:`AGREES`, :data:`DIFFERS` and "inconclusive at N seeds":
#: differing at every seed with every note on the cell explained by a checked measurement of the run, with one of them
#: explained in part, or nothing printed to compare with.
VERDICT = "twin vs thesis"
EXPLAINED, PARTLY, NOTHING = "differs (explained)", "differs (explained in part)", "-"


def _explanation(notes: list[str]) -> str:
    """What the notes on a differing cell say: :data:`EXPLAINED`, :data:`PARTLY` or :data:`DIFFERS`."""
    if not notes or any("not explained" in n or "inconclusive at" in n for n in notes):
        return DIFFERS
    if any("explained in part" in n for n in notes):
        return PARTLY
    return EXPLAINED if all("explained" in n for n in notes) else DIFFERS


def numeric_verdict(thesis: object, twin: object, notes: list[str]) -> str:
    """The headline verdict of a twin cell against the thesis's, given the notes the cell points at.

    The cell (at one seed, or :class:`~trms.present.seeds.OverSeeds`) is judged at each seed
    (:func:`~trms.present.seeds.verdict`: a number or range within 30 %, each printed mode found, "rejected" by a
    recovery time); one that differs at every seed is "explained" only when every note on it ends explained (by a
    measurement whose check passed) and none says "not explained", "explained in part" or "inconclusive".

    Examples
    --------
    >>> numeric_verdict(7.0, 34.2, ["note 3: ...; explained by the filter's gain bound."])
    'differs (explained)'
    >>> numeric_verdict(3.0, 3.4, []), numeric_verdict(7.0, 34.2, ["note 3: ...; explained in part."])
    ('agrees', 'differs (explained in part)')
    >>> numeric_verdict((5.0, 6.0), "hit the stops", ["note 6: ... not explained."])
    'differs'
    >>> numeric_verdict(6.42e-6, OverSeeds((7.86e-6, 1.66e-5, 1.1e-5), (0, 1, 3)), [])
    'inconclusive at 3 seeds'
    >>> numeric_verdict("0.1, 0.34", "0.10, 0.33, 0.87", []), numeric_verdict("0.1", "0.25", [])
    ('agrees', 'differs')
    """
    judged = verdict(thesis, twin)
    if judged is None:
        return NOTHING
    return _explanation(notes) if judged == DIFFERS else judged


def reader_summary(table: ComparisonTable) -> list[str]:
    """A few lines for a reader in a hurry, computed from the headline's verdicts: where the twin agrees with
    the thesis at every seed, where it differs for a measured reason, where it differs unexplained, and where the
    seeds disagree.

    Examples
    --------
    >>> t = side_by_side("H", ["chapter", "quantity"])
    >>> t.columns.insert(t.columns.index("notes"), VERDICT)
    >>> t.rows = [["3", "mode (Hz)", 0.34, 0.33, 0.33, AGREES, ""], ["4", "LPF (dB)", 7, 31, 34, EXPLAINED, ""]]
    >>> reader_summary(t)[0]
    'The twin agrees with the thesis (within 30% at every seed) on 1 of its 2 headline figures: mode (Hz) (ch. 3).'
    """
    i = table.columns.index(VERDICT)
    rows = [(f"{r[1]} (ch. {r[0]})", str(r[i])) for r in table.rows if r[i] != NOTHING]
    by = {v: [q for q, w in rows if w == v] for v in (AGREES, EXPLAINED, PARTLY, DIFFERS)}
    unsure = [f"{q}: {w}" for q, w in rows if w.startswith("inconclusive")]
    out = [
        f"The twin agrees with the thesis (within {EXPLAIN_ABOVE:.0%} at every seed) on {len(by[AGREES])} of its "
        f"{len(rows)} headline figures: " + ("; ".join(by[AGREES]) or "none") + "."
    ]
    if by[EXPLAINED]:
        out.append(
            f"It differs at every seed on {len(by[EXPLAINED])}, each explained by a measurement of this run that "
            "passes its check (the notes say which): " + "; ".join(by[EXPLAINED]) + "."
        )
    if by[PARTLY]:
        out.append(f"It differs, explained in part, on {len(by[PARTLY])}: " + "; ".join(by[PARTLY]) + ".")
    if by[DIFFERS]:
        out.append(f"It differs, not explained, on {len(by[DIFFERS])}: " + "; ".join(by[DIFFERS]) + ".")
    if unsure:
        out.append(f"The seeds disagree on {len(unsure)}: " + "; ".join(unsure) + ".")
    return out


def agreement(section: Section) -> list[str]:
    """A conclusion line per table: of the twin cells with a printed thesis value, how many agree at every seed, differ
    at every seed and are inconclusive.

    Examples
    --------
    >>> t = side_by_side("Table 9.9: an example", ["quantity"])
    >>> t.rows = [["a (s)", 3.0, 3.1, 3.2, ""], ["b (s)", 2.0, 2.0, 9.0, "note 1"], ["c", "pass", "pass", "pass", ""]]
    >>> t.notes = ["note 1: b, twin: 9 s vs thesis 2 s; not explained."]
    >>> for part in agreement(Section("S", tables=[t]))[0].split(", "):
    ...     print(part)
    Table 9.9: of the 2 cells with a printed value the twin agrees with 1 (within 30% at every seed)
    differs from 1 at every seed
    is inconclusive on 0; 1 notes say 'not explained'.
    """
    out = []
    for t in section.tables:
        if not {"thesis", "twin"} <= set(t.columns):
            continue
        i, j = t.columns.index("thesis"), t.columns.index("twin")
        judged = [
            v
            for row in t.rows
            if isinstance(row[i], (int, float, tuple)) and not isinstance(row[i], bool)
            for v in [verdict(row[i], row[j])]
            if v is not None
        ]
        if not judged:
            continue
        unexplained = sum("not explained" in n for n in t.notes)
        out.append(
            f"{t.title.split(':')[0]}: of the {len(judged)} cells with a printed value the twin agrees with "
            f"{judged.count(AGREES)} (within {EXPLAIN_ABOVE:.0%} at every seed), differs from {judged.count(DIFFERS)} "
            f"at every seed, is inconclusive on {sum(v.startswith('inconclusive') for v in judged)}; {unexplained} "
            "notes say 'not explained'."
        )
    return out


def compared_row(table: ComparisonTable, key: Mapping[str, object | Callable[[object], bool]]) -> Compared:
    """The row of a side-by-side table whose key columns hold ``key``'s values (or pass its tests), as data.

    Parameters
    ----------
    table : ComparisonTable
        With the columns ``thesis``, ``linear model``, ``twin`` and ``notes``.
    key : mapping
        Column name -> the value the row holds there, or a test of that cell.

    Returns
    -------
    Compared
        The row's cells, its notes cell, and the notes it cites on the twin's cell (every cited note that is not
        the linear model's).

    Examples
    --------
    >>> t = side_by_side("T", ["quantity"])
    >>> t.rows = [["a", 1.0, 1.1, 2.0, "note 1, note 2"]]
    >>> t.notes = ["note 1: a, linear model: close.", "note 2: a, twin: 2.0 vs 1.0; not explained."]
    >>> compared_row(t, {"quantity": "a"}).twin_notes
    ('note 2: a, twin: 2.0 vs 1.0; not explained.',)
    >>> compared_row(t, {"quantity": lambda q: str(q).startswith("b")})
    Traceback (most recent call last):
    trms.errors.InputError: no row of 'T' has quantity = <test>
    """
    cols = table.columns

    def holds(row: list[object]) -> bool:
        return all(
            want(row[cols.index(c)]) if callable(want) else row[cols.index(c)] == want for c, want in key.items()
        )

    row = next((r for r in table.rows if holds(r)), None)
    if row is None:
        wanted = ", ".join(f"{c} = {'<test>' if callable(w) else repr(w)}" for c, w in key.items())
        raise InputError(f"no row of {table.title!r} has {wanted}")
    ref = str(row[cols.index("notes")])
    cited = [n for n in table.notes if any(n.startswith(f"{r}:") for r in re.findall(r"note \d+", ref))]
    own = tuple(n for n in cited if ", linear model:" not in n.split(";")[0])  # the twin's notes, and shared ones
    source = str(row[cols.index(SOURCE)]) if SOURCE in cols else PRINTED
    return Compared(
        row[cols.index("thesis")], row[cols.index("linear model")], row[cols.index("twin")], ref, own, source
    )


def _table(section: Section, name: str) -> ComparisonTable:
    """The section's table whose title starts with ``name``."""
    found = next((t for t in section.tables if t.title.startswith(name)), None)
    if found is None:
        raise InputError(f"the section {section.title!r} has no table {name!r}")
    return found


def _gain_note(twin: object, calibration: Verification | None) -> str:
    """The DC gain row's note: where the twin's cell comes from, and the calibration's figure of the same quantity by
    its own protocol (a different record: 10 Hz decimated to 0.2 s), each with its range."""
    p = THESIS_PROTOCOLS[0]
    here = (
        f"ch. 3's protocol: a {p.bandwidth_hz:g} Hz PRBS of {p.amplitude_v:g} V for {p.duration_s:g} s recorded at "
        "Ts = 0.2 s, one 4th-order ARMAX per run"
        + (f", at {len(twin.values)} seeds" if isinstance(twin, OverSeeds) else "")
    )
    checks = [c for c in (calibration.checks if calibration else []) if c.name == "1dof ARMAX DC gain"]
    runs = [g for c in checks for g in c.runs]
    if not runs:
        return here + "."
    gains = [c.achieved for c in checks]
    return (
        f"{here}; the calibration's 1-DOF check (the same PRBS recorded at {1 / p.sample_time:g} Hz and decimated to "
        f"0.2 s, {len(runs)} runs at its {len(gains)} unseen seeds): single runs {min(runs):.3g}-{max(runs):.3g}, "
        f"each seed's median {min(gains):.3g}-{max(gains):.3g}, median {float(np.median(gains)):.3g}"
    )


def headline(chapters: Chapters, calibration: Verification | None = None) -> ComparisonTable:
    """The headline comparison, one row per chapter's key figure, read from the chapters' rows.

    Parameters
    ----------
    chapters : Chapters
        The report's chapter sections.
    calibration : Verification, optional
        The shipped model's verification (:func:`trms.calibration.verify`): adds, beside the twin's ARMAX DC gain,
        the calibration's figure of it by its own protocol.

    Returns
    -------
    ComparisonTable
        Columns chapter, quantity, thesis, source, linear model, twin, :data:`VERDICT`, notes.
    """
    t = side_by_side("Headline: the thesis, the linear model and the twin", ["chapter", "quantity"], sources=True)
    t.columns.insert(t.columns.index("notes"), VERDICT)

    def add(chapter: str, label: str, c: Compared, verdict_: str, note: str) -> None:
        t.rows.append([chapter, label, c.thesis, c.source, c.linear, c.twin, verdict_, note])

    def row(chapter: str, label: str, c: Compared, table: str, note: str = "") -> None:
        ref = f"{c.notes} ({table})" if "note " in c.notes else c.notes
        add(chapter, label, c, numeric_verdict(c.thesis, c.twin, list(c.twin_notes)), note or ref)

    def table_row(chapter: str, label: str, table: ComparisonTable, key: dict, note: str = "") -> None:
        row(chapter, label, compared_row(table, key), table.title.split(":")[0], note)

    c3a, c3b = _table(chapters.ch3, "Ch. 3, 1-DOF"), _table(chapters.ch3, "Table 3.1")
    table_row("3", "1-DOF pitch PSD main mode (Hz)", c3a, {"quantity": "pitch PSD main mode (Hz)"})
    gain = compared_row(c3a, {"quantity": "ARMAX DC gain (rad/V)"})
    ref = f"; {gain.notes} (Ch. 3, 1-DOF identification)" if "note " in gain.notes else ""
    row("3", "1-DOF ARMAX DC gain (rad/V)", gain, "", _gain_note(gain.twin, calibration) + ref)
    table_row(
        "3",
        "2-DOF u2 -> yaw modes (Hz), confirmed by the identified model",
        c3b,
        {"channel": "u2->y2", "quantity": "PSD modes (Hz)"},
    )
    c42, c43 = _table(chapters.ch4, "Table 4.2"), _table(chapters.ch4, "Table 4.3")
    table_row("4", "Table 4.2: LPF 0.1 Hz at 0.34 Hz (dB)", c42, {"command": "LPF 0.1 Hz", "mode (Hz)": 0.34})
    table_row("4", "Table 4.3: u2 -> y2, Filter-3 at 0.1 Hz (dB)", c43, {"channel": "u2->y2", "filter": "Filter-3"})
    c51 = _table(chapters.ch5, "Table 5.1")
    for key in TABLE_5_1:
        suffix = f"{key} (rad^2)"
        table_row(
            "5",
            f"Table 5.1: residual variance, {suffix}",
            c51,
            {"quantity": lambda q, end=suffix: str(q).endswith(end)},
        )
    ch67 = chapters.ch67
    row("6", "Table 6.1: R = 75 SAS rise time (s)", ch67.table_6_1[(75.0, "SAS", "TR")], TABLE_6_1_NAME)
    row("6", "Table 6.1: R = 1 SAS settling (s)", ch67.table_6_1[(1.0, "SAS", "TS")], TABLE_6_1_NAME)
    row(
        "6",
        "Table 6.1: R = 75 CSAS LPF 0.2 Hz settling (s)",
        ch67.table_6_1[(75.0, "CSAS LPF 0.2 Hz", "TS")],
        TABLE_6_1_NAME,
    )
    lin_m, twin_m = (
        f"{m.phase_margin_deg:.0f}; {stability(m.stable_with_delay)}"
        for m in (ch67.margins["linear"][1.0], ch67.margins["twin"][1.0])
    )
    add(
        "7",
        "R = 1: phase margin at the plant input (deg); with one sample of delay",
        Compared("unstable on the rig", lin_m, twin_m),
        AGREES if twin_m.endswith(f"; {stability(False)}") else DIFFERS,
        "the loop on each world's linear model (no seed: a linearisation); see the margins table",
    )
    add("7", "ch. 7 findings shown", *_findings_row(ch67.findings))
    c_push = ch67.push[125.0]
    row("7", f"push: back within {RECOVERY_BAND:g} rad after (s), R = 125", c_push, "Ch. 7.4")
    autopilot = _table(chapters.ch8, "Ch. 8 future work")
    for controller in ("MIMO LQG", "two SISO loops"):
        table_row(
            "8",
            f"pitch command: yaw excursion (rad), {controller}",
            autopilot,
            {
                "scenario": "pitch step",
                "controller": controller,
                "measure": lambda m: str(m).startswith("other axis"),
            },
        )
    if any(t.title.startswith("Robustness") for t in chapters.ch8.tables):
        table_row(
            "8",
            "robustness: 1-DOF CSAS R = 125 success",
            _table(chapters.ch8, "Robustness"),
            {"loop": lambda loop: str(loop).startswith("1-DOF"), "measure": "success rate"},
        )
    for r in t.rows:  # the ch. 8 rows print no thesis value: no source
        if r[2] in ("-", NOTHING) and r[0] == "8":
            r[3] = "-"
    return t


def _findings_row(found: Mapping[str, list[Finding] | Seeded[list[Finding]]]) -> tuple[Compared, str, str]:
    """The findings' headline row: how many each world shows (the twin at each seed), its verdict and note."""
    lin, tw = seeded(found["linear"]).first, seeded(found["twin"])
    counts = shown_at(tw)
    total = len(tw.first)
    per_seed = [sum(f.shown for f in r) for r in tw.results]
    cell = tw.cell(lambda r: sum(f.shown for f in r))
    c = Compared(f"{total} findings", f"{sum(f.shown for f in lin)}", cell)
    if all(k == total for k in per_seed):
        return c, AGREES, "see the ch. 7 findings table"
    if not all(k < total for k in per_seed):  # every finding shown at some seeds, not at others
        return c, inconclusive(len(per_seed)), "see the ch. 7 findings table"
    # every finding the twin misses at some seed, with its explanation (the run's own evidence) where it misses it
    notes = [why for (k, n), (_, why) in zip(counts, why_missing(tw)) if k < n]
    return c, _explanation(notes), "see the ch. 7 findings table"
