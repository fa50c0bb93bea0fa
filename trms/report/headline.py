"""The report's headline: one row per chapter's key figure, with the twin's verdict against the thesis.

:func:`headline` reads each figure from the chapter sections' rows as data: chapters 6 and 7 from the typed rows
of :class:`~trms.experiments.ch67_tables.Chapter67`, the other chapters from their tables' rows found by the
values of their key columns. :func:`numeric_verdict` judges a twin cell from the notes it points at, and
:func:`reader_summary` turns the verdicts into a few lines for a reader in a hurry.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping

import numpy as np

from trms.calibration import Verification
from trms.errors import InputError
from trms.experiments.ch67_lqg import RECOVERY_BAND
from trms.experiments.ch67_tables import TABLE_6_1_NAME, Compared, stability
from trms.present.sections import Section
from trms.present.tables import EXPLAIN_ABOVE, ComparisonTable, relative_difference, side_by_side
from trms.reference import TABLE_5_1
from trms.report.results import Chapters

__all__ = [
    "VERDICT",
    "AGREES",
    "EXPLAINED",
    "DIFFERS",
    "NOTHING",
    "numeric_verdict",
    "reader_summary",
    "agreement",
    "compared_row",
    "headline",
]

#: The headline's verdict column, and its values: the twin within :data:`EXPLAIN_ABOVE` of a printed thesis
#: value (inside a printed range), off by more with every note on it explained by a measurement of the run, off
#: with a note that says "not explained", or nothing printed to compare with.
VERDICT = "twin vs thesis"
AGREES, EXPLAINED, DIFFERS, NOTHING = "agrees", "differs (explained)", "differs", "-"


def numeric_verdict(thesis: object, twin: object, notes: list[str]) -> str:
    """The headline verdict of a twin cell against the thesis's, given the notes the cell points at.

    A printed number or range is compared with :func:`relative_difference`; a status the thesis prints (a
    word) agrees when the twin's cell is the same word or, for "rejected"/"unstable", a run that shows it.

    Examples
    --------
    >>> numeric_verdict(7.0, 34.2, ["note 3: ... explained by an ambient floor"]), numeric_verdict(3.0, 3.4, [])
    ('differs (explained)', 'agrees')
    >>> numeric_verdict((5.0, 6.0), "hit the stops", ["note 6: ... not explained."])
    'differs'
    >>> numeric_verdict("0.1, 0.34", "0.10, 0.33, 0.87", []), numeric_verdict("0.1", "0.25", [])
    ('agrees', 'differs')
    """
    modes = _numbers(thesis), _numbers(twin)
    if all(modes) and isinstance(thesis, str):  # lists of modes (Hz): each printed one found within 30 %
        found = all(any(relative_difference(t, m) <= EXPLAIN_ABOVE for t in modes[1]) for m in modes[0])
        return AGREES if found else (EXPLAINED if notes and not any("not explained" in n for n in notes) else DIFFERS)
    if isinstance(thesis, (int, float, tuple)) and not isinstance(thesis, bool):
        if isinstance(twin, (int, float)) and not isinstance(twin, bool):
            if relative_difference(float(twin), thesis) <= EXPLAIN_ABOVE:
                return AGREES
        return EXPLAINED if notes and not any("not explained" in n for n in notes) else DIFFERS
    if thesis == "rejected":  # the thesis's push: a recovery time on the twin shows it
        return AGREES if isinstance(twin, (int, float)) else DIFFERS
    return NOTHING


def _numbers(cell: object) -> list[float]:
    """The numbers of a cell that lists them ("0.10, 0.34"); empty when it holds anything else."""
    if not isinstance(cell, str):
        return []
    try:
        return [float(x) for x in cell.split(",")]
    except ValueError:
        return []


def reader_summary(table: ComparisonTable) -> list[str]:
    """A few lines for a reader in a hurry, computed from the headline's verdicts: where the twin agrees with
    the thesis, where it differs for a measured reason, and where it differs unexplained.

    Examples
    --------
    >>> t = side_by_side("H", ["chapter", "quantity"])
    >>> t.columns.insert(t.columns.index("notes"), VERDICT)
    >>> t.rows = [["3", "mode (Hz)", 0.34, 0.33, 0.33, AGREES, ""], ["4", "LPF (dB)", 7, 31, 34, EXPLAINED, ""]]
    >>> reader_summary(t)[0]
    'The twin agrees with the thesis (within 30%) on 1 of its 2 headline figures: mode (Hz) (ch. 3).'
    """
    i = table.columns.index(VERDICT)
    by = {v: [f"{r[1]} (ch. {r[0]})" for r in table.rows if r[i] == v] for v in (AGREES, EXPLAINED, DIFFERS)}
    judged = sum(len(v) for v in by.values())
    out = [
        f"The twin agrees with the thesis (within {EXPLAIN_ABOVE:.0%}) on {len(by[AGREES])} of its {judged} headline "
        f"figures: " + ("; ".join(by[AGREES]) or "none") + "."
    ]
    if by[EXPLAINED]:
        out.append(
            f"It differs on {len(by[EXPLAINED])}, each explained by a measurement of this run (the notes say how): "
            + "; ".join(by[EXPLAINED])
            + "."
        )
    if by[DIFFERS]:
        out.append(f"It differs, not explained, on {len(by[DIFFERS])}: " + "; ".join(by[DIFFERS]) + ".")
    return out


def agreement(section: Section) -> list[str]:
    """A conclusion line per table: how many twin cells with a printed thesis value lie within 30 % of it.

    Examples
    --------
    >>> t = side_by_side("Table 9.9: an example", ["quantity"])
    >>> t.rows = [["a (s)", 3.0, 3.1, 3.2, ""], ["b (s)", 2.0, 2.0, 9.0, "note 1"], ["c", "pass", "pass", "pass", ""]]
    >>> t.notes = ["note 1: b, twin: 9 s vs thesis 2 s; not explained."]
    >>> line = agreement(Section("S", tables=[t]))[0]
    >>> line.split(";")[0]
    'Table 9.9: the twin is within 30% of the thesis in 1 of 2 printed cells'
    >>> line.split(";")[1]
    " 1 are not, each with its note (1 notes say 'not explained')."
    """
    out = []
    for t in section.tables:
        if not {"thesis", "twin"} <= set(t.columns):
            continue
        i, j = t.columns.index("thesis"), t.columns.index("twin")
        pairs = [
            (row, row[j]) for row in t.rows if isinstance(row[i], (int, float, tuple)) and not isinstance(row[i], bool)
        ]
        near = [
            r for r, v in pairs if isinstance(v, (int, float)) and relative_difference(float(v), r[i]) <= EXPLAIN_ABOVE
        ]
        far = [r for r, v in pairs if r not in near]
        if not pairs:
            continue
        unexplained = sum("not explained" in n for n in t.notes)
        out.append(
            f"{t.title.split(':')[0]}: the twin is within {EXPLAIN_ABOVE:.0%} of the thesis in {len(near)} of "
            f"{len(pairs)} printed cells"
            + (f"; {len(far)} are not, each with its note ({unexplained} notes say 'not explained')" if far else "")
            + "."
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
    return Compared(row[cols.index("thesis")], row[cols.index("linear model")], row[cols.index("twin")], ref, own)


def _table(section: Section, name: str) -> ComparisonTable:
    """The section's table whose title starts with ``name``."""
    found = next((t for t in section.tables if t.title.startswith(name)), None)
    if found is None:
        raise InputError(f"the section {section.title!r} has no table {name!r}")
    return found


