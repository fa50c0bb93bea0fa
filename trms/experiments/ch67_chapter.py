"""Chapters 6 and 7 assembled: the section (tables of :mod:`trms.experiments.ch67_tables` and
:mod:`trms.experiments.ch7_findings`, figures, conclusions) and the typed rows the report's headline reads
(:class:`Chapter67`).

The twin's runs may be given at every seed of the report (:class:`~trms.present.seeds.Seeded`): Table 6.1's twin
cells, the push and the findings are then measured at each seed and judged over them; the figures, the rig's cases
and the explanations' evidence (the side-mode loops, the PCI flight, the R = 1 amplitudes' small-signal loop) are
the run's own seed's.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from trms.experiments.ch7_findings import Finding, findings, shown_at, table_findings
from trms.experiments.ch7_side_mode import SideModeEvidence
from trms.experiments.ch67_amplitudes import amplitude_note
from trms.experiments.ch67_lqg import (
    DEFAULT_AMPLITUDE,
    ESTIMATOR_QE,
    ESTIMATOR_RE,
    STOP_ANGLE,
    CaseResult,
    Margins,
    PushResult,
)
from trms.experiments.ch67_tables import (
    Cases,
    Compared,
    margin_text,
    render_6_1,
    rows_6_1,
    seeded_push,
    table_6_1_control,
    table_7,
    table_margins,
    table_push,
)
from trms.present.figures import plot_series, save_figure
from trms.present.sections import FigureRef, Section
from trms.present.seeds import Seeded, seeded
from trms.present.tables import ComparisonTable
from trms.reference import LQG_WEIGHTS_R

__all__ = ["TwinEvidence", "Chapter67", "chapter"]


@dataclass
class TwinEvidence:
    """What the twin's notes and findings read beside its runs (the run's own seed unless said).

    Attributes
    ----------
    side_mode : SideModeEvidence, optional
        :func:`~trms.experiments.ch7_side_mode.prefilter_evidence`: the low-pass finding's explanation.
    flight : tuple, optional
        :func:`~trms.experiments.ch7_findings.pci_flight`: the saturation finding's check.
    amplitudes : Seeded or dict, optional
        R = 1 SAS at the amplitudes of :func:`~trms.experiments.ch67_amplitudes.amplitude_runs`, at every seed.
    linearised : dict
        :func:`~trms.experiments.ch67_amplitudes.linearised_runs`: the R = 1 note's check.
    """

    side_mode: SideModeEvidence | None = None
    flight: tuple[float, CaseResult] | None = None
    amplitudes: Seeded[dict[float, CaseResult]] | dict[float, CaseResult] | None = None
    linearised: dict[float, CaseResult] = field(default_factory=dict)


@dataclass
class Chapter67:
    """The chapters 6 and 7 section and the typed rows its key figures are read from.

    Attributes
    ----------
    section : Section
        Table 6.1, the rig's cases, the push, the margins, the findings (and Table 6.1's control sensitivity), with
        the figures.
    table_6_1 : dict
        Table 6.1's rows by ``(R, case, measure)`` (:func:`~trms.experiments.ch67_tables.rows_6_1`).
    push : dict
        The time back within the recovery band after each push, by R
        (:func:`~trms.experiments.ch67_tables.seeded_push`).
    margins : mapping
        ``{world: {R: Margins}}`` the margins table shows.
    findings : dict
        ``{"linear": [Finding, ...], "twin": [Finding, ...] or Seeded}``
        (:func:`trms.experiments.ch7_findings.findings`) the findings table shows.
    """

    section: Section
    table_6_1: dict[tuple[float, str, str], Compared]
    push: dict[float, Compared]
    margins: Mapping[str, Mapping[float, Margins]]
    findings: dict[str, list[Finding] | Seeded[list[Finding]]]


def _stops_caption(case: CaseResult) -> str:
    """When a run was at the stops (its record's true pitch at or beyond them), for a figure's caption."""
    rec = case.record
    if rec is None or case.status != "hit the stops":
        return ""
    angles = rec.extras.get("true_angles")
    pitch = angles[:, 0] if angles is not None else rec.deviations()[1][:, 0]
    at = np.flatnonzero(np.abs(pitch) >= STOP_ANGLE)
    if at.size == 0:
        return ""
    return (
        f" The twin's run is at its stops (|pitch| >= {STOP_ANGLE:g} rad) for {at.size * rec.sample_time:.1f} s "
        "between "
        f"t = {rec.time[at[0]]:.1f} and {rec.time[at[-1]]:.1f} s, and settles between those times: its status names "
        "the worst of the run."
    )


def _figures_67(lin: Cases, first: Cases, pushes: Seeded, folder: Path) -> list[FigureRef]:
    """The chapter's figures: four cases on both worlds (figs. 6.6-7.16), the push on the twin (figs. 7.17-7.19)."""
    figs = []
    for r, case in ((125.0, "SAS"), (125.0, "CSAS LPF 0.2 Hz"), (75.0, "SAS"), (1.0, "SAS")):
        if (r, case) not in first:
            continue
        a, b = lin[(r, case)], first[(r, case)]
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
                        {"linear model u": rec_a.extras["control"][:, 0], "twin u": rec_b.extras["control"][:, 0]},
                        limits=(-lim, lim) if lim else None,
                    ),
                    folder / f"ch67_R{r:g}_{slug}.png",
                ),
                f"{case} with R = {r:g}: pitch and commanded control on the linear model and on the twin; "
                f"dashed: the actuator limits (deviation V).{_stops_caption(b)}",
            )
        )
    recs = {
        f"R = {r:g} ({p.status})": p.record.deviations()[1][:, 0]
        for r, p in pushes.first.items()
        if p.record is not None
    }
    if recs:
        one = next(p.record for p in pushes.first.values() if p.record is not None)
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        one.time,
                        recs,
                        "Twin: push on the beam at 19 s under SAS (figs. 7.17-7.19)",
                        "pitch (rad, deviation)",
                    ),
                    folder / "ch7_push_twin.png",
                ),
                "Twin pitch holding hover under SAS while the beam is pushed at 19 s.",
            )
        )
    return figs


