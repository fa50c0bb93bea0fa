"""Chapter 8's controller comparison as one study: the report's section, ``trms compare-controllers`` and the tests.

Three parts, each with its own builder, run here with one set of seeds:

* the 1-DOF comparison (:func:`~trms.experiments.ch8_controllers.compare_controllers`): LQG, PID, MPC and the
  H-infinity designs on the square wave (linear model, twin in moving and in still air) and the push, with each
  design's damping of the pitch mode; and its amplitude sweep (:func:`~trms.experiments.ch8_sweep.amplitude_sweep`,
  with and without the thrust-curve inversion);
* the same controllers over the twin's parameter spread (:func:`~trms.experiments.ch8_robustness.controller_robustness`,
  the LQG robustness study's draws, one batch per controller);
* the 2-DOF MIMO controllers (:func:`~trms.experiments.ch8_controllers_mimo.compare_controllers_mimo`) on both
  square waves of chapter 8.

:func:`study_tables` gives their tables, :func:`study_figures` the responses overlaid (the first seed, the twin in
moving air). A design is labelled robust only when its LTI certificate, the spread and its flights on the twin all
hold (:func:`twin_failures`, :func:`~trms.experiments.ch8_robustness.robust_verdict`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from trms.errors import InputError, check_in_range, check_seed
from trms.experiments.ch8_controllers import (
    CASES,
    SQUARE,
    Comparison,
    compare_controllers,
    table_controllers,
    table_designs,
)
from trms.experiments.ch8_controllers_mimo import MimoComparison, compare_controllers_mimo, table_controllers_mimo
from trms.experiments.ch8_designs import CONTROLLERS
from trms.experiments.ch8_robustness import Robustness, controller_robustness, table_robustness
from trms.experiments.ch8_sweep import OVERSHOOT_POINTS, Sweep, amplitude_sweep, table_sweep
from trms.present.figures import plot_series, save_figure
from trms.present.sections import FigureRef
from trms.present.tables import ComparisonTable
from trms.reference import SAMPLE_TIME_1DOF

if TYPE_CHECKING:
    from matplotlib.typing import LineStyleType

__all__ = [
    "ControllerStudy",
    "controller_study",
    "study_tables",
    "plot_responses",
    "study_figures",
    "twin_failures",
]

#: The case the figure overlays.
FIGURE_CASE = "twin, moving air"
#: Each controller's colour and dash in the figure (the H-infinity designs in three colours and three dashes).
_STYLES: tuple[tuple[str, LineStyleType], ...] = (
    ("tab:blue", "-"),
    ("tab:orange", "-"),
    ("tab:green", "-"),
    ("tab:red", "--"),
    ("tab:purple", "-."),
    ("tab:brown", ":"),
)


@dataclass(frozen=True)
class ControllerStudy:
    """The three parts of the comparison (module docstring).

    Attributes
    ----------
    comparison : Comparison
    spread : Robustness or None
        None when no spread sample was asked for.
    mimo : MimoComparison or None
        None when no MIMO seed was asked for.
    seconds : float
        Wall time of the study (s).
    sweep : Sweep or None
        The amplitude sweep (None when not asked for).
    """

    comparison: Comparison
    spread: Robustness | None
    mimo: MimoComparison | None
    seconds: float = 0.0
    sweep: Sweep | None = None


def controller_study(
    seeds: Sequence[int] = (0, 1, 2),
    samples: int = 6,
    mimo_seeds: Sequence[int] = (0, 1, 2),
    sample_time: float = SAMPLE_TIME_1DOF,
    mimo_worlds: Sequence[str] = ("linear model", "twin, moving air"),
    cases: Sequence[str] = tuple(CASES),
    push: bool = True,
    sweep_seeds: Sequence[int] = (0,),
) -> ControllerStudy:
    """Run the comparison's three parts (module docstring) at the same study seed.

    Parameters
    ----------
    seeds : sequence of int
        Plant seeds of the 1-DOF comparison (at least one).
    samples : int
        Twins of the parameter spread each 1-DOF controller flies (0: none), 0 to 10000.
    mimo_seeds : sequence of int
        Plant seeds of the 2-DOF comparison (empty: none).
    sample_time : float
        Sample time of the 1-DOF designs and plants (s): 0.2 or 0.1.
    mimo_worlds : sequence of str
        Worlds of the 2-DOF comparison (:data:`~trms.experiments.ch8_controllers_mimo.WORLDS`).
    cases : sequence of str
        Square-wave cases of the 1-DOF comparison (:data:`~trms.experiments.ch8_controllers.CASES`).
    push : bool
        Fly the 1-DOF push too.
    sweep_seeds : sequence of int
        Moving-air seeds of the amplitude sweep (empty: no sweep).

    Returns
    -------
    ControllerStudy

    Raises
    ------
    InputError
        No 1-DOF seed, a sample count outside [0, 10000], or what the parts refuse.

    Examples
    --------
    >>> controller_study(seeds=(), samples=0, mimo_seeds=())
    Traceback (most recent call last):
    trms.errors.InputError: seeds must name at least one seed
    >>> controller_study(seeds=(0,), samples=0, mimo_seeds=(-3,))
    Traceback (most recent call last):
    trms.errors.InputError: MIMO seed must be a non-negative integer, got -3
    """
    if isinstance(seeds, str) or isinstance(mimo_seeds, str) or isinstance(sweep_seeds, str):
        raise InputError("seeds and mimo_seeds must be sequences of whole numbers, not a string")
    seeds = tuple(int(check_seed("seed", s, allow_none=False)) for s in seeds)  # type: ignore[arg-type]
    mimo_seeds = tuple(int(check_seed("MIMO seed", s, allow_none=False)) for s in mimo_seeds)  # type: ignore[arg-type]
    sweep_seeds = tuple(int(check_seed("sweep seed", s, allow_none=False)) for s in sweep_seeds)  # type: ignore[arg-type]
    if not seeds:
        raise InputError("seeds must name at least one seed")
    n = int(check_in_range("samples", samples, 0, 10_000))
    started = time.perf_counter()
    comparison = compare_controllers(seeds, sample_time, cases, push)
    spread = controller_robustness(n, sample_time=sample_time) if n else None
    mimo = compare_controllers_mimo(tuple(mimo_seeds), tuple(mimo_worlds)) if mimo_seeds else None
    sweep = amplitude_sweep(sweep_seeds, sample_time) if sweep_seeds else None
    return ControllerStudy(comparison, spread, mimo, time.perf_counter() - started, sweep)


def twin_failures(comparison: Comparison) -> dict[str, str] | None:
    """Per controller, what of its twin flights failed (empty: they held): a twin case whose overshoot is more than
    :data:`~trms.experiments.ch8_sweep.OVERSHOOT_POINTS` from the linear model's, a still-air step that never
    settled, or more than one in eight moving-air steps that never settled. None when the linear model or no twin
    case was flown (nothing to judge by).

    Examples
    --------
    >>> from trms.experiments.ch8_controllers import ControllerCase
    >>> rows = (ControllerCase("PID", "linear model", 8.0, 9.0, 0, 8, 0.1, 0.0),
    ...         ControllerCase("PID", "twin, still air", 25.0, 9.0, 2, 8, 0.1, 0.0))
    >>> twin_failures(Comparison(rows, {}, {}, {}, (0,), 0.2))
    {'PID': 'still air: overshoot 25 % against 8 % on the model; 2/8 steps unsettled'}
    """
    linear = {c.controller: c for c in comparison.cases if c.case == "linear model" and c.status == "flown"}
    twin = [c for c in comparison.cases if c.case.startswith("twin") and c.status == "flown"]
    if not linear or not twin:
        return None
    out: dict[str, str] = {}
    for c in twin:
        if c.controller not in linear:
            continue
        problems = []
        lin = linear[c.controller]
        if abs(c.overshoot - lin.overshoot) > OVERSHOOT_POINTS:
            problems.append(f"overshoot {c.overshoot:.3g} % against {lin.overshoot:.3g} % on the model")
        allowed = 0 if c.case == "twin, still air" else c.steps // 8
        if c.unsettled > allowed:
            problems.append(f"{c.unsettled}/{c.steps} steps unsettled")
        text = "; ".join(problems)
        where = c.case.removeprefix("twin, ")
        old = out.get(c.controller, "")
        out[c.controller] = "; ".join(x for x in (old, f"{where}: {text}" if text else "") if x)
    return out


def study_tables(study: ControllerStudy) -> dict[str, ComparisonTable]:
    """The study's tables by name, in order: the 1-DOF comparison (``comparison``), its designs' damping and margins
    (``designs``), the amplitude sweep (``sweep``), the spread (``spread``, with the robust verdicts) and the 2-DOF
    comparison (``mimo``), those that ran.

    Examples
    --------
    >>> from trms.experiments.ch8_controllers import Comparison
    >>> study = ControllerStudy(Comparison((), {}, {}, {}, (0,), 0.2), None, None)
    >>> list(study_tables(study))
    ['comparison']
    """
    tables = {"comparison": table_controllers(study.comparison)}
    if study.comparison.damping:
        tables["designs"] = table_designs(study.comparison)
    if study.sweep is not None:
        tables["sweep"] = table_sweep(study.sweep)
    if study.spread is not None:
        tables["spread"] = table_robustness(study.spread, twin_failures(study.comparison))
    if study.mimo is not None:
        tables["mimo"] = table_controllers_mimo(study.mimo)
    return tables


def plot_responses(comparison: Comparison, case: str = FIGURE_CASE) -> Figure:
    """Every controller's pitch and command at the first seed of ``case``, overlaid on the reference.

    Raises
    ------
    InputError
        ``case`` was not flown.

    Examples
    --------
    >>> plot_responses(Comparison((), {}, {}, {}, (0,), 0.2))
    Traceback (most recent call last):
    trms.errors.InputError: case 'twin, moving air' was not flown; flown: none
    """
    records = {name: comparison.records[(name, case)] for name in CONTROLLERS if (name, case) in comparison.records}
    if not records:
        flown = sorted({c for _, c in comparison.records})
        raise InputError(f"case {case!r} was not flown; flown: {', '.join(map(repr, flown)) or 'none'}")
    first = next(iter(records.values()))
    series = {"reference": first.extras["reference"][:, 0]}
    if "prefiltered_reference" in first.extras:
        series["reference through the prefilter"] = first.extras["prefiltered_reference"][:, 0]
    inputs = {}
    for name, rec in records.items():
        du, dy = rec.deviations()
        series[name] = dy[:, 0]
        inputs[name] = du[:, 0]
    fig = plot_series(
        first.time,
        series,
        f"Ch. 8 controllers on the 1-DOF pitch, {case}, seed {comparison.seeds[0]} "
        f"(square wave +-{SQUARE[2]:g} rad, Ts = {comparison.sample_time:g} s)",
        "pitch (rad, deviation)",
        inputs,
        "main rotor (V, deviation)",
    )
    styles = dict(zip(CONTROLLERS, _STYLES))
    for axis in fig.axes[:2]:  # each controller in its own colour and dash on both panels, the reference black
        for line in axis.get_lines():
            label = str(line.get_label())
            colour, dash = styles.get(label, ("black", ":" if label == "reference" else "-"))
            if label == "reference through the prefilter":
                colour = "0.6"
            line.set_color(colour)
            line.set_linestyle(dash)
    fig.axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.axes[1].legend().remove()
    fig.set_size_inches(10.0, fig.get_size_inches()[1])
    fig.subplots_adjust(right=0.74)
    return fig


def study_figures(study: ControllerStudy, folder: str | os.PathLike[str]) -> list[FigureRef]:
    """The study's figure written into ``folder``: every controller's response overlaid (:func:`plot_responses`)."""
    if not any(case == FIGURE_CASE for _, case in study.comparison.records):
        return []
    path = save_figure(plot_responses(study.comparison), Path(folder) / "ch8_controllers.png")
    worst = max(
        (c for c in study.comparison.cases if c.case == FIGURE_CASE and np.isfinite(c.overshoot)),
        key=lambda c: c.overshoot,
        default=None,
    )
    caption = "Every controller of the comparison on the twin in moving air, the same seed and square wave"
    if worst is not None:
        caption += f"; the largest mean overshoot is {worst.controller}'s, {worst.overshoot:.1f} %."
    return [FigureRef(path, caption)]
