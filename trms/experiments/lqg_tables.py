"""Table 6.1 of the thesis (SAS and CSAS on the linear pitch model), reproduced and explained.

Set-up (thesis ch. 6.7-6.9, with the choices the thesis leaves open stated)
---------------------------------------------------------------------------
* Plant: eq. (3.11), ``Ts = 0.2 s``, realised in the observer canonical form of eq. (6.33)
  (so ``Q = I`` weighs the same kind of state as the thesis's design), as a
  :class:`~trms.plant.LinearPlant` with absolute limits ``+-10 V`` about a trim input
  ``u0`` (default 0 V: the linear model carries no trim, so the deviation limit is
  ``+-10 V``); the plant saturates and records it.
* Controller: integral LQG, ``Q = I`` (5 x 5), ``R`` = 75, 1, 100, 125; estimator
  ``Qe = I`` (process noise on every state), ``Re = 1``: the thesis gives no values, only
  "estimator faster than the regulator"; with these the slowest estimator pole has
  ``|z| = 0.53`` against 0.82-0.95 for the regulators. The compensator acts on the tracking
  error (the thesis's fig. 6.5 and eq. 6.37), with conditional-integration anti-windup at
  the deviation limits.
* Command: a square wave of amplitude ``A`` (default 0.2 rad, i.e. steps of 0.4 rad after
  the first), period 40 s, two periods (80 s), starting high at t = 0. The thesis prints
  neither the amplitude nor the limit in deviation volts.
* Prefilters (CSAS): Butterworth order 2 low-pass at 0.2 and 0.3 Hz; Butterworth order 2
  band-stops 0.15-0.35 Hz and 0.24-0.44 Hz in cascade ("centre 0.25 and 0.34 Hz, bandwidth
  0.2 Hz").
* Measures (per step of the raw command, :mod:`trms.control.metrics`): rise time 10-90 %,
  settling time to the 2 % band; the table reports the largest over the run's full-swing
  steps (they differ only when the actuator saturates; the first step, from rest, is half as
  large and its 2 % band half as wide, which noise alone can keep a response out of). "control" is "high" when the commanded
  control went beyond the deviation limit at any sample, as in the thesis.

What moves the table
--------------------
Rise and settling times are independent of ``A`` and of the limit while nothing saturates
(the loop is linear). The "control" column is set by the ratio of the deviation limit to the
command step: the peak command of each case is proportional to ``A``.
:func:`table_6_1_sensitivity` runs a grid of amplitudes and limits.

Cells more than 30 % from the thesis (with the defaults)
-------------------------------------------------------
See :data:`DIFFERENCES`: each is explained there and added to the table's notes.

On the twin (ch. 7): the same controllers around any plant
----------------------------------------------------------
:func:`run_case` takes any plant and the model to design on (default: the plant's own, for a
linear plant); :func:`lqg_cases` runs every ``(R, case)`` of chapters 6 and 7 (adding the rig's
LPF 0.1 Hz and BSF 0.34 Hz prefilters) with the controllers designed on eq. (3.11), and judges
each run (:func:`judge`: settled, not settled, hit the mechanical stops, diverged);
:func:`push_rejection` holds hover and pushes the beam at 19 s (ch. 7.4). :func:`section` puts
the linear model's and the twin's results beside the thesis's.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import control
import numpy as np

from ..control.loop import closed_loop, deviation_limits
from ..control.lqg import LQGController, design_lqg
from ..control.metrics import StepMetrics, square_wave_metrics
from ..control.plots import plot_closed_loop
from ..control.realization import observer_canonical
from ..control.shaping import CommandFilter, bands_around, butterworth_lowpass, multiband_bandstop
from ..errors import DivergenceError, InputError, check_in_range
from ..identification.signals import square_wave
from ..plant import LinearPlant, OperatingPoint, Plant, Record
from ..reference import (
    CHAPTER_7_OUTCOMES,
    CHAPTER_7_PREFILTER_OUTCOMES,
    CHAPTER_7_PREFILTERS,
    LQG_WEIGHTS_R,
    PUSH_WEIGHTS_R,
    SAMPLE_TIME_1DOF,
    TABLE_6_1,
    TABLE_6_1_PREFILTERS,
    VOLTAGE_LIMIT,
    eq_3_11,
)
from .figures import plot_series
from .section import FigureRef, Section, finite_or
from .tables import ComparisonTable, format_cell, relative_difference, side_by_side

__all__ = [
    "CASES",
    "ALL_CASES",
    "PUSH",
    "CaseResult",
    "judge",
    "case_setup",
    "worst",
    "lqg_cases",
    "push_rejection",
    "section",
    "DEFAULT_AMPLITUDE",
    "DEFAULT_PERIOD",
    "DEFAULT_DURATION",
    "ESTIMATOR_QE",
    "ESTIMATOR_RE",
    "DIFFERENCES",
    "pitch_plant",
    "prefilters",
    "run_case",
    "table_6_1",
    "table_6_1_sensitivity",
    "plot_table_6_1",
]

#: The four control structures of Table 6.1, in its column order.
CASES = ("SAS", "CSAS LPF 0.2 Hz", "CSAS LPF 0.3 Hz", "CSAS BSF 0.25 & 0.34 Hz")
#: Every (R, case) run on the rig (ch. 7): Table 6.1's cases plus the LPF 0.1 Hz and the BSF 0.34 Hz.
ALL_CASES = CASES + tuple(CHAPTER_7_PREFILTERS)
#: The push of ch. 7.4: time (s), angular impulse about pitch (N m s), duration (s); this project's
#: choice of size (the thesis pushed by hand "around 18-20 s").
PUSH = (19.0, 0.02, 0.2)
#: Pitch (rad) beyond which a run counts as having hit the mechanical stops (the twin's are at 1.1 rad).
STOP_ANGLE = 1.0
#: Settling band (fraction of the step) that decides a run's status and stands in for the 2 % band
#: when gusts and noise keep a run out of it (0.02 x 0.4 rad = 8 mrad, the size of the gust wander).
WIDE_BAND = 0.05
#: A 2 % settling time later than this fraction of the half period means the response only drifted into the
#: band by the period's end (gust wander is as wide as the band): the 5 % band is reported instead.
HELD_FRACTION = 0.75
#: Band (rad) the pitch must stay within after a push to count as recovered.
RECOVERY_BAND = 0.02
#: Square-wave amplitude (rad): this project's choice (the thesis does not print it).
DEFAULT_AMPLITUDE = 0.2
#: Square-wave period (s): long enough for the slowest case (13 s in the thesis) to settle per half.
DEFAULT_PERIOD = 40.0
#: Run length (s): two periods.
DEFAULT_DURATION = 80.0
#: Estimator process-noise covariance (times I) and measurement-noise covariance: this project's choice.
ESTIMATOR_QE = 1.0
ESTIMATOR_RE = 1.0
#: Relative difference beyond which a cell must be explained.
EXPLAIN_ABOVE = 0.30

#: Explanations of the cells more than 30 % from the thesis with the default settings, by (R, case, measure).
DIFFERENCES = {
    (75.0, "CSAS LPF 0.2 Hz", "TR"): (
        "Our 10-90 % rise time is 3.1 s. Read from the command edge to 90 % (the prefilter delays the start of "
        "the response by about 1.5 s) it is 4.6 s, the thesis's 4.5 s: the thesis seems to time the rise from the "
        "command step, which counts the prefilter's delay. Its SAS values (no delay) agree within 25 %."
    ),
    (75.0, "CSAS LPF 0.3 Hz", "TS"): (
        "With Qe = I the estimator damps the 0.34 Hz mode that the 0.3 Hz prefilter still lets through, and the "
        "run settles like the 0.2 Hz case (6.6 s). This cell depends on the estimator weights, which the thesis "
        "does not print: with Qe = 0.01 I (a slower estimator) it settles in 8.8 s, closer to the thesis's 10 s, "
        "while the other cells move by less than 0.5 s."
    ),
    (1.0, "CSAS BSF 0.25 & 0.34 Hz", "TR"): (
        "The band-stop lets the command's high frequencies through and the R = 1 compensator answers with a 10.9 V "
        "peak, beyond the 10 V limit on the 0.4 rad steps: the actuator saturates for 0.6 s and the rise slows "
        "to 3.6 s. Without the limit (or on the first, 0.2 rad, step) the rise time is 2.2 s, 14 % from the thesis."
    ),
}


def pitch_plant(trim: float = 0.0, limit: float = VOLTAGE_LIMIT, noise_std: float = 0.0) -> LinearPlant:
    """Eq. (3.11) in observer canonical form as a plant with absolute limits ``+-limit`` about ``trim``.

    Parameters
    ----------
    trim : float
        Trim input (V, absolute) at the hover operating point; pitch trim 0 rad.
    limit : float
        Absolute actuator limit (V), > ``|trim|``.
    noise_std : float
        Measurement noise (rad), >= 0.
    """
    lim = check_in_range("limit", limit, 0.0, np.inf, unit=" V", low_open=True)
    u0 = check_in_range("trim", trim, -lim, lim, unit=" V")
    if abs(u0) >= lim:
        raise InputError(f"trim = {trim!r} V must lie strictly inside the limits +-{lim} V")
    model = observer_canonical(eq_3_11())
    op = OperatingPoint(np.array([u0]), np.array([0.0]), ("u1",), ("y1",))
    return LinearPlant(model, operating_point=op, input_limits=(-lim, lim), noise_std=noise_std)


def prefilters(sample_time: float = SAMPLE_TIME_1DOF) -> dict[str, CommandFilter | None]:
    """Every case's prefilter (``None`` for SAS), chapters 6 and 7, designed at ``sample_time``."""
    out: dict[str, CommandFilter | None] = {"SAS": None}
    for name, (kind, order, freqs, bandwidth) in {**TABLE_6_1_PREFILTERS, **CHAPTER_7_PREFILTERS}.items():
        if kind == "lowpass":
            out[name] = butterworth_lowpass(order, freqs[0], sample_time)
        else:
            out[name] = multiband_bandstop(order, bands_around(freqs, bandwidth), sample_time)
    return out