def _conclusion_67(
    f_twin: Seeded, t61: ComparisonTable, margins: Mapping[str, Mapping[float, Margins]], n: int
) -> list[str]:
    """The chapter's conclusion: the findings shown at every seed, at some, at none; Table 6.1's notes counted; R = 1
    on eq. (3.11)."""
    counts = shown_at(f_twin)
    shown = [f.name for f, (k, m) in zip(f_twin.first, counts) if k == m]
    missed = [
        f"{f.name} ({'explained in part' if f.partly else 'explained' if f.explained else 'not explained'}, see the "
        "findings table)"
        for f, (k, _) in zip(f_twin.first, counts)
        if k == 0
    ]
    some = [f"{f.name} ({k} of {m})" for f, (k, m) in zip(f_twin.first, counts) if 0 < k < m]
    m1 = margins["linear"].get(1.0)
    conclusion = [
        f"The twin shows {len(shown)} of {len(counts)} ch. 7 findings"
        + (f" at every one of its {n} seeds" if n > 1 else "")
        + f": {', '.join(shown) or 'none'}."
        + (f" Not shown at any seed: {'; '.join(missed)}." if missed else "")
        + (f" Shown at some seeds only: {'; '.join(some)}." if some else ""),
        f"Table 6.1, its notes: {sum(1 for n in t61.notes if 'explained by' in n and 'not explained' not in n)} cells "
        f"explained by a measurement of the same runs that passes its check, "
        f"{sum(1 for n in t61.notes if 'not explained' in n)} not explained, "
        f"{sum(1 for n in t61.notes if 'inconclusive at' in n)} inconclusive over the seeds; its control column is "
        "a sensitivity (the command amplitude at which each loop meets the actuator limit), not a verdict.",
    ]
    if m1 is not None:
        conclusion.append(
            f"R = 1 on eq. (3.11): {margin_text(m1)}; the thesis's rig, computing with at least one sample of delay, "
            "was unstable there though its simulation settled."
        )
    return conclusion


