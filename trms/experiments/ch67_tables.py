"""Chapters 6 and 7 presented: Table 6.1, the rig's cases, the push, the loop margins, the ch. 7 findings.

Every builder here takes the results of :mod:`trms.experiments.ch67_lqg` (run on the linear model
and on the twin) and returns a :class:`~trms.present.tables.ComparisonTable`; the report, the
CLI and the tests call the same builders. Every note that says why a cell differs from the thesis
is computed from the same run: the cell under the alternative definitions that
:func:`~trms.experiments.ch67_lqg.summarise` measures (rise timed from the command edge, the first
step from rest, the other settling band), the amplitude at which the peak control would meet the
limit, or the loop's margins; where none brings the cell within 30 % of the thesis, the note says
"not explained". A ch. 7 finding the twin does not show is explained the same way
(:func:`findings`): by the command amplitude, or by the same loops on the twin's linearisation
without and with the thesis's 0.25 Hz mode (:mod:`trms.experiments.ch7_side_mode`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from trms.experiments.ch7_side_mode import VARIANTS, SideModeEvidence
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
    STOP_ANGLE,
    WANDER_WINDOW,
    CaseResult,
    Margins,
    PushResult,
)
from trms.present.figures import plot_series, save_figure
from trms.present.sections import FigureRef, Section
from trms.present.tables import ComparisonTable, format_cell, relative_difference, side_by_side
from trms.reference import (
    CHAPTER_7_OUTCOMES,
    CHAPTER_7_PREFILTER_OUTCOMES,
    LQG_WEIGHTS_R,
    PUSH_WEIGHTS_R,
    TABLE_6_1,
    VOLTAGE_LIMIT,
)

__all__ = [
    "EXPLAIN_ABOVE",
    "VERDICTS",
    "Finding",
    "table_6_1",
    "table_6_1_control",
    "amplitude_at_limit",
    "table_7",
    "table_push",
    "table_margins",
    "findings",
    "table_findings",
    "section",
]

#: Relative difference beyond which a cell must be explained.
EXPLAIN_ABOVE = 0.30
#: How a finding's explanation ends: explained by a measurement of this run, or not.
VERDICTS = ("explained", "not explained")
_WORLD = {"linear": "linear model", "twin": "twin"}


# ------------------------------------------------------------------------------------ Table 6.1
def _alternatives(s: Mapping[str, float | str], key: str) -> dict[str, float]:
    """The cell ``key`` ("TR"/"TS") under the alternative definitions measured in the same run."""
    if key == "TR":
        return {"timed from the command edge": float(s["TR edge"]), "first step, from rest": float(s["TR first"])}
    other = "TS wide" if s["band"] == NARROW_BAND else "TS narrow"
    label = "in the 5 % band" if other == "TS wide" else "in the 2 % band"
    return {label: float(s[other]), "first step, from rest (2 % band)": float(s["TS first"])}


def _more(a: Mapping[str, float | str], b: Mapping[str, float | str], key: str) -> bool:
    """Run ``a``'s measure ``key`` is larger than run ``b``'s."""
    return float(a[key]) > float(b[key])


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
    table = side_by_side(
        f"Table 6.1: SAS and CSAS (Q = I), square wave +-{DEFAULT_AMPLITUDE:g} rad; controllers designed on eq. (3.11)",
        ["R", "case", "measure"],
    )
    flagged: list[str] = []
    for (r, case), printed in TABLE_6_1.items():
        if (r, case) not in lin or (r, case) not in twin:
            continue
        for j, (key, label) in enumerate((("TR", "TR (s)"), ("TS", "TS (s)"), ("control", "control"))):
            cells, marks = [], []
            for world, res in (("linear", lin[(r, case)]), ("twin", twin[(r, case)])):
                cell, note = _cell_note(world, r, case, key, res, printed[j], (margins or {}).get(world))
                cells.append(cell)
                if note:
                    if note not in flagged:
                        flagged.append(note)
                    marks.append(f"note {flagged.index(note) + 1}")
            table.rows.append([r, case, label, printed[j], *cells, ", ".join(marks)])
    table.notes = [
        f"TR: 10-90 % rise; TS: settling in the 2 % band (or the 5 % band where the run's measured wander does not "
        f"fit in the 2 % band); both the largest over the full-swing steps of a square wave of period "
        f"{DEFAULT_PERIOD:g} s over {DEFAULT_DURATION:g} s. Control: the thesis's 'high' means beyond the actuator "
        "limit at its square wave, whose amplitude it does not print; here the amplitude at which the peak control "
        f"meets the +-10 V limit, scaled from this run's +-{DEFAULT_AMPLITUDE:g} rad (the next table reads it at the "
        f"PCI set-up's +-{PCI_LIMIT:g} V and for a slower and a faster estimator). "
        f"Estimator Qe = {ESTIMATOR_QE:g} I, Re = {ESTIMATOR_RE:g}.",
    ] + [f"note {i + 1}: {n}" for i, n in enumerate(flagged)]
    return table


def amplitude_at_limit(res: CaseResult, limit: float, trim: float) -> float:
    """The square-wave amplitude (rad) at which a run's peak control would meet the absolute limit ``+-limit`` (V)
    about ``trim`` (V), scaled from the run's own amplitude (the loop is linear in the command up to saturation).

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import lqg_cases, pitch_plant
    >>> res = lqg_cases(pitch_plant(), pitch_plant().system, [75.0], ["SAS"])[(75.0, "SAS")]
    >>> round(amplitude_at_limit(res, 10.0, 0.0) / amplitude_at_limit(res, 5.0, 0.0), 6)
    2.0
    """
    s = res.summary
    room = min(limit - trim, limit + trim)
    return room / float(s["peak"]) * float(s["step"]) / 2.0


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
                cells.append(amplitude_at_limit(base, limit, trim) if _ok(base) else base.status)
            for k in scales:
                res = by_scale.get(k, {}).get((r, case))
                cells.append(
                    float(res.summary["peak"]) / (float(res.summary["step"]) / 2.0)
                    if res is not None and _ok(res)
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


def table_push(push: Mapping[float, PushResult]) -> ComparisonTable:
    """Ch. 7.4: peak pitch after the push and the time to come back within :data:`RECOVERY_BAND`."""
    t, j, _ = PUSH
    table = side_by_side(
        f"Ch. 7.4: push rejection under SAS, impulse {j:g} N m s about pitch at {t:g} s (twin; the "
        "linear model has no torque input)",
        ["R", "measure"],
    )
    for r, res in push.items():
        peak = res.peak if np.isfinite(res.peak) else res.status
        back = res.recovery if np.isfinite(res.recovery) else res.status
        table.rows.append([r, "peak pitch after the push (rad)", "rejected (figs. 7.17-7.19)", "-", peak, ""])
        table.rows.append([r, f"back within {RECOVERY_BAND:g} rad after (s)", "rejected", "-", back, ""])
    return table


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
            stable = "stable" if m.stable else "unstable"
            table.rows.append(
                [
                    r,
                    f"{_WORLD[world]} ({models[world]})",
                    m.gain_margin_db,
                    m.phase_margin_deg,
                    m.delay_margin_s if m.stable else "unstable",
                    stable,
                    "stable" if m.stable_with_delay else "unstable",
                ]
            )
    table.notes = [
        "Loop transfer L = -C_y(z) G(z): the compensator from the measurement to the control in series "
        "with the plant model; delay margin = the smallest phase margin / crossover frequency over every "
        "gain crossover. 'one sample of computation delay' closes the loop with an extra z^-1."
    ]
    return table


# ------------------------------------------------------------------------------ ch. 7 findings
class Finding(tuple):
    """``(finding, criterion, shown, measurement, explanation)``: one ch. 7 finding tested on one world.

    ``explanation`` is empty when the world shows the finding; otherwise it says, with numbers
    measured in the same run, why not, and holds one of :data:`VERDICTS`.
    """

    __slots__ = ()

    def __new__(cls, finding: str, criterion: str, shown: bool, measurement: str, explanation: str = "") -> Finding:
        return super().__new__(cls, (finding, criterion, bool(shown), measurement, explanation))

    @property
    def explanation(self) -> str:
        """Why the world does not show the finding (empty when it does)."""
        return str(self[4])

    @property
    def shown(self) -> bool:
        """Whether the world shows the finding by its criterion."""
        return bool(self[2])


def _ok(res: CaseResult) -> bool:
    return res.status in ("settled", "not settled") and bool(res.summary)


def _saturation(res: CaseResult) -> Finding:
    """R = 75 SAS saturates and overshoots; when not, the command amplitude where its peak control meets the limit."""
    name, criterion = "R = 75 SAS saturates and overshoots", "commanded control beyond the limit and overshoot >= 10 %"
    if not _ok(res):
        return Finding(name, criterion, False, f"the run {res.status}", f"the run {res.status}: not explained.")
    s = res.summary
    overshoot = float(s["overshoot"])
    shown = s["control"] == "high" and overshoot >= 10.0
    measurement = f"peak |u| {s['peak']:.3g} V against {s['limit']:.3g} V; overshoot {s['overshoot']:.1f} %"
    if shown:
        return Finding(name, criterion, True, measurement)
    amplitude = float(s["step"]) / 2.0
    reach = float(s["limit"]) / float(s["peak"]) * amplitude
    trim = VOLTAGE_LIMIT - float(s["limit"])  # the limit is the room of +-10 V about the trim
    reach_pci = amplitude_at_limit(res, PCI_LIMIT, trim)
    why = []
    if s["control"] != "high":
        why.append(
            f"the peak |u| is {float(s['peak']) / float(s['limit']):.0%} of the limit at this run's "
            f"+-{amplitude:g} rad square wave; it grows with the command amplitude, which the thesis does not "
            f"print: scaled from this run it meets the limit at +-{reach:.2g} rad"
            + (f", beyond the {STOP_ANGLE:g} rad stops" if reach >= STOP_ANGLE else "")
            + f" (at the PCI set-up's +-{PCI_LIMIT:g} V, from +-{reach_pci:.2g} rad"
            + (", within the stops: the finding holds there above that amplitude)" if reach_pci < STOP_ANGLE else ")")
        )
    if overshoot < 10.0:
        why.append(f"the overshoot is {overshoot:.1f} % (criterion 10 %)")
    verdict = "explained" if overshoot >= 10.0 else "not explained"
    return Finding(name, criterion, False, measurement, "; ".join(why) + f": {verdict} by the command amplitude.")


#: How a run measure is printed in the findings: label, format, unit.
_MEASURES = {"overshoot": ("overshoot", ".1f", "%"), "TS": ("TS", ".3g", "s"), "peak": ("peak |u|", ".2g", "V")}


def _against(
    res: Mapping[tuple[float, str], CaseResult], rig: Sequence[float], case: str, base: str, keys: Sequence[str]
) -> tuple[bool, str, dict[str, float]]:
    """Whether ``case`` is larger than ``base`` on every measure of ``keys`` at every R run on the rig, the per-R
    measurement, and the mean differences (``case`` minus ``base``, NaN when no R ran)."""
    larger, parts = True, []
    deltas: dict[str, list[float]] = {k: [] for k in keys}
    for r in rig:
        a, b = res[(r, base)], res[(r, case)]
        if not (_ok(a) and _ok(b)):
            larger = False
            parts.append(f"R = {r:g}: {a.status}/{b.status}")
            continue
        sa, sb = a.summary, b.summary
        larger &= all(_more(sb, sa, k) for k in keys)
        for k in keys:
            deltas[k].append(float(sb[k]) - float(sa[k]))
        parts.append(
            f"R = {r:g}: "
            + ", ".join(
                f"{_MEASURES[k][0]} {sb[k]:{_MEASURES[k][1]}} vs {sa[k]:{_MEASURES[k][1]}} {_MEASURES[k][2]}"
                for k in keys
            )
        )
    means = {k: float(np.mean(v)) if v else float("nan") for k, v in deltas.items()}
    return larger, "; ".join(parts), means


def _lpf_worse(res: Mapping[tuple[float, str], CaseResult], rig: Sequence[float]) -> tuple[bool, str, tuple]:
    """The LPF criterion on one set of runs: shown, the per-R measurement, mean differences (overshoot %, TS s)."""
    worse, parts, means = _against(res, rig, "CSAS LPF 0.3 Hz", "CSAS LPF 0.2 Hz", ("overshoot", "TS"))
    return bool(worse and rig), parts, (means["overshoot"], means["TS"])


def _lpf_explanation(evidence: SideModeEvidence, rig: Sequence[float]) -> str:
    """Why the twin does not show "LPF 0.3 Hz worse": its linearisation without and with the thesis's 0.25 Hz mode."""
    shown = {}
    lines = []
    for name in VARIANTS:
        ok, parts, (d_os, d_ts) = _lpf_worse(evidence.results[name], rig)
        shown[name] = ok
        low, high, f_main = evidence.peaks[name]
        lines.append(
            f"on {name} (largest |G| within 0.04 Hz of {evidence.frequency_hz:g} Hz {low:.3g} rad/V against "
            f"{high:.3g} rad/V at {f_main:.3f} Hz): {'shown' if ok else 'not shown'}, the 0.3 Hz prefilter adding "
            f"{d_os:+.1f} % overshoot and {d_ts:+.2g} s settling on average ({parts})"
        )
    plain, moded = (shown[v] for v in VARIANTS)
    calm, calm_parts, (c_os, c_ts) = _lpf_worse(evidence.still_air, rig) if evidence.still_air else (False, "", (0, 0))
    if evidence.still_air:
        lines.append(
            f"on the nonlinear, quantised twin in still air: {'shown' if calm else 'not shown'}, the 0.3 Hz "
            f"prefilter adding {c_os:+.1f} % overshoot and {c_ts:+.2g} s settling on average ({calm_parts})"
        )
    pf = evidence.prefilter_db
    head = (
        f"at {evidence.frequency_hz:g} Hz the 0.3 Hz prefilter attenuates the command by "
        f"{-pf['CSAS LPF 0.3 Hz']:.1f} dB and the 0.2 Hz one by {-pf['CSAS LPF 0.2 Hz']:.1f} dB. The same loops "
        "without the twin's ambient excitation and nonlinearity, "
        + "; and ".join(lines)
        + f" (the mode: DC gain {evidence.gain:.3g} rad/V, damping {evidence.damping:.3f}, its peak equal to the "
        "main mode's). "
    )
    if moded and not plain:
        verdict = "explained: the finding needs the 0.25 Hz mode the twin does not have."
    elif moded and plain and evidence.still_air and calm:
        verdict = (
            "explained: the twin's own small-signal model shows it, by less than the thesis's mode makes it, and so "
            "does the twin in still air: the ambient excitation of the twin's run hides it."
        )
    elif moded and plain and evidence.still_air:
        verdict = (
            "explained in part: the twin's own small-signal model shows it, by less than the thesis's mode makes it, "
            "but the twin in still air does not show it at every R (above): the ambient excitation does not hide it "
            "alone; the twin's nonlinearity or quantisation hides an effect that small at one R at least (not "
            "separated further)."
        )
    elif moded and plain:
        verdict = "not explained: the twin's own small-signal model shows it, by less than the thesis's mode makes it."
    else:
        verdict = "not explained: the loop does not show it even with the thesis's 0.25 Hz mode."
    return head + verdict


