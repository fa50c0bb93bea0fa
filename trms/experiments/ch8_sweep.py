"""Large-signal validity of the ch. 8 designs, measured: an amplitude sweep on the twin, with and without the
thrust-curve inversion.

A design made on eq. (3.11) assumes the twin's thrust slope at hover everywhere; the twin's slope changes by 60 % of
its hover value per volt, so a loop that is exact on the model may hold at small steps and overshoot at large ones. Each
design of :mod:`trms.experiments.ch8_designs` flies the comparison's square wave scaled by :data:`SCALES` (0.1x to 1x of
+-0.2 rad) on

* the twin in still air with exact encoders (nothing but the physics: no turbulence, no noise, no quantisation,
  which at 0.1x would be a fifth of the 2 % band),
* the twin in moving air (turbulence, noise, quantisation; settling in the noise band of
  :func:`~trms.control.metrics.noise_band`),

with the thrust-curve inversion as the comparison flies it (and the other setting at 1x), beside the linear model at
the same amplitude. A design *holds* at an amplitude
when its twin overshoot there is within :data:`OVERSHOOT_POINTS` points of its design-model overshoot, or within the
noise floor where that is wider (at 0.1x in moving air the step is 0.04 rad and 3 standard deviations of the pitch
at rest are a third of it: an overshoot cannot be read finer than the noise); the table gives the largest amplitude
up to which it holds at every amplitude flown (:func:`largest_valid_scale`), and which inversion setting the
measurement supports.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from trms.errors import InputError, check_choice, check_in_range
from trms.experiments.ch8_controllers import SQUARE, Flight, fly, summarise_steps
from trms.experiments.ch8_designs import CONTROLLERS, INVERSION, designs_at
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable
from trms.reference import SAMPLE_TIME_1DOF

__all__ = [
    "SCALES",
    "OVERSHOOT_POINTS",
    "SWEEP_CASES",
    "SweepPoint",
    "Sweep",
    "amplitude_sweep",
    "largest_valid_scale",
    "inversion_gap",
    "table_sweep",
]

#: Amplitudes flown, as fractions of the comparison's +-0.2 rad.
SCALES = (0.1, 0.25, 0.5, 1.0)
#: A design holds where its twin overshoot is within this many points (%) of its design-model overshoot.
OVERSHOOT_POINTS = 10.0
#: The sweep's twin cases: name -> (still air, exact encoders).
SWEEP_CASES = {"twin, still air, exact encoders": (True, True), "twin, moving air": (False, False)}


@dataclass(frozen=True)
class SweepPoint:
    """One design at one amplitude on one twin case, with the inversion off or on.

    Attributes
    ----------
    controller, case : str
    scale : float
        Amplitude as a fraction of +-0.2 rad.
    inversion : bool
    overshoot : float
        Mean overshoot of the twin's steps (%); NaN where a run diverged.
    unsettled, steps : int
        Steps never settled (noise band) and steps flown, over the seeds.
    linear_overshoot : float
        The design model's mean overshoot at the same amplitude (%).
    noise : float
        The noise floor (% of the full-swing step): 3 standard deviations of the loop's pitch at rest, at least 2 %.
    """

    controller: str
    case: str
    scale: float
    inversion: bool
    overshoot: float
    unsettled: int
    steps: int
    linear_overshoot: float
    noise: float = 2.0

    @property
    def holds(self) -> bool:
        """Within :data:`OVERSHOOT_POINTS` of the design model's overshoot, or within the noise floor if wider.

        Examples
        --------
        >>> SweepPoint("PID", "twin, moving air", 1.0, True, 13.0, 0, 8, 8.5).holds
        True
        >>> SweepPoint("PID", "twin, moving air", 0.1, True, 31.0, 0, 8, 8.5, noise=35.0).holds
        True
        """
        gap = abs(self.overshoot - self.linear_overshoot)
        return bool(np.isfinite(self.overshoot) and gap <= max(OVERSHOOT_POINTS, self.noise))


@dataclass(frozen=True)
class Sweep:
    """The whole sweep: its points, seeds, sample time (s) and the worker time it took (s)."""

    points: tuple[SweepPoint, ...]
    seeds: tuple[int, ...]
    sample_time: float
    seconds: float = 0.0


def _row(name: str, case: str, flight: Flight) -> tuple[float, int, int, float]:
    row = summarise_steps(name, case, flight, SQUARE[1] / 2.0)
    return row.overshoot, row.unsettled, row.steps, 100.0 * row.band


def amplitude_sweep(
    seeds: Sequence[int] = (0,),
    sample_time: float = SAMPLE_TIME_1DOF,
    scales: Sequence[float] = SCALES,
    inversion: bool = INVERSION,
    other_at: Sequence[float] = (1.0,),
) -> Sweep:
    """Fly every design at every amplitude on the linear model and the sweep's twin cases (module docstring), with
    the thrust-curve inversion as the comparison flies it, and the other setting at ``other_at``.

    Parameters
    ----------
    seeds : sequence of int
        Seeds of the moving-air runs (still air and the linear model fly the first: nothing random moves them, or
        only the linear model's sensor noise).
    sample_time : float
        0.2 or 0.1 s.
    scales : sequence of float
        Amplitudes, fractions of +-0.2 rad, in (0, 2].
    inversion : bool
        The inversion setting flown at every amplitude.
    other_at : sequence of float
        Amplitudes (of ``scales``) at which the other setting is flown too.

    Returns
    -------
    Sweep

    Examples
    --------
    >>> s = amplitude_sweep(seeds=(7,), scales=(0.25,), other_at=())
    >>> sorted({p.case for p in s.points}) == sorted(SWEEP_CASES), all(p.holds for p in s.points)
    (True, True)
    """
    started = time.perf_counter()
    seeds = tuple(int(s) for s in seeds)
    if not seeds:
        raise InputError("seeds must name at least one seed")
    ts = float(check_choice("sample_time", float(sample_time), (0.2, 0.1), error=InputError))
    scales = tuple(float(check_in_range("scale", s, 0.0, 2.0, low_open=True)) for s in scales)
    other = {float(s) for s in other_at}
    designs = designs_at(ts)
    points = []
    for scale in scales:
        linear, _ = fly(designs, "linear", False, seeds[:1], scale)
        for setting in (bool(inversion), not inversion) if scale in other else (bool(inversion),):
            for case, (still, exact) in SWEEP_CASES.items():
                seeds_here = seeds[:1] if still else seeds
                flights, _ = fly(designs, "twin", still, seeds_here, scale, setting, quantised=not exact)
                for name, flight in flights.items():
                    ov, uns, steps, noise = _row(name, case, flight)
                    lin = _row(name, "linear model", linear[name])[0] if name in linear else math.nan
                    points.append(SweepPoint(name, case, scale, setting, ov, uns, steps, lin, noise))
    return Sweep(tuple(points), seeds, ts, time.perf_counter() - started)


def largest_valid_scale(sweep: Sweep, controller: str, case: str, inversion: bool) -> float:
    """The largest amplitude (fraction of +-0.2 rad) up to which ``controller`` holds on ``case`` at every amplitude
    flown (0: it fails at the smallest).

    Examples
    --------
    >>> pts = [SweepPoint("PID", "c", s, True, ov, 0, 4, 8.0) for s, ov in ((0.25, 9.0), (0.5, 12.0), (1.0, 30.0))]
    >>> largest_valid_scale(Sweep(tuple(pts), (0,), 0.2), "PID", "c", True)
    0.5
    """
    pts = sorted(
        (p for p in sweep.points if (p.controller, p.case, p.inversion) == (controller, case, inversion)),
        key=lambda p: p.scale,
    )
    out = 0.0
    for p in pts:
        if not p.holds:
            break
        out = p.scale
    return out


def inversion_gap(sweep: Sweep, inversion: bool, scale: float = 1.0) -> float:
    """Mean over the designs and twin cases of ``|twin overshoot - design-model overshoot|`` (points) at ``scale``
    with the inversion ``inversion``: the measure the default setting is chosen by.

    Examples
    --------
    >>> pts = (SweepPoint("PID", "c", 1.0, True, 9.0, 0, 4, 8.0), SweepPoint("PID", "c", 1.0, False, 20.0, 0, 4, 8.0))
    >>> inversion_gap(Sweep(pts, (0,), 0.2), True), inversion_gap(Sweep(pts, (0,), 0.2), False)
    (1.0, 12.0)
    """
    gaps = [
        abs(p.overshoot - p.linear_overshoot)
        for p in sweep.points
        if p.inversion == inversion and p.scale == scale and np.isfinite(p.overshoot)
    ]
    return float(np.mean(gaps)) if gaps else math.nan


def _noise_note(sweep: Sweep) -> str:
    """The moving-air noise floor at each amplitude (median over the designs, % of the step)."""
    parts = []
    for scale in sorted({p.scale for p in sweep.points}):
        vals = [p.noise for p in sweep.points if p.scale == scale and p.case == "twin, moving air"]
        if vals:
            parts.append(f"{np.median(vals):.0f} % of the step at {scale:g}x")
    return ", ".join(parts) or "not flown"


def table_sweep(sweep: Sweep) -> ComparisonTable:
    """The sweep as a table: per design, twin case and inversion setting, the twin's overshoot at every amplitude
    beside the design model's, the unsettled steps and the largest amplitude at which the design holds.

    Examples
    --------
    >>> pts = (SweepPoint("PID", "twin, moving air", 1.0, True, 13.0, 0, 8, 8.5),)
    >>> table_sweep(Sweep(pts, (0,), 0.2)).rows[0][:4]
    ['PID', 'twin, moving air', 'on', 8.5]
    """
    scales = sorted({p.scale for p in sweep.points})
    table = ComparisonTable(
        f"Ch. 8 designs at large signals: the square wave's amplitude swept on the twin (Ts = {sweep.sample_time:g} s)",
        ["controller", "case", "thrust-curve inversion", "design model overshoot at 1x (%)"]
        + [f"twin overshoot at {s:g}x (%)" for s in scales]
        + [
            "steps unsettled (all amplitudes)",
            f"holds up to (x 0.2 rad; within {OVERSHOOT_POINTS:g} points or the noise)",
        ],
    )
    for name in CONTROLLERS:
        for case in SWEEP_CASES:
            for inversion in (False, True):
                pts = {
                    p.scale: p for p in sweep.points if (p.controller, p.case, p.inversion) == (name, case, inversion)
                }
                if not pts:
                    continue
                top = pts[max(pts)]
                row: list[object] = [name, case, "on" if inversion else "off", finite_or(top.linear_overshoot, "-")]
                table.rows.append(
                    row
                    + [finite_or(pts[s].overshoot, "diverged") if s in pts else "-" for s in scales]
                    + [
                        f"{sum(p.unsettled for p in pts.values())}/{sum(p.steps for p in pts.values())}",
                        largest_valid_scale(sweep, name, case, inversion) or "none",
                    ]
                )
    on, off = inversion_gap(sweep, True), inversion_gap(sweep, False)
    table.notes += [
        f"The comparison's square wave (+-{SQUARE[2]:g} rad, period {SQUARE[1]:g} s) times each amplitude; moving air "
        f"at seeds {', '.join(map(str, sweep.seeds))}, still air and the design model at the first (exact encoders "
        "in still air: quantisation would be a fifth of the 2 % band at 0.1x). Settling in the noise band. A design "
        f"holds at an amplitude where its twin overshoot is within {OVERSHOOT_POINTS:g} points of the design model's, "
        "or within the noise floor where wider: in moving air 3 standard deviations of the pitch at rest are "
        + _noise_note(sweep)
        + ".",
        f"At 1x the twin's overshoot differs from the design model's by {off:.1f} points on average without the "
        f"thrust-curve inversion and by {on:.1f} with it; the comparison flies it "
        + ("on" if INVERSION else "off")
        + (
            " (the setting with the smaller gap)."
            if (on <= off) == INVERSION
            else " (NOT the setting with the smaller gap)."
        )
        if np.isfinite(on) and np.isfinite(off)
        else "Only one inversion setting was flown.",
    ]
    return table