def run_case(
    plant: Plant,
    r_weight: float,
    case: str,
    amplitude: float = DEFAULT_AMPLITUDE,
    period: float = DEFAULT_PERIOD,
    duration: float = DEFAULT_DURATION,
    seed: int | None = 0,
    model: control.StateSpace | None = None,
) -> tuple[Record, list[StepMetrics]]:
    """Design the LQG for ``R = r_weight`` and run one case of Table 6.1 (or ch. 7) on ``plant``.

    Parameters
    ----------
    plant : Plant
        Any 1-DOF plant (e.g. :func:`pitch_plant` or the twin).
    r_weight : float
        Control weight ``R`` (``Q = I``).
    case : str
        One of :data:`ALL_CASES`.
    amplitude, period, duration : float
        Square-wave command (rad, s, s).
    seed : int, optional
        Plant reset seed (noise, gusts).
    model : control.StateSpace, optional
        Design model; default the plant's own ``system`` (a :class:`~trms.plant.LinearPlant`).

    Returns
    -------
    Record, list of StepMetrics

    Raises
    ------
    DivergenceError
        The plant's simulation blew up (an unstable loop on the twin).
    """
    controller, ref, prefilter, meta = case_setup(plant, r_weight, case, amplitude, period, duration, model)
    record = closed_loop(plant, controller, ref, prefilter=prefilter, seed=seed, metadata=meta)
    return record, square_wave_metrics(record)


