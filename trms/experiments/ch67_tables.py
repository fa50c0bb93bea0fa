"""Chapters 6 and 7 presented: Table 6.1, the rig's cases, the push, the loop margins, the ch. 7 findings.

Every builder here takes the results of :mod:`trms.experiments.ch67_lqg` (run on the linear model
and on the twin) and returns a :class:`~trms.present.tables.ComparisonTable`; the report, the
CLI and the tests call the same builders. Every note that says why a cell differs from the thesis
is computed from the same run: the cell under the alternative definitions that
:func:`~trms.experiments.ch67_lqg.summarise` measures (rise timed from the command edge, the first
step from rest, the other settling band), the amplitude at which the peak control would meet the
limit, or the loop's margins; where none brings the cell within 30 % of the thesis, the note says
"not explained". The twin's cells may be its runs at every seed of the report (:class:`~trms.present.seeds.Seeded`):
each is then the median (range) over the seeds and judged at each (:func:`~trms.present.seeds.verdict`), and an
explanation holds only if it holds at every seed. The ch. 7 findings and their explanations are measured in
:mod:`trms.experiments.ch7_findings`; :mod:`trms.experiments.ch67_chapter` assembles the section.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from trms.experiments.ch7_findings import amplitude_at_limit, measured
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
from trms.present.seeds import AGREES, DIFFERS, Seeded, agreeing, over_seeds, seeded, verdict
from trms.present.tables import EXPLAIN_ABOVE, ComparisonTable, format_cell, relative_difference, side_by_side
from trms.reference import (
    CHAPTER_7_OUTCOMES,
    CHAPTER_7_PREFILTER_OUTCOMES,
    LITERATURE,
    LQG_WEIGHTS_R,
    PRINTED,
    TABLE_6_1,
)

__all__ = [
    "Compared",
    "MEASURES_6_1",
    "TABLE_6_1_NAME",
    "rows_6_1",
    "render_6_1",
    "table_6_1",
    "table_6_1_control",
    "table_7",
    "push_rows",
    "seeded_push",
    "table_push",
    "stability",
    "margin_text",
    "table_margins",
]

#: One world's LQG runs by (R, case), or the twin's at every seed.
Cases = Mapping[tuple[float, str], CaseResult]

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


def margin_text(m: Margins) -> str:
    """A loop's margins in words, as the notes quote them.

    Examples
    --------
    >>> margin_text(Margins(3.0, -11.0, 0.12, True, False))[:79]
    'its loop is stable, with a phase margin of -11 deg and a delay margin of 0.12 s'
    """
    if not m.stable:
        return (
            f"its loop broken at the plant input is unstable already (closed-loop poles outside the unit circle; delay "
            f"margin {m.delay_margin_s:.2g} s)"
        )
    return (
        f"its loop is stable, with a phase margin of {m.phase_margin_deg:.0f} deg and a delay margin of "
        f"{m.delay_margin_s:.2f} s; with one sample of computation delay it is "
        f"{'stable' if m.stable_with_delay else 'unstable'}"
    )


def _cell(res: CaseResult, key: str) -> object:
    """One run's cell of Table 6.1: the measure (s), the run's status, "not settled", or the control's limit text."""
    if res.status in ("hit the stops", "diverged"):
        return res.status
    s = res.summary
    if key == "control":  # a sensitivity, not a verdict: the amplitude where the peak control meets the limit
        return f"limit from +-{float(s['limit']) / float(s['peak']) * DEFAULT_AMPLITUDE:.2g} rad"
    value = float(s[key])
    return value if np.isfinite(value) else "not settled"


