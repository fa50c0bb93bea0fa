"""Table 6.1's R = 1 loop at several command amplitudes, on the twin and on the twin's linearisation.

Under R = 1 SAS the twin hits its stops at the table's square wave
(:data:`~trms.experiments.ch67_lqg.DEFAULT_AMPLITUDE` rad), where eq. (3.11) settles in the thesis's 5-6 s. What the
twin does at smaller amplitudes is measured at every seed (:func:`amplitude_runs`), and the same controller is flown
on the twin's linearisation at hover, without noise or nonlinearity (:func:`linearised_runs`).
:func:`amplitude_note` writes the cell's note: the twin's response at each amplitude, measured, and an explanation
by the twin's small-signal loop only where its own check passes -- the linearised loop's overshoot at the smallest
amplitude within 30 % of the twin's (the median over the seeds), and the linearised loop reaching the stops at the
table's amplitude exactly when the twin does at every seed.
"""

from __future__ import annotations

from collections.abc import Sequence

import control
import numpy as np

from trms.experiments.ch7_side_mode import loop_plant
from trms.experiments.ch67_lqg import DEFAULT_AMPLITUDE, STOP_ANGLE, CaseResult, lqg_cases, without_records
from trms.plant import Plant
from trms.present.seeds import Seeded, seeded
from trms.present.tables import EXPLAIN_ABOVE, relative_difference

__all__ = ["AMPLITUDES", "amplitude_runs", "linearised_runs", "amplitude_note"]

#: Square-wave amplitudes (rad) the R = 1 loop is flown at beside the table's own.
AMPLITUDES = (0.02, 0.05)


def amplitude_runs(
    plant: Plant,
    model: control.StateSpace,
    seed: int = 0,
    amplitudes: Sequence[float] = AMPLITUDES,
    r_weight: float = 1.0,
    case: str = "SAS",
) -> dict[float, CaseResult]:
    """The ``(R, case)`` loop designed on ``model`` flown on ``plant`` at each square-wave amplitude (rad), records
    dropped.

    Examples
    --------
    >>> from trms.experiments.ch67_lqg import pitch_plant
    >>> runs = amplitude_runs(pitch_plant(), pitch_plant().system)
    >>> sorted(runs), runs[0.02].status
    ([0.02, 0.05], 'settled')
    """
    out = {}
    for a in amplitudes:
        out[float(a)] = without_records(lqg_cases(plant, model, [r_weight], [case], amplitude=a, seed=seed))[
            (float(r_weight), case)
        ]
    return out


def linearised_runs(
    model: control.StateSpace,
    amplitudes: Sequence[float] = (*AMPLITUDES, DEFAULT_AMPLITUDE),
    r_weight: float = 1.0,
    case: str = "SAS",
    twin=None,
) -> dict[float, CaseResult]:
    """The same loop on the twin's linearisation at hover (:func:`~trms.experiments.ch7_side_mode.loop_plant`, no
    measurement noise), at each amplitude: what the twin's small-signal model does with the controller.

    Examples
    --------
    >>> from trms.worlds import design_model
    >>> runs = linearised_runs(design_model("1dof"), (0.02,))
    >>> runs[0.02].status, 50.0 < runs[0.02].summary["overshoot"] < 100.0
    ('settled', True)
    """
    from trms.twin import Twin

    twin = twin if twin is not None else Twin("1dof", float(model.dt))
    return amplitude_runs(loop_plant(twin, noise_std=0.0), model, 0, amplitudes, r_weight, case)


def _range(values: list[float], fmt: str = ".3g") -> str:
    lo, hi = min(values), max(values)
    return f"{lo:{fmt}}" if f"{lo:{fmt}}" == f"{hi:{fmt}}" else f"{lo:{fmt}}-{hi:{fmt}}"


def _at(runs: list[CaseResult], amplitude: float) -> str:
    """What the runs at one amplitude did, over the seeds."""
    statuses: dict[str, int] = {}
    for c in runs:
        statuses[c.status] = statuses.get(c.status, 0) + 1
    said = ", ".join(f"{s} at {k}" for s, k in statuses.items())
    measured = [c.summary for c in runs if c.summary]
    if not measured:
        return f"+-{amplitude:g} rad: {said}"
    return (
        f"+-{amplitude:g} rad: {said}, overshoot {_range([float(s['overshoot']) for s in measured], '.0f')} %, "
        f"largest |pitch| {_range([float(s['excursion']) for s in measured], '.2g')} rad, peak |u| "
        f"{_range([float(s['peak']) for s in measured], '.2g')} V"
    )


def amplitude_note(
    where: str, twin: Seeded[dict[float, CaseResult]] | dict[float, CaseResult], linearised: dict[float, CaseResult]
) -> str:
    """The note on the twin's R = 1 cell: its response at each amplitude over the seeds, and whether the twin's
    small-signal loop explains it (module docstring).

    Parameters
    ----------
    where : str
        The cell, for the note.
    twin : Seeded or dict
        The twin's runs by amplitude (rad) at each seed, the table's amplitude among them.
    linearised : dict
        :func:`linearised_runs` at the same amplitudes.

    Returns
    -------
    str
        Ending "explained by the twin's small-signal loop." or "not explained (...)."

    Examples
    --------
    >>> run = CaseResult("settled", {"overshoot": 300.0, "excursion": 0.1, "peak": 0.9}, None)
    >>> stops = CaseResult("hit the stops", {"overshoot": 800.0, "excursion": 1.1, "peak": 9.0}, None)
    >>> note = amplitude_note("R = 1, twin", {0.02: run, 0.2: stops}, {0.02: run, 0.2: stops})
    >>> note.endswith("explained by the twin's small-signal loop.")
    True
    """
    tw = seeded(twin)
    amplitudes = sorted(tw.first)
    said = "; ".join(_at([r[a] for r in tw.results], a) for a in amplitudes)
    head = f"{where}: measured at each command amplitude over {len(tw.seeds)} seed(s) (amplitude_runs): {said}"
    small, table = amplitudes[0], amplitudes[-1]
    twin_small = [float(r[small].summary["overshoot"]) for r in tw.results if r[small].summary]
    lin_small, lin_table = linearised.get(small), linearised.get(table)
    if not twin_small or lin_small is None or lin_table is None or not lin_small.summary or not lin_table.summary:
        return f"{head}; not explained (no small-signal loop to compare)."
    ours, theirs = float(np.median(twin_small)), float(lin_small.summary["overshoot"])
    stops_twin = all(r[table].status in ("hit the stops", "diverged") for r in tw.results)
    stops_lin = float(lin_table.summary["excursion"]) >= STOP_ANGLE
    linear = (
        f"on the twin's linearisation at hover, without noise or nonlinearity (linearised_runs), the same controller "
        f"overshoots {theirs:.0f} % at +-{small:g} rad (the twin: {ours:.0f} %, median) and reaches "
        f"{float(lin_table.summary['excursion']):.2g} rad at +-{table:g} rad (the stops: {STOP_ANGLE:g} rad)"
    )
    if relative_difference(ours, theirs) <= EXPLAIN_ABOVE and stops_twin == stops_lin:
        return (
            f"{head}. {linear[0].upper()}{linear[1:]}: the loop designed on eq. (3.11) is barely damped on the twin's "
            "small-signal model (see the margins table), so the square wave's amplitude decides whether it reaches "
            "the stops: explained by the twin's small-signal loop."
        )
    return f"{head}; not explained ({linear}: the check fails)."