def headline(chapters: Chapters, calibration: Verification | None = None) -> ComparisonTable:
    """The headline comparison, one row per chapter's key figure, read from the chapters' rows.

    Parameters
    ----------
    chapters : Chapters
        The report's chapter sections.
    calibration : Verification, optional
        The shipped model's verification (:func:`trms.calibration.verify`): adds, beside the twin's ARMAX DC gain,
        the same figure over the calibration's unseen seeds (the same protocol).

    Returns
    -------
    ComparisonTable
        Columns chapter, quantity, thesis, linear model, twin, :data:`VERDICT`, notes.
    """
    t = side_by_side("Headline: the thesis, the linear model and the twin", ["chapter", "quantity"])
    t.columns.insert(t.columns.index("notes"), VERDICT)

    def add(chapter: str, label: str, thesis: object, linear: object, twin: object, verdict: str, note: str) -> None:
        t.rows.append([chapter, label, thesis, linear, twin, verdict, note])

    def row(chapter: str, label: str, c: Compared, table: str, note: str = "") -> None:
        ref = f"{c.notes} ({table})" if "note " in c.notes else c.notes
        add(
            chapter,
            label,
            c.thesis,
            c.linear,
            c.twin,
            numeric_verdict(c.thesis, c.twin, list(c.twin_notes)),
            note or ref,
        )

    def table_row(chapter: str, label: str, table: ComparisonTable, key: dict, note: str = "") -> None:
        row(chapter, label, compared_row(table, key), table.title.split(":")[0], note)

    c3a, c3b = _table(chapters.ch3, "Ch. 3, 1-DOF"), _table(chapters.ch3, "Table 3.1")
    table_row("3", "1-DOF pitch PSD main mode (Hz)", c3a, {"quantity": "pitch PSD main mode (Hz)"})
    gain_checks = [c for c in (calibration.checks if calibration else []) if c.name == "1dof ARMAX DC gain"]
    gains = [c.achieved for c in gain_checks]
    runs = [g for c in gain_checks for g in c.runs]
    table_row(
        "3",
        "1-DOF ARMAX DC gain (rad/V)",
        c3a,
        {"quantity": "ARMAX DC gain (rad/V)"},
        f"one 60 s run; the same signal and model (the calibration's 1-DOF protocol, recorded at 10 Hz) at its "
        f"{len(gains)} unseen seeds: single runs {min(runs):.3g}-{max(runs):.3g} ({len(runs)} runs, the scatter "
        f"of one run), each seed's median of its runs {min(gains):.3g}-{max(gains):.3g}, median "
        f"{float(np.median(gains)):.3g}"
        if runs
        else "",
    )
    table_row("3", "2-DOF u2 -> yaw modes (Hz)", c3b, {"channel": "u2->y2", "quantity": "PSD modes (Hz)"})
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
        "unstable on the rig",
        lin_m,
        twin_m,
        AGREES if twin_m.endswith(f"; {stability(False)}") else DIFFERS,
        "see the margins table",
    )
    f_lin, f_twin = ch67.findings["linear"], ch67.findings["twin"]
    missed = [f for f in f_twin if not f.shown]
    add(
        "7",
        "ch. 7 findings shown",
        f"{len(f_twin)} findings",
        f"{sum(f.shown for f in f_lin)}",
        f"{len(f_twin) - len(missed)}",
        AGREES if not missed else (EXPLAINED if all(f.explained for f in missed) else DIFFERS),
        "see the ch. 7 findings table",
    )
    row("7", f"push: back within {RECOVERY_BAND:g} rad after (s), R = 125", ch67.push[125.0], "Ch. 7.4")
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
    return t