def _cell_note(
    world: str,
    r: float,
    case: str,
    key: str,
    runs: Seeded[CaseResult],
    printed: object,
    margins: Mapping[float, Margins] | None,
    status_note: str | None = None,
) -> tuple[object, str | None]:
    """The cell (over the seeds) and, when it does not agree with the thesis at every seed, the note on it.

    A status at every seed gets ``status_note`` (or the loop's margins: "not explained"); a measure that differs at
    every seed is explained by an alternative definition only when the same one brings it within 30 % of the thesis at
    every seed; one that agrees at some seeds only is "inconclusive at N seeds".
    """
    where = f"R = {r:g}, {case}, {key}, {_WORLD[world]}"
    if key == "control":
        return _cell(runs.first, key), None
    cell = runs.cell(lambda c: _cell(c, key))
    wide = [c for c in runs.results if measured(c) and c.summary["band"] != NARROW_BAND]
    band = None
    if key == "TS" and wide:
        s = wide[0].summary
        band = (
            f"{where}: settling read in the {s['band']:.0%} band at {len(wide)} of {len(runs.results)} seed(s): the "
            f"runs' measured wander (e.g. {1e3 * float(s['wander']):.1f} mrad, largest |error| over the last "
            f"{WANDER_WINDOW:g} s of each step) exceeds the 2 % band ({1e3 * NARROW_BAND * float(s['step']):.1f} mrad)."
        )
    judged = verdict(printed, cell)
    if judged == AGREES:
        return cell, band
    if judged != DIFFERS:
        k, n = agreeing(printed, cell)
        note = (
            f"{where}: {format_cell(cell)} s vs thesis {format_cell(printed)} s: within {EXPLAIN_ABOVE:.0%} at {k} "
            f"of {n} seeds: {judged}."
        )
    elif all(isinstance(_cell(c, key), str) for c in runs.results):
        if status_note is not None:
            note = status_note
        else:
            note = f"{where}: {format_cell(cell)}"
            if margins and r in margins:
                note += f"; {margin_text(margins[r])} (see the margins table)"
            note += ": not explained."
    else:
        alts = [_alternatives(c.summary, key) if c.summary else {} for c in runs.results]
        common = [
            name
            for name in alts[0]
            if all(
                name in a and np.isfinite(a[name]) and relative_difference(a[name], printed) <= EXPLAIN_ABOVE
                for a in alts
            )
        ]
        head = f"{where}: {format_cell(cell)} s vs thesis {format_cell(printed)} s"
        if common:
            name = common[0]
            values = runs.cell(lambda c: _alternatives(c.summary, key)[name])
            every = " at every seed" if len(runs.seeds) > 1 else ""
            note = f"{head}; {name} it is {format_cell(values)} s{every} (summarise): explained by that definition."
        else:
            listed = "; ".join(
                f"{k} {v:.3g} s" if np.isfinite(v) else f"{k} never within its band" for k, v in alts[0].items()
            )
            note = f"{head}; not explained (the same run at seed {runs.seeds[0]}: {listed})."
            sat = runs.first.summary.get("saturated") if runs.first.summary else None
            if sat is not None and float(sat) > 0:
                note = note[:-2] + f"; the actuator saturated for {float(sat):.1f} s)."
    return cell, (band + " " + note) if band else note


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
    source : str
        Where the thesis's value comes from (:data:`trms.reference.SOURCES`).
    """

    thesis: object
    linear: object
    twin: object
    notes: str = ""
    twin_notes: tuple[str, ...] = ()
    source: str = PRINTED


#: Table 6.1's measures: the key :func:`rows_6_1` files each row under, and the row's label.
MEASURES_6_1 = {"TR": "TR (s)", "TS": "TS (s)", "control": "control"}
#: The name Table 6.1's title starts with (and its notes are cited by).
TABLE_6_1_NAME = "Table 6.1"


def rows_6_1(
    lin: Cases,
    twin: Cases | Seeded[Cases],
    margins: Mapping[str, Mapping[float, Margins]] | None = None,
    status_notes: Mapping[tuple[float, str], str] | None = None,
) -> tuple[dict[tuple[float, str, str], Compared], list[str]]:
    """Table 6.1's rows by ``(R, case, measure)`` (a key of :data:`MEASURES_6_1`) and the notes they cite.

    Parameters
    ----------
    lin, twin, margins
        As :func:`table_6_1` (the twin's runs may be :class:`~trms.present.seeds.Seeded`).
    status_notes : mapping, optional
        The twin's note on a ``(R, case)`` whose runs gave a status at every seed (e.g. R = 1's,
        :func:`trms.experiments.ch67_amplitudes.amplitude_note`).

    Returns
    -------
    rows : dict
        In the thesis's order; each row's ``notes`` cites the returned notes by number.
    notes : list of str
        ``"note k: ..."``, every cell that does not agree with the thesis at every seed, with what the same runs
        measure under the alternative definitions.

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
    tw = seeded(twin)
    for (r, case), printed in TABLE_6_1.items():
        if (r, case) not in lin or any((r, case) not in t for t in tw.results):
            continue
        for j, key in enumerate(MEASURES_6_1):
            cells, marks, twin_notes = [], [], []
            worlds = (
                ("linear", Seeded((tw.seeds[0],), (lin[(r, case)],)), None),
                (
                    "twin",
                    Seeded(tw.seeds, tuple(t[(r, case)] for t in tw.results)),
                    (status_notes or {}).get((r, case)),
                ),
            )
            for world, runs, status in worlds:
                cell, note = _cell_note(world, r, case, key, runs, printed[j], (margins or {}).get(world), status)
                cells.append(cell)
                if note:
                    if note not in flagged:
                        flagged.append(note)
                    marks.append(f"note {flagged.index(note) + 1}")
                    if world == "twin":
                        twin_notes.append(f"{marks[-1]}: {note}")
            rows[(r, case, key)] = Compared(printed[j], cells[0], cells[1], ", ".join(marks), tuple(twin_notes))
    return rows, [f"note {i + 1}: {n}" for i, n in enumerate(flagged)]