def case_setup(
    plant: Plant,
    r_weight: float,
    case: str,
    amplitude: float = DEFAULT_AMPLITUDE,
    period: float = DEFAULT_PERIOD,
    duration: float = DEFAULT_DURATION,
    model: control.StateSpace | None = None,
) -> tuple[LQGController, np.ndarray, CommandFilter | None, dict[str, object]]:
    """The loop of one case (see :func:`run_case`): controller, square-wave reference, prefilter, metadata.

    Examples
    --------
    >>> c, ref, pf, meta = case_setup(pitch_plant(), 75.0, "SAS", duration=4.0)
    >>> ref.shape, pf, meta["case"]
    ((20,), None, 'SAS')
    """
    if case not in ALL_CASES:
        raise InputError(f"unknown case {case!r}; allowed: {', '.join(repr(c) for c in ALL_CASES)}")
    if model is None:
        if not isinstance(plant, LinearPlant):
            raise InputError("a design model is needed for a plant that is not a LinearPlant")
        model = plant.system
    design = design_lqg(model, Q=1.0, R=r_weight, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    controller = LQGController(design, deviation_limits(plant))
    ref = square_wave(duration, plant.sample_time, period, amplitude)
    meta = {"R": float(r_weight), "case": case, "amplitude_rad": float(amplitude)}
    return controller, ref, prefilters(plant.sample_time)[case], meta


def worst(values: Sequence[float]) -> float:
    """The largest of per-step values, ``nan`` if any is ``nan`` (a step that never settled)."""
    arr = np.asarray(values, float)
    return float("nan") if np.any(np.isnan(arr)) else float(arr.max())


def full_swing(steps: Sequence[StepMetrics]) -> list[StepMetrics]:
    """The steps of a square wave that span its whole swing (``-A`` to ``+A``).

    The first step, from rest to ``+A``, is half as large: its 2 % band is half as wide (4 mrad for
    +-0.2 rad), below what measurement noise and quantisation let a response hold, so it would decide
    every worst case for reasons that have nothing to do with the controller.
    """
    swing = max(abs(m.target - m.initial) for m in steps)
    return [m for m in steps if abs(m.target - m.initial) >= 0.99 * swing]


def _summary(record: Record, steps: list[StepMetrics], limits: tuple[np.ndarray, np.ndarray]) -> dict[str, object]:
    u = record.extras["control"]
    high = bool(np.any(u < limits[0]) or np.any(u > limits[1]))
    full = full_swing(steps)
    return {
        "TR": worst([m.rise_time for m in full]),
        "TS": worst([m.settling_time for m in full]),
        "overshoot": max(m.overshoot for m in steps),
        "peak": float(np.abs(u).max()),
        "control": "high" if high else "ok",
        "saturated": float(sum(m.saturated_time for m in steps)),
        "TV": float(sum(m.total_variation for m in steps)),
    }


def table_6_1(
    weights: Sequence[float] = LQG_WEIGHTS_R,
    amplitude: float = DEFAULT_AMPLITUDE,
    trim: float = 0.0,
    limit: float = VOLTAGE_LIMIT,
) -> ComparisonTable:
    """Table 6.1 on the linear model, computed beside the thesis's values.

    Parameters
    ----------
    weights : sequence of float
        Values of ``R`` (the thesis prints 75 and 1; 100 and 125 are its ch. 7 additions).
    amplitude : float
        Square-wave amplitude (rad).
    trim, limit : float
        Trim input and absolute actuator limit (V); the deviation limit is ``+-limit - trim``.

    Returns
    -------
    ComparisonTable
        One row per (R, case): computed TR, TS (s), overshoot (%), peak |u| (V), control, time
        saturated (s), total variation of u (V), then the thesis's TR, TS, control.
    """
    plant = pitch_plant(trim, limit)
    limits = deviation_limits(plant)
    table = ComparisonTable(
        title=f"Table 6.1 on eq. (3.11): square wave +-{amplitude:g} rad, deviation limits {limits[0][0]:g} / {limits[1][0]:g} V",
        columns=["R", "case", "TR (s)", "TS (s)", "overshoot (%)", "peak |u| (V)", "control", "saturated (s)",
                 "TV of u (V)", "thesis TR (s)", "thesis TS (s)", "thesis control"],
    )
    flagged: list[str] = []
    for r in weights:
        for case in CASES:
            record, steps = run_case(plant, r, case, amplitude)
            s = _summary(record, steps, limits)
            thesis = TABLE_6_1.get((float(r), case))
            t_tr, t_ts, t_ctl = thesis if thesis else (None, None, None)
            table.rows.append([float(r), case, s["TR"], s["TS"], s["overshoot"], s["peak"], s["control"],
                               s["saturated"], s["TV"], t_tr, t_ts, t_ctl])
            if thesis is None:
                continue
            for key, computed, printed in (("TR", s["TR"], t_tr), ("TS", s["TS"], t_ts)):
                d = relative_difference(computed, printed)
                if not d <= EXPLAIN_ABOVE:
                    why = DIFFERENCES.get((float(r), case, key), "not explained for these settings (see the module docstring)")
                    flagged.append(f"R = {r:g}, {case}, {key}: {computed:.3g} s vs {format_cell(printed)} s ({d:.0%} off). {why}")
            if s["control"] != t_ctl:
                flagged.append(
                    f"R = {r:g}, {case}, control: {s['control']} (peak {s['peak']:.3g} V) vs thesis {t_ctl}: set by the "
                    "limit-to-step ratio, which the thesis does not print (see table_6_1_sensitivity)."
                )
    table.notes = [
        "Plant eq. (3.11) (observer canonical form), Ts = 0.2 s; LQG Q = I, estimator Qe = I, Re = 1; compensator on "
        "the tracking error (fig. 6.5); conditional-integration anti-windup; the plant saturates at its limits.",
        f"Square wave +-{amplitude:g} rad, period {DEFAULT_PERIOD:g} s, {DEFAULT_DURATION:g} s; TR and TS are the largest "
        "over the run's full-swing steps (the first step, from rest, is half as large); 'high' = commanded control "
        "beyond the deviation limit at some sample.",
        "R = 100 and 125 are not in the thesis's Table 6.1 (they were added on the rig, ch. 7): no thesis values.",
    ] + flagged
    return table


def table_6_1_sensitivity(
    amplitudes: Sequence[float] = (0.1, 0.2, 0.5),
    limits: Sequence[float] = (10.0, 2.0, 0.5),
    weights: Sequence[float] = (75.0, 1.0),
) -> ComparisonTable:
    """How Table 6.1 moves with the square-wave amplitude and the deviation limit.

    Parameters
    ----------
    amplitudes : sequence of float
        Square-wave amplitudes (rad).
    limits : sequence of float
        Symmetric deviation limits (V) (trim 0).
    weights : sequence of float
        Values of ``R``.

    Returns
    -------
    ComparisonTable
        One row per (amplitude, limit, R): each case's "TR/TS/control", and how many of the
        thesis's "control" cells the setting reproduces.
    """
    table = ComparisonTable(
        title="Table 6.1 sensitivity to the command amplitude and the deviation limit (TR s / TS s / control)",
        columns=["amplitude (rad)", "limit (V)", "R", *CASES, "control cells as thesis"],
    )
    for a in amplitudes:
        for lim in limits:
            plant = pitch_plant(0.0, lim)
            dev = deviation_limits(plant)
            for r in weights:
                cells, agree, total = [], 0, 0
                for case in CASES:
                    record, steps = run_case(plant, r, case, a)
                    s = _summary(record, steps, dev)
                    cells.append(f"{s['TR']:.2g}/{s['TS']:.2g}/{s['control']}")
                    thesis = TABLE_6_1.get((float(r), case))
                    if thesis is not None:
                        total += 1
                        agree += thesis[2] == s["control"]
                table.rows.append([float(a), float(lim), float(r), *cells, f"{agree}/{total}" if total else None])
    table.notes = [
        "Without saturation TR and TS do not depend on the amplitude (linear loop); the control column flips where "
        "the peak command (proportional to the amplitude) crosses the limit.",
    ]
    return table


def plot_table_6_1(
    folder: str | os.PathLike[str],
    weights: Sequence[float] = LQG_WEIGHTS_R,
    amplitude: float = DEFAULT_AMPLITUDE,
    trim: float = 0.0,
    limit: float = VOLTAGE_LIMIT,
) -> list[Path]:
    """One PNG per (R, case): response and control with the limit drawn (figs. 6.6-6.14).

    Parameters
    ----------
    folder : path-like
        Output folder (created).
    weights, amplitude, trim, limit
        As in :func:`table_6_1`.

    Returns
    -------
    list of pathlib.Path
    """
    plant = pitch_plant(trim, limit)
    limits = deviation_limits(plant)
    paths = []
    for r in weights:
        for case in CASES:
            record, _ = run_case(plant, r, case, amplitude)
            slug = case.lower().replace(" & ", "_").replace(" ", "_").replace(".", "p")
            paths.append(plot_closed_loop(record, Path(folder) / f"table_6_1_R{r:g}_{slug}.png",
                                          f"{case}, Q = I, R = {r:g} (eq. 3.11)", limits))
    return paths


# ------------------------------------------------------------------ the same controllers on any plant
@dataclass
class CaseResult:
    """One closed-loop run of chapter 6/7 on one plant.

    Attributes
    ----------
    status : str
        ``"settled"``, ``"not settled"`` (the last step never entered the :data:`WIDE_BAND` band),
        ``"hit the stops"`` (pitch beyond :data:`STOP_ANGLE`) or ``"diverged"`` (the simulation blew up).
    summary : dict
        TR, TS (s, 2 % band), "TS wide" (s, :data:`WIDE_BAND`), overshoot (%), peak |u| (V), control
        ("ok"/"high"), saturated (s), TV (V); empty when diverged.
    record : Record or None
        The run (None when diverged).
    """

    status: str
    summary: dict[str, object]
    record: Record | None


def judge(record: Record, steps: list[StepMetrics]) -> str:
    """Status of a closed-loop run: settled, not settled, or hit the stops (see :class:`CaseResult`).

    ``steps`` are the run's step measures at the band that decides "settled"."""
    angles = record.extras.get("true_angles")
    pitch = np.abs(angles[:, 0]) if angles is not None else np.abs(record.deviations()[1][:, 0])
    if np.max(pitch) >= STOP_ANGLE:
        return "hit the stops"
    if not steps or not np.isfinite(steps[-1].settling_time):
        return "not settled"
    return "settled"


def lqg_cases(
    plant: Plant,
    model: control.StateSpace,
    weights: Sequence[float] = LQG_WEIGHTS_R,
    cases: Sequence[str] = ALL_CASES,
    amplitude: float = DEFAULT_AMPLITUDE,
    seed: int = 0,
) -> dict[tuple[float, str], CaseResult]:
    """Every ``(R, case)`` closed around ``plant`` with controllers designed on ``model``.

    Parameters
    ----------
    plant : Plant
        The linear model or the twin (1-DOF, 0.2 s).
    model : control.StateSpace
        Design model (the thesis's: eq. 3.11, :func:`trms.experiments.plants.design_model`).
    weights, cases : sequences
        ``R`` values and case names.
    amplitude : float
        Square-wave amplitude (rad).
    seed : int
        Plant seed (noise, gusts) of every run.
    """
    limits = deviation_limits(plant)
    out = {}
    for r in weights:
        for case in cases:
            try:
                record, steps = run_case(plant, r, case, amplitude, seed=seed, model=model)
            except DivergenceError:
                out[(float(r), case)] = CaseResult("diverged", {}, None)
                continue
            wide = square_wave_metrics(record, band=WIDE_BAND)
            summary = _summary(record, steps, limits)
            summary["TS wide"] = worst([m.settling_time for m in full_swing(wide)])
            out[(float(r), case)] = CaseResult(judge(record, wide), summary, record)
    return out


@dataclass
class PushResult:
    """Push rejection on one plant: peak pitch deviation after the push (rad), recovery time (s, nan if never)."""

    status: str
    peak: float
    recovery: float
    record: Record | None


def push_rejection(
    make: object,
    model: control.StateSpace,
    weights: Sequence[float] = PUSH_WEIGHTS_R,
    duration: float = 40.0,
    seed: int = 0,
) -> dict[float, PushResult]:
    """Hold hover under SAS and push the beam (ch. 7.4): :data:`PUSH` about pitch.

    Parameters
    ----------
    make : callable
        ``make(pushes) -> Plant``: builds the plant with the given pushes (the twin; the linear
        model has no torque input).
    model : control.StateSpace
        Design model.
    weights : sequence of float
        ``R`` values (the thesis: 75, 100, 125).
    duration : float
        Run length (s).
    seed : int
        Plant seed.
    """
    from ..twin import Push

    t_push, impulse, width = PUSH
    plant = make([Push.impulse(t_push, impulse, width, "pitch")])  # type: ignore[operator]
    n = int(round(duration / plant.sample_time))
    out = {}
    for r in weights:
        controller = LQGController(design_lqg(model, Q=1.0, R=r, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE), deviation_limits(plant))
        try:
            rec = closed_loop(plant, controller, np.zeros(n), seed=seed, metadata={"R": float(r), "push": list(PUSH)})
        except DivergenceError:
            out[float(r)] = PushResult("diverged", float("nan"), float("nan"), None)
            continue
        y = rec.deviations()[1][:, 0]
        after = rec.time >= t_push
        outside = np.flatnonzero(after & (np.abs(y) > RECOVERY_BAND))
        if outside.size == 0:
            recovery = 0.0
        elif outside[-1] == len(y) - 1:
            recovery = float("nan")
        else:
            recovery = float(rec.time[outside[-1] + 1] - t_push)
        status = "recovered" if np.isfinite(recovery) else "not recovered"
        out[float(r)] = PushResult(status, float(np.max(np.abs(y[after]))), recovery, rec)
    return out


def _brief(res: CaseResult) -> str:
    if not res.summary:
        return res.status
    s = res.summary
    return f"{res.status}; overshoot {s['overshoot']:.0f} %; peak |u| {s['peak']:.1f} V; control {s['control']}"


def _thesis_61(r: float, case: str, key: int) -> object:
    printed = TABLE_6_1.get((r, case))
    if printed is None:
        return "not in Table 6.1"
    return printed[key]


def _table_6_1_side(lin: Mapping, twin: Mapping, weights: Sequence[float]) -> ComparisonTable:
    table = side_by_side("Table 6.1: SAS and CSAS (Q = I), square wave +-0.2 rad; controllers designed on eq. (3.11)",
                         ["R", "case", "measure"])
    for r in weights:
        for case in CASES:
            a, b = lin[(r, case)], twin[(r, case)]
            for key, label in ((0, "TR (s)"), (1, "TS (s)"), (2, "control")):
                cells = []
                for res in (a, b):
                    if not res.summary:
                        cells.append(res.status)
                    elif key == 2:
                        cells.append(res.summary["control"])
                    elif key == 0:
                        cells.append(finite_or(res.summary["TR"], res.status))
                    elif res.status != "settled" or (np.isfinite(res.summary["TS"])
                                                      and res.summary["TS"] <= HELD_FRACTION * DEFAULT_PERIOD / 2):
                        cells.append(finite_or(res.summary["TS"], res.status))
                    else:
                        cells.append(f"{res.summary['TS wide']:.3g} ({WIDE_BAND:.0%} band; 2 % band not held)")
                note = ""
                if key == 0:
                    note = f"twin: {b.status}" + ("" if case != "SAS" else f"; rig (ch. 7): {CHAPTER_7_OUTCOMES[r]}")
                table.rows.append([r, case, label, _thesis_61(r, case, key), *cells, note])
    table.notes = [
        "Largest TR (10-90 %) and TS (2 % band) over the run's full-swing steps (the first step, from rest, is half "
        "as large); 'high' = commanded control beyond the deviation "
        "limit at some sample. The linear model runs calm with measurement noise; the twin adds encoder quantisation, "
        "gusts and its own nonlinear, flexible dynamics.",
        "Thesis values are the simulation of ch. 6 (R = 75 and 1); R = 100 and 125 were only run on the rig (ch. 7).",
    ]
    return table


def _table_7(lin: Mapping, twin: Mapping, weights: Sequence[float]) -> ComparisonTable:
    table = side_by_side("Ch. 7: the controllers on the rig (status; overshoot; peak |u|; control)", ["R", "case"])
    for r in weights:
        for case in ALL_CASES:
            if r == 1.0:
                thesis = "unstable (SAS); not run further"
            elif case == "SAS":
                thesis = CHAPTER_7_OUTCOMES[r].split(";")[0].replace("SAS: ", "")
            elif case == "CSAS BSF 0.25 & 0.34 Hz":
                thesis = "not run on the rig (ch. 7 used the 0.34 Hz band-stop)"
            else:
                thesis = CHAPTER_7_PREFILTER_OUTCOMES[case]
            table.rows.append([r, case, thesis, _brief(lin[(r, case)]), _brief(twin[(r, case)]), ""])
    best = _best(twin, weights)
    table.notes = [f"Twin, SAS alone: smallest overshoot with R = {best[0]:g}, smallest total variation of the control "
                   f"with R = {best[1]:g} (the rig's best was R = 125)." if best else "Twin: no SAS run settled."]
    return table


def _best(res: Mapping, weights: Sequence[float]) -> tuple[float, float] | None:
    ok = [r for r in weights if res[(r, "SAS")].status == "settled"]
    if not ok:
        return None
    return (min(ok, key=lambda r: res[(r, "SAS")].summary["overshoot"]),
            min(ok, key=lambda r: res[(r, "SAS")].summary["TV"]))


def _table_push(push: Mapping[float, PushResult]) -> ComparisonTable:
    t, j, w = PUSH
    table = side_by_side(f"Ch. 7.4: push rejection under SAS, impulse {j:g} N m s about pitch at {t:g} s", ["R", "measure"])
    for r, res in push.items():
        table.rows.append([r, "peak pitch after the push (rad)", "rejected (figs. 7.17-7.19)", "no torque input",
                           finite_or(res.peak, res.status), ""])
        table.rows.append([r, f"back within {RECOVERY_BAND:g} rad after (s)", "rejected", "no torque input",
                           finite_or(res.recovery, res.status), "the twin holds hover under gusts and noise meanwhile"])
    return table


def section(
    lin: Mapping[tuple[float, str], CaseResult],
    twin: Mapping[tuple[float, str], CaseResult],
    push: Mapping[float, PushResult],
    folder: str | os.PathLike[str],
    weights: Sequence[float] = LQG_WEIGHTS_R,
) -> Section:
    """The chapters 6 and 7 section: Table 6.1 and the rig's cases side by side, the push, figures."""
    folder = Path(folder)
    figs = []
    for r, case in ((125.0, "SAS"), (125.0, "CSAS LPF 0.2 Hz"), (75.0, "SAS"), (1.0, "SAS"), (100.0, "CSAS LPF 0.3 Hz")):
        if (r, case) not in twin:
            continue
        a, b = lin[(r, case)], twin[(r, case)]
        if a.record is None or b.record is None:
            continue
        slug = case.lower().replace(" & ", "_").replace(" ", "_").replace(".", "p")
        series = {"command": a.record.extras["reference"][:, 0], f"linear model ({a.status})": a.record.deviations()[1][:, 0],
                  f"twin ({b.status})": b.record.deviations()[1][:, 0]}
        figs.append(FigureRef(plot_series(folder / f"ch67_R{r:g}_{slug}.png", a.record.time, series,
                                          f"{case}, Q = I, R = {r:g}: linear model and twin (figs. 6.6-7.16)",
                                          "pitch (rad, deviation)",
                                          {"linear model u": a.record.extras["control"][:, 0],
                                           "twin u": b.record.extras["control"][:, 0]}),
                              f"{case} with R = {r:g}: pitch and commanded control on the linear model and on the twin."))
    recs = {f"R = {r:g} ({p.status})": p.record.deviations()[1][:, 0] for r, p in push.items() if p.record is not None}
    if recs:
        first = next(p.record for p in push.values() if p.record is not None)
        figs.append(FigureRef(plot_series(folder / "ch7_push_twin.png", first.time, recs,
                                          "Twin: push on the beam at 19 s under SAS (figs. 7.17-7.19)", "pitch (rad, deviation)"),
                              "Twin pitch holding hover under SAS while the beam is pushed at 19 s."))
    paragraphs = [
        "Integral LQG (Q = I, estimator Qe = I, Re = 1, current estimator, anti-windup) designed on eq. (3.11) for each R, "
        "with and without the command prefilters, tracking a square wave of +-0.2 rad (period 40 s, 80 s). The same "
        "controllers run on the linear model and on the twin, which adds encoder quantisation, measurement noise, gusts, "
        "+-10 V saturation about its own hover trim, and its nonlinear and flexible dynamics.",
    ]
    return Section("Chapters 6 and 7: LQG (SAS and CSAS) on the linear model and on the twin", paragraphs,
                   [_table_6_1_side(lin, twin, weights), _table_7(lin, twin, weights), _table_push(push)], figs)