def findings(
    res: Mapping[tuple[float, str], CaseResult],
    push: Mapping[float, PushResult] | None,
    margins: Mapping[float, Margins],
    evidence: SideModeEvidence | None = None,
) -> list[Finding]:
    """Each finding of the thesis's ch. 7 tested on one world's runs, with its criterion and measurement.

    A finding the world does not show carries an explanation measured in the same run: the command
    amplitude at which R = 75 would saturate, and for the low-pass finding the same loops on the
    twin's linearisation without and with the thesis's 0.25 Hz mode (``evidence``).

    Parameters
    ----------
    res : mapping
        :func:`trms.experiments.ch67_lqg.lqg_cases` on one world (R = 75, 1 and 125 at least).
    push : mapping or None
        :func:`trms.experiments.ch67_lqg.push_rejection` (None: no torque input, the finding is untested).
    margins : mapping
        That world's :func:`trms.experiments.ch67_lqg.loop_margins` by R.
    evidence : SideModeEvidence, optional
        :func:`trms.experiments.ch7_side_mode.prefilter_evidence` (the twin's); without it a missing
        low-pass finding is "not explained".

    Returns
    -------
    list of Finding
        In the thesis's order: R = 75 saturates, R = 1 unstable, R = 125 best, LPF 0.3 Hz worse, BSF
        poor, push rejected.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import lqg_cases, loop_margins, pitch_plant
    >>> p = pitch_plant(noise_std=1e-3)
    >>> res = lqg_cases(p, p.system, [75.0, 1.0, 125.0])
    >>> f = findings(res, None, {1.0: loop_margins(p.system, p.system, 1.0)})
    >>> f[1][0], f[1].shown
    ('R = 1 SAS unstable on the rig', True)
    """
    out = [_saturation(res[(75.0, "SAS")])]
    s1, m1 = res[(1.0, "SAS")], margins[1.0]
    out.append(
        Finding(
            "R = 1 SAS unstable on the rig",
            "the run hits the stops or diverges, or its loop is unstable with one sample of computation delay",
            s1.status in ("hit the stops", "diverged") or not m1.stable_with_delay,
            f"run: {s1.status}; phase margin {m1.phase_margin_deg:.0f} deg, "
            + (f"delay margin {m1.delay_margin_s:.3g} s" if m1.stable else "closed loop unstable")
            + f", with one sample of delay {'stable' if m1.stable_with_delay else 'unstable'}",
        )
    )
    rig = [r for r in (75.0, 100.0, 125.0) if (r, "SAS") in res]
    settled = {r: float(res[(r, "SAS")].summary["overshoot"]) for r in rig if _ok(res[(r, "SAS")])}
    best = min(settled, key=settled.__getitem__) if settled else None
    out.append(
        Finding(
            "R = 125 SAS best",
            f"smallest SAS overshoot among R = {', '.join(f'{r:g}' for r in rig)}",
            best == 125.0,
            "; ".join(f"R = {r:g}: {v:.1f} %" for r, v in settled.items()) or "none settled",
        )
    )
    worse, lpf_parts, _ = _lpf_worse(res, rig)
    why = ""
    if not worse:
        why = _lpf_explanation(evidence, rig) if evidence is not None else "no alternative measured: not explained."
    out.append(
        Finding(
            "LPF 0.3 Hz worse than LPF 0.2 Hz",
            "for every R run on the rig: larger overshoot and longer settling with the 0.3 Hz prefilter",
            worse,
            lpf_parts,
            why,
        )
    )
    poor, bsf_parts, _ = _against(res, rig, "CSAS BSF 0.34 Hz", "CSAS LPF 0.2 Hz", ("overshoot", "TS", "peak"))
    out.append(
        Finding(
            "BSF 0.34 Hz poor",
            "for every R run on the rig, against LPF 0.2 Hz: larger overshoot, longer settling and larger peak control",
            poor,
            bsf_parts,
            "" if poor else "not explained.",
        )
    )
    if push is None:
        out.append(
            Finding(
                "push rejected by all three controllers",
                f"back within {RECOVERY_BAND:g} rad before the run ends, R = 75, 100, 125",
                False,
                "no torque input",
                "the linear model has no torque input, so the push cannot be applied: not explained.",
            )
        )
    else:
        ok = all(p.status == "recovered" for p in push.values()) and set(PUSH_WEIGHTS_R) <= set(push)
        out.append(
            Finding(
                "push rejected by all three controllers",
                f"back within {RECOVERY_BAND:g} rad before the run ends, R = 75, 100, 125",
                ok,
                "; ".join(f"R = {r:g}: {p.status} after {format_cell(p.recovery)} s" for r, p in push.items()),
                "" if ok else "not explained.",
            )
        )
    return out