def render_6_1(rows: Mapping[tuple[float, str, str], Compared], notes: list[str]) -> ComparisonTable:
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
        f"meets the +-10 V limit, scaled from this run's +-{DEFAULT_AMPLITUDE:g} rad (the last table reads it at the "
        f"+-{PCI_LIMIT:g} V of Feedback's PCI set-up ({LITERATURE}, not the thesis) and for a slower and a faster "
        f"estimator). Estimator Qe = {ESTIMATOR_QE:g} I, Re = {ESTIMATOR_RE:g}. Twin: the seed-by-seed runs' median "
        "(range) where they were flown at several seeds, each seed judged (within 30 % of the thesis's: agrees at "
        "every seed, differs at none, else inconclusive); its control column is the first seed's.",
        *notes,
    ]
    return table


def table_6_1(
    lin: Cases,
    twin: Cases | Seeded[Cases],
    margins: Mapping[str, Mapping[float, Margins]] | None = None,
) -> ComparisonTable:
    """Table 6.1 (R = 75 and 1, the thesis's rows) on the linear model and on the twin, with computed notes.

    Parameters
    ----------
    lin, twin : mapping
        :func:`trms.experiments.ch67_lqg.lqg_cases` on each world (must hold R = 75 and 1); the twin's may be its runs
        at every seed (:class:`~trms.present.seeds.Seeded`).
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
    return render_6_1(*rows_6_1(lin, twin, margins))


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
        f"+-{PCI_LIMIT:g} V: Feedback's 33-949 PCI set-up ({LITERATURE}; the thesis prints +-10 V). "
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


def table_7(lin: Cases, twin: Cases, weights: Sequence[float] = LQG_WEIGHTS_R) -> ComparisonTable:
    """Every (R, case) of ch. 7: what the rig did (thesis text), what each world does (at the run's own seed)."""
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


def seeded_push(
    push: Mapping[float, PushResult] | Seeded[Mapping[float, PushResult]],
) -> dict[float, tuple[Compared, Compared]]:
    """Each R's rows of :func:`push_rows`, the twin's cells over every seed of ``push``.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import PushResult
    >>> runs = Seeded((0, 1000), ({125.0: PushResult("recovered", 0.1, 2.5, None)},
    ...                           {125.0: PushResult("recovered", 0.1, 3.5, None)}))
    >>> str(seeded_push(runs)[125.0][1].twin)
    '3 (2.5-3.5; 2 seeds)'
    """
    tw = seeded(push)
    out = {}
    for r in tw.first:
        rows = [push_rows(p[r]) for p in tw.results]
        peak, back = rows[0]
        out[r] = (
            Compared(peak.thesis, peak.linear, over_seeds([x[0].twin for x in rows], tw.seeds)),
            Compared(back.thesis, back.linear, over_seeds([x[1].twin for x in rows], tw.seeds)),
        )
    return out


def table_push(push: Mapping[float, PushResult] | Seeded[Mapping[float, PushResult]]) -> ComparisonTable:
    """Ch. 7.4: peak pitch after the push and the time to come back within :data:`RECOVERY_BAND` (the twin at every
    seed of ``push``)."""
    t, j, _ = PUSH
    table = side_by_side(
        f"Ch. 7.4: push rejection under SAS, impulse {j:g} N m s about pitch at {t:g} s (twin; the "
        "linear model has no torque input)",
        ["R", "measure"],
    )
    labels = ("peak pitch after the push (rad)", f"back within {RECOVERY_BAND:g} rad after (s)")
    for r, rows in seeded_push(push).items():
        for label, row in zip(labels, rows):
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
                    m.delay_margin_s,
                    stability(m.stable),
                    stability(m.stable_with_delay),
                ]
            )
    table.notes = [
        "Loop transfer L = -C_y(z) G(z): the compensator from the measurement to the control in series "
        "with the plant model (classical_margins). Delay margin: for a stable loop the smallest extra delay that "
        "brings a gain crossover onto -1; for an unstable one negative, minus the smallest advance that would. A "
        "stable loop can show a negative phase margin at a crossover where its open loop has unstable poles (an LQG "
        "compensator can have them); the closed loop column reads the closed-loop poles. 'one sample of computation "
        "delay' closes the loop with an extra z^-1."
    ]
    return table