def chapter(
    lin: Cases,
    twin: Cases | Seeded[Cases],
    push: Mapping[float, PushResult] | Seeded[Mapping[float, PushResult]],
    margins: Mapping[str, Mapping[float, Margins]],
    margin_models: Mapping[str, str],
    folder: str | os.PathLike[str],
    weights: Sequence[float] = LQG_WEIGHTS_R,
    evidence: TwinEvidence | None = None,
    estimators: Mapping[str, Mapping[float, Cases]] | None = None,
    trim: float = 0.0,
) -> Chapter67:
    """The chapters 6 and 7 section (Table 6.1, the rig's cases, the push, the margins, the findings, figures) with its
    typed rows.

    ``evidence`` (:class:`TwinEvidence`) explains a missing finding and the R = 1 cells; see
    :func:`trms.experiments.ch7_findings.findings` and :mod:`trms.experiments.ch67_amplitudes`. ``estimators``
    (``{world: {Qe scale: lqg_cases(...)}}``, the thesis's estimator added from ``lin``/``twin``) and ``trim`` (V)
    add Table 6.1's control sensitivity (:func:`~trms.experiments.ch67_tables.table_6_1_control`) as the last table.

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
    >>> c.table_6_1[(75.0, "SAS", "TR")].thesis, len(c.findings["twin"].first), len(c.section.tables)
    (3.0, 7, 5)
    """
    folder = Path(folder)
    evidence = evidence or TwinEvidence()
    tw, pushes = seeded(twin), seeded(push)
    first = tw.first
    figs = _figures_67(lin, first, pushes, folder)
    f_lin = findings(lin, None, margins["linear"])
    f_twin = Seeded(
        tw.seeds,
        tuple(
            findings(runs, pushed, margins["twin"], evidence.side_mode, evidence.flight)
            for runs, pushed in zip(tw.results, pushes.results)
        ),
    )
    status_notes = {}
    if evidence.amplitudes is not None and all((1.0, "SAS") in t for t in tw.results):
        amps = seeded(evidence.amplitudes)
        joined = Seeded(
            tw.seeds, tuple({**a, DEFAULT_AMPLITUDE: t[(1.0, "SAS")]} for a, t in zip(amps.results, tw.results))
        )
        status_notes[(1.0, "SAS")] = amplitude_note("R = 1, SAS, twin", joined, evidence.linearised)
    rows, notes = rows_6_1(lin, tw, margins, status_notes)
    t61 = render_6_1(rows, notes)
    n = len(tw.seeds)
    conclusion = _conclusion_67(f_twin, t61, margins, n)
    section = Section(
        "Chapters 6 and 7: LQG (SAS and CSAS) on the linear model and on the twin",
        [
            f"Integral LQG (the cost J of eq. 6.34, Q = I, estimator Qe = {ESTIMATOR_QE:g} I, Re = {ESTIMATOR_RE:g}, "
            "current estimator, anti-windup) designed on eq. (3.11) for each R, with and without the command "
            f"prefilters, tracking a square wave of +-{DEFAULT_AMPLITUDE:g} rad. The same controllers run on the "
            "linear model and on the twin"
            + (f", the twin at {n} seeds ({', '.join(str(s) for s in tw.seeds)})." if n > 1 else "."),
        ],
        [
            t61,
            table_7(lin, first, weights),
            table_push(pushes),
            table_margins(margins, margin_models),
            table_findings(f_lin, f_twin),
            *(
                [
                    table_6_1_control(
                        {w: {1.0: base, **estimators.get(w, {})} for w, base in (("linear", lin), ("twin", first))},
                        trim,
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
        {r: rows2[1] for r, rows2 in seeded_push(pushes).items()},
        margins,
        {"linear": f_lin, "twin": f_twin},
    )