def table_findings(lin: Sequence[Finding], twin: Sequence[Finding]) -> ComparisonTable:
    """The ch. 7 findings table: each finding, its criterion, whether each world shows it, and why not.

    Examples
    --------
    >>> f = Finding("a finding", "its criterion", False, "x = 1", "x < 2: not explained.")
    >>> table_findings([f], [f]).rows[0][3:5]
    ['not shown', 'x = 1']
    """
    table = ComparisonTable(
        "Ch. 7 findings: does each world show them?",
        [
            "finding (thesis ch. 7)",
            "criterion",
            "linear model",
            "twin",
            "measurement (twin)",
            "why the twin does not show it (measured in this run)",
            "measurement (linear model)",
        ],
    )
    for a, b in zip(lin, twin):
        table.rows.append(
            [
                b[0],
                b[1],
                "shown" if a.shown else "not shown",
                "shown" if b.shown else "not shown",
                b[3],
                b.explanation or "-",
                a[3],
            ]
        )
    missing = [f for f in twin if not f.shown]
    explained = [f for f in missing if f.explanation and "not explained" not in f.explanation]
    table.notes = [
        f"The twin shows {sum(f.shown for f in twin)} of {len(twin)} findings; the linear model "
        f"{sum(f.shown for f in lin)}. Of the {len(missing)} the twin does not show, {len(explained)} are "
        f"explained by a measurement of this run and {len(missing) - len(explained)} are not."
    ]
    return table


# ------------------------------------------------------------------------------------- section
def section(
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
) -> Section:
    """The chapters 6 and 7 section: Table 6.1, the rig's cases, the push, the margins, the findings, figures.

    ``evidence`` (:func:`trms.experiments.ch7_side_mode.prefilter_evidence` on the twin) explains a
    missing low-pass finding; see :func:`findings`. ``estimators`` (``{world: {Qe scale: lqg_cases(...)}}``,
    the thesis's estimator added from ``lin``/``twin``) and ``trim`` (V) add Table 6.1's control sensitivity
    (:func:`table_6_1_control`) as the last table.
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
    t61 = table_6_1(lin, twin, margins)
    shown = [f[0] for f in f_twin if f.shown]
    missed = [
        f"{f[0]} ({'not explained' if 'not explained' in f.explanation else 'explained'}, see the findings table)"
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
    return Section(
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
