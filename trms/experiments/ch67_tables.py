"""Chapters 6 and 7 presented: Table 6.1, the rig's cases, the push, the loop margins, the ch. 7 findings.

Every builder here takes the results of :mod:`trms.experiments.ch67_lqg` (run on the linear model
and on the twin) and returns a :class:`~trms.present.tables.ComparisonTable`; the report, the
CLI and the tests call the same builders. Every note that says why a cell differs from the thesis
is computed from the same run: the cell under the alternative definitions that
:func:`~trms.experiments.ch67_lqg.summarise` measures (rise timed from the command edge, the first
step from rest, the other settling band), the amplitude at which the peak control would meet the
limit, or the loop's margins; where none brings the cell within 30 % of the thesis, the note says
"not explained". The ch. 7 findings and their explanations are measured in
:mod:`trms.experiments.ch7_findings`. :func:`chapter` assembles the section and keeps the rows its key figures
are read from as data (:class:`Chapter67`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from trms.experiments.ch7_findings import Finding, amplitude_at_limit, findings, measured, table_findings
from trms.experiments.ch7_side_mode import SideModeEvidence
from trms.experiments.ch67_lqg import (
    ALL_CASES,
    DEFAULT_AMPLITUDE,
    DEFAULT_DURATION,
    DEFAULT_PERIOD,
    ESTIMATOR_QE,
    ESTIMATOR_RE,
    NARROW_BAND,
    PCI_LIMIT,
    PUSH,
    RECOVERY_BAND,
    WANDER_WINDOW,
    CaseResult,
    Margins,
    PushResult,
)
from trms.present.figures import plot_series, save_figure
from trms.present.sections import FigureRef, Section
from trms.present.tables import EXPLAIN_ABOVE, ComparisonTable, format_cell, relative_difference, side_by_side
from trms.reference import CHAPTER_7_OUTCOMES, CHAPTER_7_PREFILTER_OUTCOMES, LQG_WEIGHTS_R, TABLE_6_1

__all__ = [
    "Compared",
    "MEASURES_6_1",
    "TABLE_6_1_NAME",
    "rows_6_1",
    "table_6_1",
    "table_6_1_control",
    "table_7",
    "push_rows",
    "table_push",
    "stability",
    "table_margins",
    "Chapter67",
    "chapter",
]

_WORLD = {"linear": "linear model", "twin": "twin"}
# The findings' criteria under this module's name as well (the side-mode tests read them here).


# ------------------------------------------------------------------------------------ Table 6.1
def _alternatives(s: Mapping[str, float | str], key: str) -> dict[str, float]:
    """The cell ``key`` ("TR"/"TS") under the alternative definitions measured in the same run."""
    if key == "TR":
        return {"timed from the command edge": float(s["TR edge"]), "first step, from rest": float(s["TR first"])}
    other = "TS wide" if s["band"] == NARROW_BAND else "TS narrow"
    label = "in the 5 % band" if other == "TS wide" else "in the 2 % band"
    return {label: float(s[other]), "first step, from rest (2 % band)": float(s["TS first"])}


def _margin_text(m: Margins) -> str:
    if not m.stable:
        return "its loop broken at the plant input is unstable already (closed-loop poles outside the unit circle)"
    return (
        f"its loop has {m.phase_margin_deg:.0f} deg phase margin and {m.delay_margin_s:.2f} s delay margin; with "
        f"one sample of computation delay it is {'stable' if m.stable_with_delay else 'unstable'}"
    )


def _cell_note(
    world: str, r: float, case: str, key: str, res: CaseResult, printed: object, margins: Mapping[float, Margins] | None
) -> tuple[object, str | None]:
    """The cell and, when it is more than 30 % off (or a status), the note that explains it."""
    where = f"R = {r:g}, {case}, {key}, {_WORLD[world]}"
    if res.status in ("hit the stops", "diverged"):
        why = f"R = {r:g}, {_WORLD[world]}: the run {res.status}"
        if margins and r in margins:
            why += f"; {_margin_text(margins[r])} (see the margins table)"
        return res.status, why + "."
    s = res.summary
    if key == "control":  # a sensitivity, not a verdict: the amplitude where the peak control meets the limit
        return f"limit from +-{float(s['limit']) / float(s['peak']) * DEFAULT_AMPLITUDE:.2g} rad", None
    value = float(s[key])
    if not np.isfinite(value):
        return "not settled", f"{where}: not settled within its band by the step's end."
    note = None
    if key == "TS" and s["band"] != NARROW_BAND:
        note = (
            f"{where}: settling read in the {s['band']:.0%} band: the run's measured wander "
            f"({1e3 * float(s['wander']):.1f} mrad, largest |error| over the last {WANDER_WINDOW:g} s of each step) "
            f"exceeds the 2 % band ({1e3 * NARROW_BAND * float(s['step']):.1f} mrad)."
        )
    d = relative_difference(value, printed)
    if not d > EXPLAIN_ABOVE:
        return value, note
    alts = _alternatives(s, key)
    close = {k: v for k, v in alts.items() if np.isfinite(v) and relative_difference(v, printed) <= EXPLAIN_ABOVE}
    listed = "; ".join(f"{k} {v:.3g} s" if np.isfinite(v) else f"{k} never within its band" for k, v in alts.items())
    head = f"{where}: {value:.3g} s vs thesis {format_cell(printed)} s ({d:.0%} off)"
    if close:
        k, v = next(iter(close.items()))
        why = f"{head}; {k} it is {v:.3g} s ({relative_difference(v, printed):.0%} off): explained by that definition."
    else:
        why = f"{head}; not explained (the same run {listed})."
        if float(s["saturated"]) > 0:
            why = why[:-1] + f"; the actuator saturated for {s['saturated']:.1f} s)."
    return value, (note + " " + why) if note else why


@dataclass(frozen=True)
class Compared:
    """One quantity of a side-by-side table as data: the thesis's value, each world's cell, the notes it cites.

    Attributes
    ----------
    thesis, linear, twin : object
        The cells as the table prints them (a number, a range or a word).
    notes : str
        The row's notes cell: the notes it cites (``"note 1, note 3"``), or empty.
    twin_notes : tuple of str
        The notes on the twin's cell, as the table prints them (``"note 3: ..."``).
    """

    thesis: object
    linear: object
    twin: object
    notes: str = ""
    twin_notes: tuple[str, ...] = ()


#: Table 6.1's measures: the key :func:`rows_6_1` files each row under, and the row's label.
MEASURES_6_1 = {"TR": "TR (s)", "TS": "TS (s)", "control": "control"}
#: The name Table 6.1's title starts with (and its notes are cited by).
TABLE_6_1_NAME = "Table 6.1"


def rows_6_1(
    lin: Mapping[tuple[float, str], CaseResult],
    twin: Mapping[tuple[float, str], CaseResult],
    margins: Mapping[str, Mapping[float, Margins]] | None = None,
) -> tuple[dict[tuple[float, str, str], Compared], list[str]]:
    """Table 6.1's rows by ``(R, case, measure)`` (a key of :data:`MEASURES_6_1`) and the notes they cite.

    Parameters
    ----------
    lin, twin, margins
        As :func:`table_6_1`.

    Returns
    -------
    rows : dict
        In the thesis's order; each row's ``notes`` cites the returned notes by number.
    notes : list of str
        ``"note k: ..."``, every cell more than 30 % from the thesis with what the same run measures under the
        alternative definitions.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import lqg_cases, pitch_plant
    >>> p = pitch_plant(noise_std=1e-3)
    >>> rows, notes = rows_6_1(*[lqg_cases(p, p.system, [75.0], ["SAS"])] * 2)
    >>> rows[(75.0, "SAS", "TR")].thesis, sorted({k for _, _, k in rows}) == sorted(MEASURES_6_1)
    (3.0, True)
    """
    flagged: list[str] = []
    rows: dict[tuple[float, str, str], Compared] = {}
    for (r, case), printed in TABLE_6_1.items():
        if (r, case) not in lin or (r, case) not in twin:
            continue
        for j, key in enumerate(MEASURES_6_1):
            cells, marks, twin_notes = [], [], []
            for world, res in (("linear", lin[(r, case)]), ("twin", twin[(r, case)])):
                cell, note = _cell_note(world, r, case, key, res, printed[j], (margins or {}).get(world))
                cells.append(cell)
                if note:
                    if note not in flagged:
                        flagged.append(note)
                    marks.append(f"note {flagged.index(note) + 1}")
                    if world == "twin":
                        twin_notes.append(f"{marks[-1]}: {note}")
            rows[(r, case, key)] = Compared(printed[j], cells[0], cells[1], ", ".join(marks), tuple(twin_notes))
    return rows, [f"note {i + 1}: {n}" for i, n in enumerate(flagged)]


def _render_6_1(rows: Mapping[tuple[float, str, str], Compared], notes: list[str]) -> ComparisonTable:
    """Table 6.1 from :func:`rows_6_1`."""
    table = side_by_side(
        f"{TABLE_6_1_NAME}: SAS and CSAS (Q = I), square wave +-{DEFAULT_AMPLITUDE:g} rad; controllers designed on "
        "eq. (3.11)",
        ["R", "case", "measure"],
    )
    table.rows = [
        [r, case, MEASURES_6_1[key], c.thesis, c.linear, c.twin, c.notes] for (r, case, key), c in rows.items()
    ]
    table.notes = [
        f"TR: 10-90 % rise; TS: settling in the 2 % band (or the 5 % band where the run's measured wander does not "
        f"fit in the 2 % band); both the largest over the full-swing steps of a square wave of period "
        f"{DEFAULT_PERIOD:g} s over {DEFAULT_DURATION:g} s. Control: the thesis's 'high' means beyond the actuator "
        "limit at its square wave, whose amplitude it does not print; here the amplitude at which the peak control "
        f"meets the +-10 V limit, scaled from this run's +-{DEFAULT_AMPLITUDE:g} rad (the next table reads it at the "
        f"PCI set-up's +-{PCI_LIMIT:g} V and for a slower and a faster estimator). "
        f"Estimator Qe = {ESTIMATOR_QE:g} I, Re = {ESTIMATOR_RE:g}.",
        *notes,
    ]
    return table


def table_6_1(
    lin: Mapping[tuple[float, str], CaseResult],
    twin: Mapping[tuple[float, str], CaseResult],
    margins: Mapping[str, Mapping[float, Margins]] | None = None,
) -> ComparisonTable:
    """Table 6.1 (R = 75 and 1, the thesis's rows) on the linear model and on the twin, with computed notes.

    Parameters
    ----------
    lin, twin : mapping
        :func:`trms.experiments.ch67_lqg.lqg_cases` on each world (must hold R = 75 and 1).
    margins : mapping, optional
        ``{"linear": {R: Margins}, "twin": {...}}`` (:func:`trms.experiments.ch67_lqg.loop_margins`),
        quoted where a run fails.

    Returns
    -------
    ComparisonTable
        Rows ``[R, case, measure, thesis, linear model, twin, notes]``; ``notes`` lists every cell more
        than 30 % from the thesis with what the same run measures under the alternatives.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import lqg_cases, pitch_plant
    >>> p = pitch_plant(noise_std=1e-3)
    >>> res = lqg_cases(p, p.system, [75.0, 1.0], ["SAS"])
    >>> table_6_1(res, res).rows[0][:4]
    [75.0, 'SAS', 'TR (s)', 3.0]
    """
    return _render_6_1(*rows_6_1(lin, twin, margins))


def table_6_1_control(
    runs: Mapping[str, Mapping[float, Mapping[tuple[float, str], CaseResult]]], trim: float
) -> ComparisonTable:
    """Table 6.1's control column as a sensitivity: the square-wave amplitude at which each loop's peak control meets
    the thesis's +-10 V and the PCI set-up's +-2.5 V, and the peak control per radian of command under the thesis's
    estimator and a slower and a faster one.

    Parameters
    ----------
    runs : mapping
        ``{world: {estimator scale: lqg_cases(...)}}`` with the scale 1 (the thesis's estimator) among them.
    trim : float
        The hover voltage the limits are about (V).
    """
    scales = sorted({k for by in runs.values() for k in by})
    table = ComparisonTable(
        "Table 6.1's control: the command amplitude at which each loop meets the actuator limit (rad), and its peak "
        "control per radian of command (V/rad) by estimator speed",
        [
            "R",
            "case",
            "world",
            "thesis",
            "+-10 V from (rad)",
            f"+-{PCI_LIMIT:g} V from (rad)",
            *(f"V/rad, Qe x{k:g}" for k in scales),
        ],
    )
    for (r, case), printed in TABLE_6_1.items():
        for world, by_scale in runs.items():
            base = by_scale.get(1.0, {}).get((r, case))
            if base is None:
                continue
            cells: list[object] = []
            for limit in (10.0, PCI_LIMIT):
                cells.append(amplitude_at_limit(base, limit, trim) if measured(base) else base.status)
            for k in scales:
                res = by_scale.get(k, {}).get((r, case))
                cells.append(
                    float(res.summary["peak"]) / (float(res.summary["step"]) / 2.0)
                    if res is not None and measured(res)
                    else (res.status if res is not None else "-")
                )
            table.rows.append([r, case, _WORLD[world], printed[2], *cells])
    table.notes = [
        "Scaled from each run's peak control (the loops are linear in the command until the actuator saturates). "
        "Qe x k: the estimator's process noise covariance times k (above 1 faster, below 1 slower). The thesis's "
        "'high' reads as a square wave above the amplitude in the limit's column; its 'ok', below it."
    ]
    return table


# ------------------------------------------------------------------------------ ch. 7 on the rig
def _brief(res: CaseResult) -> str:
    if not res.summary:
        return res.status
    s = res.summary
    return f"{res.status}; overshoot {s['overshoot']:.0f} %; peak |u| {s['peak']:.2g} V; control {s['control']}"


def table_7(lin: Mapping, twin: Mapping, weights: Sequence[float] = LQG_WEIGHTS_R) -> ComparisonTable:
    """Every (R, case) of ch. 7: what the rig did (thesis text), what each world does."""
    table = side_by_side("Ch. 7: the controllers on the rig (status; overshoot; peak |u|; control)", ["R", "case"])
    for r in weights:
        if r == 1.0:  # the rig ran R = 1 only as SAS
            table.rows.append(
                [r, "SAS", "unstable (SAS); not run further", _brief(lin[(r, "SAS")]), _brief(twin[(r, "SAS")]), ""]
            )
            continue
        for case in ALL_CASES:
            if case == "SAS":
                thesis = CHAPTER_7_OUTCOMES[r].split(";")[0].replace("SAS: ", "")
            elif case in CHAPTER_7_PREFILTER_OUTCOMES:
                thesis = CHAPTER_7_PREFILTER_OUTCOMES[case]
            else:
                thesis = "not run on the rig"
            table.rows.append([r, case, thesis, _brief(lin[(r, case)]), _brief(twin[(r, case)]), ""])
    return table


def push_rows(res: PushResult) -> tuple[Compared, Compared]:
    """One push's rows of :func:`table_push`: the peak pitch after it (rad), and the time to come back within
    :data:`~trms.experiments.ch67_lqg.RECOVERY_BAND` (s); the run's status where it never does.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import PushResult
    >>> peak, back = push_rows(PushResult("recovered", 0.1, 2.5, None))
    >>> back.thesis, back.linear, back.twin
    ('rejected', '-', 2.5)
    """
    peak = res.peak if np.isfinite(res.peak) else res.status
    back = res.recovery if np.isfinite(res.recovery) else res.status
    return Compared("rejected (figs. 7.17-7.19)", "-", peak), Compared("rejected", "-", back)


def table_push(push: Mapping[float, PushResult]) -> ComparisonTable:
    """Ch. 7.4: peak pitch after the push and the time to come back within :data:`RECOVERY_BAND`."""
    t, j, _ = PUSH
    table = side_by_side(
        f"Ch. 7.4: push rejection under SAS, impulse {j:g} N m s about pitch at {t:g} s (twin; the "
        "linear model has no torque input)",
        ["R", "measure"],
    )
    labels = ("peak pitch after the push (rad)", f"back within {RECOVERY_BAND:g} rad after (s)")
    for r, res in push.items():
        for label, row in zip(labels, push_rows(res)):
            table.rows.append([r, label, row.thesis, row.linear, row.twin, row.notes])
    return table


def stability(stable: bool) -> str:
    """A loop's stability as the margins table prints it.

    Examples
    --------
    >>> stability(True), stability(False)
    ('stable', 'unstable')
    """
    return "stable" if stable else "unstable"


def table_margins(margins: Mapping[str, Mapping[float, Margins]], models: Mapping[str, str]) -> ComparisonTable:
    """Gain, phase and delay margin of every LQG loop at the plant input, on each world's linear model."""
    table = ComparisonTable(
        "Stability margins of the LQG loops, broken at the plant input (python-control)",
        [
            "R",
            "world (plant model)",
            "gain margin (dB)",
            "phase margin (deg)",
            "delay margin (s)",
            "closed loop",
            "with one sample of computation delay",
        ],
    )
    for world, by_r in margins.items():
        for r, m in by_r.items():
            table.rows.append(
                [
                    r,
                    f"{_WORLD[world]} ({models[world]})",
                    m.gain_margin_db,
                    m.phase_margin_deg,
                    m.delay_margin_s if m.stable else "unstable",
                    stability(m.stable),
                    stability(m.stable_with_delay),
                ]
            )
    table.notes = [
        "Loop transfer L = -C_y(z) G(z): the compensator from the measurement to the control in series "
        "with the plant model; delay margin = the smallest phase margin / crossover frequency over every "
        "gain crossover. 'one sample of computation delay' closes the loop with an extra z^-1."
    ]
    return table


# ------------------------------------------------------------------------------------- section
@dataclass
class Chapter67:
    """The chapters 6 and 7 section and the typed rows its key figures are read from.

    Attributes
    ----------
    section : Section
        Table 6.1, the rig's cases, the push, the margins, the findings (and Table 6.1's control sensitivity), with
        the figures.
    table_6_1 : dict
        Table 6.1's rows by ``(R, case, measure)`` (:func:`rows_6_1`).
    push : dict
        The time back within the recovery band after each push, by R (:func:`push_rows`).
    margins : mapping
        ``{world: {R: Margins}}`` the margins table shows.
    findings : dict
        ``{world: [Finding, ...]}`` (:func:`trms.experiments.ch7_findings.findings`) the findings table shows.
    """

    section: Section
    table_6_1: dict[tuple[float, str, str], Compared]
    push: dict[float, Compared]
    margins: Mapping[str, Mapping[float, Margins]]
    findings: dict[str, list[Finding]]


def chapter(
    lin: Mapping[tuple[float, str], CaseResult],
    twin: Mapping[tuple[float, str], CaseResult],
    push: Mapping[float, PushResult],
    margins: Mapping[str, Mapping[float, Margins]],
    margin_models: Mapping[str, str],
    folder: str | os.PathLike[str],
    weights: Sequence[float] = LQG_WEIGHTS_R,
    evidence: SideModeEvidence | None = None,
    estimators: Mapping[str, Mapping[float, Mapping[tuple[float, str], CaseResult]]] | None = None,
    trim: float = 0.0,
) -> Chapter67:
    """The chapters 6 and 7 section (Table 6.1, the rig's cases, the push, the margins, the findings, figures) with its
    typed rows.

    ``evidence`` (:func:`trms.experiments.ch7_side_mode.prefilter_evidence` on the twin) explains a
    missing low-pass finding; see :func:`trms.experiments.ch7_findings.findings`. ``estimators``
    (``{world: {Qe scale: lqg_cases(...)}}``, the thesis's estimator added from ``lin``/``twin``) and ``trim`` (V)
    add Table 6.1's control sensitivity (:func:`table_6_1_control`) as the last table.

    Returns
    -------
    Chapter67

    Examples
    --------
    >>> import tempfile
    >>> from trms.experiments.ch67_lqg import lqg_cases, loop_margins, pitch_plant
    >>> p, weights = pitch_plant(noise_std=1e-3), (75.0, 1.0, 125.0)
    >>> res = lqg_cases(p, p.system, weights)
    >>> m = {w: {r: loop_margins(p.system, p.system, r) for r in weights} for w in ("linear", "twin")}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     c = chapter(res, res, {}, m, {"linear": "eq. (3.11)", "twin": "eq. (3.11)"}, folder, weights)
    >>> c.table_6_1[(75.0, "SAS", "TR")].thesis, len(c.findings["twin"]), len(c.section.tables), len(c.section.figures)
    (3.0, 6, 5, 4)
    """
    folder = Path(folder)
    figs = []
    for r, case in ((125.0, "SAS"), (125.0, "CSAS LPF 0.2 Hz"), (75.0, "SAS"), (1.0, "SAS")):
        if (r, case) not in twin:
            continue
        a, b = lin[(r, case)], twin[(r, case)]
        rec_a, rec_b = a.record, b.record
        if rec_a is None or rec_b is None:
            continue
        lim = float(b.summary.get("limit") or 0.0)
        slug = case.lower().replace(" & ", "_").replace(" ", "_").replace(".", "p")
        series = {
            "command": rec_a.extras["reference"][:, 0],
            f"linear model ({a.status})": rec_a.deviations()[1][:, 0],
            f"twin ({b.status})": rec_b.deviations()[1][:, 0],
        }
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        rec_a.time,
                        series,
                        f"{case}, Q = I, R = {r:g}: linear model and twin (figs. 6.6-7.16)",
                        "pitch (rad, deviation)",
                        {
                            "linear model u": rec_a.extras["control"][:, 0],
                            "twin u": rec_b.extras["control"][:, 0],
                        },
                        limits=(-lim, lim) if lim else None,
                    ),
                    folder / f"ch67_R{r:g}_{slug}.png",
                ),
                f"{case} with R = {r:g}: pitch and commanded control on the linear model and on the twin; "
                "dashed: the actuator limits (deviation V).",
            )
        )
    recs = {f"R = {r:g} ({p.status})": p.record.deviations()[1][:, 0] for r, p in push.items() if p.record is not None}
    if recs:
        first = next(p.record for p in push.values() if p.record is not None)
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        first.time,
                        recs,
                        "Twin: push on the beam at 19 s under SAS (figs. 7.17-7.19)",
                        "pitch (rad, deviation)",
                    ),
                    folder / "ch7_push_twin.png",
                ),
                "Twin pitch holding hover under SAS while the beam is pushed at 19 s.",
            )
        )
    f_lin = findings(lin, None, margins["linear"])
    f_twin = findings(twin, push, margins["twin"], evidence)
    paragraphs = [
        f"Integral LQG (the cost J of eq. 6.34, Q = I, estimator Qe = {ESTIMATOR_QE:g} I, Re = {ESTIMATOR_RE:g}, "
        "current estimator, anti-windup) designed on eq. (3.11) for each R, with and without the command "
        "prefilters, tracking a "
        f"square wave of +-{DEFAULT_AMPLITUDE:g} rad. The same controllers run on the linear model and on the twin.",
    ]
    rows, notes = rows_6_1(lin, twin, margins)
    t61 = _render_6_1(rows, notes)
    shown = [f.name for f in f_twin if f.shown]
    missed = [
        f"{f.name} ({'not explained' if 'not explained' in f.explanation else 'explained'}, see the findings table)"
        for f in f_twin
        if not f.shown
    ]
    m1 = margins["linear"].get(1.0)
    conclusion = [
        f"The twin shows {len(shown)} of {len(f_twin)} ch. 7 findings: {', '.join(shown) or 'none'}."
        + (f" Not shown: {'; '.join(missed)}." if missed else ""),
        f"Table 6.1, its notes: {sum(1 for n in t61.notes if 'explained by' in n)} cells explained by an "
        f"alternative definition measured in the same run, {sum(1 for n in t61.notes if 'not explained' in n)} "
        "not explained; its control column is a sensitivity (the command amplitude at which each loop meets the "
        "actuator limit), not a verdict.",
    ]
    if m1 is not None:
        conclusion.append(
            f"R = 1 on eq. (3.11): {_margin_text(m1)} -- the rig computes with at least that delay, "
            "which is why it was unstable there though the simulation settled."
        )
    section = Section(
        "Chapters 6 and 7: LQG (SAS and CSAS) on the linear model and on the twin",
        paragraphs,
        [
            t61,
            table_7(lin, twin, weights),
            table_push(push),
            table_margins(margins, margin_models),
            table_findings(f_lin, f_twin),
            *(
                [
                    table_6_1_control(
                        {w: {1.0: base, **estimators.get(w, {})} for w, base in (("linear", lin), ("twin", twin))}, trim
                    )
                ]
                if estimators is not None
                else []
            ),
        ],
        figs,
        conclusion=conclusion,
    )
    return Chapter67(
        section,
        rows,
        {r: push_rows(p)[1] for r, p in push.items()},
        margins,
        {"linear": f_lin, "twin": f_twin},
    )
