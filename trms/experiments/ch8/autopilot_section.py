"""Chapter 8's autopilot in the report: the choice of ``R`` (its scan table), the autopilot's tables and figures.

What they show is run by :mod:`trms.experiments.ch8.autopilot`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from trms.experiments.ch8.autopilot import (
    CONTROL_WEIGHTS,
    CONTROLLERS,
    INTEGRATOR_WEIGHTS,
    SCENARIOS,
    STATE_WEIGHTS,
    TARGETS,
    AutopilotRun,
    meets_targets,
)
from trms.experiments.ch8.autopilot_margins import GAIN_MARGIN_DB, PHASE_MARGIN_DEG, InputMargins
from trms.experiments.ch8.autopilot_tuning import TARGET_FRACTION, TUNING_SEEDS
from trms.present.figures import plot_series, save_figure
from trms.present.sections import FigureRef, Section, finite_or
from trms.present.tables import ComparisonTable, side_by_side
from trms.reference import VOLTAGE_LIMIT

__all__ = ["table_scan", "autopilot_figures", "section_8_autopilot"]


def table_scan(scan: Sequence[InputMargins], runs: Mapping[float, Mapping[str, AutopilotRun]]) -> ComparisonTable:
    """The autopilot's design beside its control weights scaled: each loop's margins on the twin's linearisation and
    its runs on the twin, against the targets.

    Examples
    --------
    >>> t = table_scan([InputMargins(1.0, (7.0, 9.0), (35.0, 60.0), True)], {})
    >>> t.rows[0][-1]
    'the design'
    """
    table = ComparisonTable(
        "Ch. 8: the MIMO LQG autopilot's design (per-channel weights), beside its control weights scaled",
        [
            "R scale",
            "gain margin u1 (dB)",
            "phase margin u1 (deg)",
            "gain margin u2 (dB)",
            "phase margin u2 (deg)",
            "closed loop",
            *(
                f"twin, {scen}: rise; settling (s); {'yaw' if scen.startswith('pitch') else 'pitch'} excursion (rad)"
                for scen in SCENARIOS
            ),
            "targets",
            "design",
        ],
    )

    def run_cell(run: AutopilotRun | None) -> str:
        if run is None:
            return "not run"
        if not run.measures:
            return run.status
        m = run.measures
        ts = finite_or(m["TS"], "not settled")
        return f"{m['TR']:.1f}; " + (f"{ts:.1f}" if isinstance(ts, float) else ts) + f"; {m['cross']:.3g}"

    for m in scan:
        s_runs = runs.get(m.scale, {})
        missed = [
            f"{scen}: {', '.join(meets_targets(scen, r.measures))}"
            for scen, r in s_runs.items()
            if r.measures and meets_targets(scen, r.measures)
        ]
        table.rows.append(
            [
                f"{m.scale:g}",
                *(finite_or(v, "no crossing") for i in (0, 1) for v in (m.gain_margin_db[i], m.phase_margin_deg[i])),
                "stable" if m.stable else "unstable",
                *(run_cell(s_runs.get(scen)) for scen in SCENARIOS),
                ("missed: " + "; ".join(missed)) if missed else ("met" if s_runs else "not run"),
                "the design" if m.scale == 1.0 else ("adequate margins" if m.adequate else "inadequate margins"),
            ]
        )
    targets = "; ".join(f"{scen}: " + ", ".join(f"{k} <= {v:g}" for k, v in t.items()) for scen, t in TARGETS.items())
    table.notes = [
        f"The design: Q = {STATE_WEIGHTS} on the angles, {INTEGRATOR_WEIGHTS} on their integrators, 1 on the rates "
        f"and rotor states, 0 on the delay line; R = diag{CONTROL_WEIGHTS} (u1, u2), tuned by a search flown on the "
        f"twin in moving air at seeds {', '.join(map(str, TUNING_SEEDS))} (trms.experiments.ch8.autopilot_tuning), "
        f"each target asked at {TARGET_FRACTION:.0%} of its limit, with margins; each row scales R.",
        f"Margins: the loop designed on the reduced model and closed around the twin's full linearisation at hover "
        f"(bending states and transport delay included), broken at each plant input with the other closed; adequate: "
        f"a gain margin of at least {GAIN_MARGIN_DB:g} dB (up or down) and a phase margin of at least "
        f"{PHASE_MARGIN_DEG:g} deg. The report, the robustness batch, `trms run` and the Gymnasium tasks' LQG "
        "baseline fly the design.",
        "The runs: on the twin in moving air, through the reference prefilter and the thrust-curve inversion; settling "
        f"in the noise band, the worst of the step and the return; targets (s, rad): {targets}.",
    ]
    return table


_LABELS = {
    "TR": "rise time (s)",
    "TS": "settling time, noise band (s)",
    "TS 5 %": "settling time, 5 % (s)",
    "overshoot": "overshoot (%)",
    "cross": "other axis' largest excursion (rad)",
    "rms u1": "RMS u1 (V)",
    "rms u2": "RMS u2 (V)",
    "TV": "total variation of u (V)",
}


def _table(res: Mapping[str, Mapping[tuple[str, str], AutopilotRun]]):
    table = side_by_side(
        "Ch. 8 future work: 2-DOF LQG autopilot against two SISO loops (per-channel weights)",
        ["scenario", "controller", "measure"],
    )
    for scen in SCENARIOS:
        for name in CONTROLLERS:
            a, b = res["linear"][(name, scen)], res["twin"][(name, scen)]
            for key, label in _LABELS.items():
                cells = [finite_or(r.measures[key], "not settled") if r.measures else r.status for r in (a, b)]
                note = ""
                if key == "cross":
                    note = (
                        "yaw moved by the pitch command: the u1 -> yaw coupling"
                        if scen.startswith("pitch")
                        else "pitch moved by the yaw command"
                    )
                table.rows.append([scen, name, label, "-", *cells, note])
    notes = []
    for w in ("linear", "twin"):
        for scen in SCENARIOS:
            m, s = res[w][("MIMO LQG", scen)], res[w][("two SISO loops", scen)]
            moved = "yaw" if scen.startswith("pitch") else "pitch"
            if m.measures and s.measures and s.measures["cross"] > 0:
                notes.append(
                    f"{w}, {scen}: the {moved} moves {m.measures['cross']:.3g} rad under the MIMO LQG against "
                    f"{s.measures['cross']:.3g} rad under the two SISO loops "
                    f"({m.measures['cross'] / s.measures['cross']:.0%})."
                )
    table.notes = notes + [
        "Design model: the twin's linearisation reduced to rigid-body and motor states (bending "
        "states residualised). The linear model column runs it on the full linearisation (18 states) "
        "with measurement noise; the twin adds quantisation, its ambient excitation and its nonlinear dynamics."
    ]
    return table


def autopilot_figures(twin: Mapping[tuple[str, str], AutopilotRun], folder: str | os.PathLike[str]) -> list[FigureRef]:
    """The twin's autopilot runs drawn into ``folder``, one figure a scenario: the tracked and cross-coupled angles
    and both inputs, per controller (a scenario where a controller did not run is left out).

    Parameters
    ----------
    twin : mapping
        :func:`autopilot_runs` on the twin.
    folder : path-like
        Where the PNG files go.

    Returns
    -------
    list of FigureRef

    Examples
    --------
    >>> import tempfile
    >>> from trms.experiments.ch8.autopilot import autopilot_runs
    >>> from trms.worlds import design_model, make_plant
    >>> runs = autopilot_runs(make_plant("linear", "2dof"), design_model("2dof"))
    >>> [f.path.name for f in autopilot_figures(runs, tempfile.mkdtemp())]
    ['ch8_pitch_twin.png', 'ch8_yaw_twin.png']
    """
    folder = Path(folder)
    figs = []
    for scen, (tracked, _) in SCENARIOS.items():
        recorded = {name: twin[(name, scen)].record for name in CONTROLLERS}
        runs = {name: rec for name, rec in recorded.items() if rec is not None}
        if len(runs) < len(recorded):
            continue
        first = next(iter(runs.values()))
        series = {"command": first.extras["reference"][:, tracked]}
        for name, rec in runs.items():
            dy = rec.deviations()[1]
            series[f"{name}: {rec.output_names[tracked]}"] = dy[:, tracked]
            series[f"{name}: {rec.output_names[1 - tracked]}"] = dy[:, 1 - tracked]
        inputs = {
            f"{name}: {rec.input_names[j]}": rec.extras["control"][:, j] for name, rec in runs.items() for j in (0, 1)
        }
        trim = first.operating_point.inputs
        limits = (
            float(np.max(-VOLTAGE_LIMIT - trim)),
            float(np.min(VOLTAGE_LIMIT - trim)),
        )  # the tighter of the two inputs
        figs.append(
            FigureRef(
                save_figure(
                    plot_series(
                        first.time,
                        series,
                        f"Twin 2-DOF, {scen}: MIMO LQG against two SISO loops",
                        "angle (rad, deviation)",
                        inputs,
                        limits=limits,
                    ),
                    folder / f"ch8_{scen.split()[0]}_twin.png",
                ),
                f"Twin under the {scen}: tracked and cross-coupled angles and both inputs, per controller.",
            )
        )
    return figs


def section_8_autopilot(
    res: Mapping[str, Mapping[tuple[str, str], AutopilotRun]],
    folder: str | os.PathLike[str],
    extra: list | None = None,
    scan: Sequence[InputMargins] | None = None,
    scan_records: Mapping[float, Mapping[str, AutopilotRun]] | None = None,
    extra_figures: Sequence[FigureRef] = (),
    figures: Sequence[FigureRef] | None = None,
) -> Section:
    """The chapter 8 section: the autopilot, its design beside scaled control weights (``scan``,
    :func:`~trms.experiments.ch8.autopilot_margins.margin_scan`, with the twin's ``scan_records``,
    :func:`~trms.experiments.ch8.autopilot.scan_runs`), and ``extra`` tables such as
    the robustness batch and the controller comparison, with their ``extra_figures``. ``figures``: the twin's
    :func:`autopilot_figures`, when already drawn (drawn into ``folder`` otherwise).
    """
    figs = autopilot_figures(res["twin"], folder) if figures is None else list(figures)
    paragraphs = [
        "A 2-DOF LQG autopilot for pitch and yaw together (the thesis's first suggestion for future work), designed on "
        "the twin's linearisation reduced to its rigid-body and motor states, against two SISO LQG loops designed on "
        "the u1 -> pitch and u2 -> yaw columns of the same model.",
    ]
    paragraphs.append(
        "Both designs use the autopilot's per-channel weights, tuned by a search flown on the twin against the targets "
        f"({', '.join(f'{scen}: ' + ', '.join(f'{k} <= {v:g}' for k, v in t.items()) for scen, t in TARGETS.items())}) "
        f"with a gain margin of at least {GAIN_MARGIN_DB:g} dB and a phase margin of at least {PHASE_MARGIN_DEG:g} deg "
        "at each plant input; the design table shows the margins and the runs on the twin beside scaled control "
        "weights."
    )
    choice = [table_scan(scan, scan_records or {})] if scan is not None else []
    return Section(
        "Chapter 8 (future work): 2-DOF LQG autopilot and robustness",
        paragraphs,
        [*choice, _table(res), *(extra or [])],
        [*figs, *extra_figures],
    )
