"""The thesis's future work flown side by side: integral LQG, PID, constrained MPC and H-infinity on the 1-DOF pitch.

Every controller is designed on the same model (eq. 3.11 at ``Ts``, the thesis's design model;
:mod:`trms.experiments.ch8_designs`) and flown as it is built there (its reference prefilter, the thrust-curve
inversion on the twin) on the same scenarios at the same seeds:

* **square wave** (+-0.2 rad, period 30 s, 60 s): on the linear model, on the twin in moving air (its rotor-wash
  turbulence and electronics noise, as on the rig) and on the twin in still air;
* **push** on the twin in moving air (ch. 7.4's push, :data:`~trms.experiments.ch67_lqg.PUSH`, at hover): the
  largest pitch excursion and the time back within :data:`~trms.experiments.ch67_lqg.RECOVERY_BAND`.

Measured per controller and case (:func:`~trms.control.metrics.square_wave_metrics`): overshoot, settling time and
the steps that never settle, in the band the plant's own noise allows (:func:`~trms.control.metrics.noise_band`:
``max(2 % of the step, 3 standard deviations of the same loop's output at rest)``, the rest measured by
:func:`rest_std` on a run of the same loop at the same seed holding hover) and in the 5 % band beside it, RMS
control, the share of the time commanded beyond the +-10 V limits, and the largest voltage jump a 0.4 rad step
causes; on the design model, each compensator's disk margin at the plant input
(:func:`~trms.control.margins.disk_margin`; MPC's is its law while no constraint acts) and its damping of the
0.34 Hz pitch mode (:func:`~trms.experiments.ch8_designs.design_damping`).

MPC needs ``osqp`` and H-infinity ``slycot`` (the ``control`` extra); without them those rows say so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import control
import numpy as np

from trms.batch import batch_closed_loop
from trms.control.damping import MIN_DAMPING, ModeDamping
from trms.control.loop import Controller, closed_loop
from trms.control.margins import DiskMargin, disk_margin
from trms.control.metrics import WIDE_BAND, StepMetrics, noise_band, square_wave_metrics
from trms.errors import InputError, check_choice
from trms.experiments.ch8_designs import (
    CONTROLLERS,
    DESIGN_DAMPING,
    DISTURBANCE_GRID,
    HINF_ROBUST,
    INVERSION,
    PREFILTER,
    SPREAD_WEIGHT,
    Designs,
    controllers_for,
    design_damping,
    designs_at,
    feedback_compensator,
    reference_prefilter,
)
from trms.experiments.ch67_lqg import PUSH, RECOVERY_BAND
from trms.plant import Plant
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable
from trms.record import Record
from trms.reference import SAMPLE_TIME_1DOF
from trms.signals import square_wave
from trms.twin import Twin
from trms.worlds import make_plant

__all__ = [
    "SQUARE",
    "CASES",
    "REST",
    "FULL_SWING",
    "ControllerCase",
    "Comparison",
    "Flight",
    "compare_controllers",
    "fly",
    "rest_std",
    "summarise_steps",
    "square_reference",
    "table_controllers",
    "table_designs",
]

#: The square-wave cases: (world, still air).
CASES = {"linear model": ("linear", False), "twin, moving air": ("twin", False), "twin, still air": ("twin", True)}
#: The square wave: duration (s), period (s), amplitude (rad).
SQUARE = (60.0, 30.0, 0.2)
#: The push run's length (s).
PUSH_DURATION = 40.0
#: The run at rest that measures a loop's noise at a target (:func:`rest_std`): its length and the start left out,
#: the way from hover to the target (s).
REST = (45.0, 15.0)
#: The full swing of the square wave (rad), to which the voltage jump is scaled.
FULL_SWING = 2.0 * SQUARE[2]


@dataclass(frozen=True)
class ControllerCase:
    """One controller on one case, over the seeds.

    Attributes
    ----------
    controller, case : str
    overshoot : float
        Mean overshoot of the steps (%).
    settling : float
        Median settling time of the settled steps (s; NaN if none settled), in the noise band (module docstring).
    unsettled : int
        Steps that never settled within the noise band.
    steps : int
    rms_control : float
        Mean RMS control (V, deviation).
    saturated : float
        Mean share of the time commanded beyond the limits (fraction).
    status : str
        ``"flown"``, or why not (a missing extra, a diverged run).
    settling_wide : float
        Median settling time of the steps settled within 5 % (s).
    unsettled_wide : int
        Steps that never settled within 5 %.
    band : float
        The noise band of a full-swing step at the flight's amplitude (fraction of that step), the largest over the
        seeds.
    jump : float
        The largest voltage jump (V, ``max |u(k) - u(k-1)|`` from the sample before a step) per
        :data:`FULL_SWING` of step, over the steps and seeds.
    """

    controller: str
    case: str
    overshoot: float
    settling: float
    unsettled: int
    steps: int
    rms_control: float
    saturated: float
    status: str = "flown"
    settling_wide: float = math.nan
    unsettled_wide: int = 0
    band: float = math.nan
    jump: float = math.nan


@dataclass(frozen=True)
class Comparison:
    """Every controller on every case, the push, the margins and the damping.

    Attributes
    ----------
    cases : tuple of ControllerCase
    push_peak, push_recovery : dict
        Per controller: the largest pitch excursion after the push (rad) and the time back within the recovery
        band (s; ``inf``: never), medians over the seeds.
    margins : dict
        Per controller: the disk margin on the design model, or ``None`` (a missing extra).
    seeds : tuple of int
    sample_time : float
    records : dict
        ``(controller, case)`` -> the square-wave Record at the first seed (for figures).
    damping : dict
        Per controller: the pitch mode's damping on the design model (:class:`~trms.control.damping.ModeDamping`).
    inversion : bool
        Whether the twin cases flew behind the thrust-curve inversion.
    """

    cases: tuple[ControllerCase, ...]
    push_peak: dict[str, float]
    push_recovery: dict[str, float]
    margins: dict[str, DiskMargin | None]
    seeds: tuple[int, ...]
    sample_time: float
    records: dict[tuple[str, str], Record] = field(default_factory=dict)
    damping: dict[str, ModeDamping] = field(default_factory=dict)
    inversion: bool = INVERSION


@dataclass(frozen=True)
class Flight:
    """One controller's square-wave runs on one case: a Record per seed (None where it diverged) and, per seed, the
    standard deviation (rad) of the loop's output at rest at each target of the reference (:func:`rest_std`)."""

    records: tuple[Record | None, ...]
    rest: tuple[dict[float, float], ...]


def square_reference(sample_time: float, scale: float = 1.0) -> np.ndarray:
    """The comparison's square wave (:data:`SQUARE`) at ``sample_time`` (s), its amplitude times ``scale``:
    deviation rad, one per sample.

    Examples
    --------
    >>> r = square_reference(0.2)
    >>> r.shape, float(r.max()), float(square_reference(0.2, 0.5).max())
    ((300,), 0.2, 0.1)
    """
    return square_wave(SQUARE[0], sample_time, SQUARE[1], SQUARE[2] * scale)


def _runs(
    plants: Sequence[Plant], controllers: Sequence[Controller], reference: np.ndarray, seeds: Sequence[int], ts: float
) -> list[Record | None]:
    """Each plant under its controller through the comparison's prefilter: one batch on twins, one loop each on
    linear models (a diverged twin run is None)."""
    prefilter = reference_prefilter(ts)
    twins = [p for p in plants if isinstance(p, Twin)]
    if len(twins) == len(plants):
        return batch_closed_loop(twins, list(controllers), reference, prefilter, list(seeds)).records
    return [closed_loop(p, c, reference, prefilter, seed=s) for p, c, s in zip(plants, controllers, seeds)]


def rest_std(
    plants: Sequence[Plant], controllers: Sequence[Controller], seeds: Sequence[int], level: float = 0.0
) -> list[float]:
    """Each loop's measured output at rest at ``level``: the standard deviation (rad) of the first output over a
    run holding the reference at ``level`` (deviation rad) for :data:`REST` (its first seconds, the way there, left
    out), at the plant's seed.

    Examples
    --------
    >>> from trms.experiments.ch8_designs import controllers_for
    >>> plant = make_plant("twin", "1dof", seed=3, still_air=True)
    >>> rest_std([plant], [controllers_for(designs_at(0.2), plant)[0]["LQG"]], [3])
    [0.0]
    """
    ts = float(plants[0].sample_time)
    n = int(round(REST[0] / ts))
    skip = int(round(REST[1] / ts))
    records = _runs(plants, controllers, np.full(n, float(level)), seeds, ts)
    out = []
    for rec in records:
        out.append(math.nan if rec is None else float(np.std(rec.deviations()[1][skip:, 0])))
    return out


def fly(
    designs: Designs,
    world: str,
    still_air: bool,
    seeds: Sequence[int],
    scale: float = 1.0,
    inversion: bool = INVERSION,
    quantised: bool = True,
) -> tuple[dict[str, Flight], dict[str, str]]:
    """Every controller on the square wave (its amplitude times ``scale``) at each seed in one world, and each
    loop's rest at each target of the reference (:func:`rest_std`; none in still air, where nothing moves the plant
    at rest).

    Returns
    -------
    flights : dict
        Name -> :class:`Flight`.
    missing : dict
        Name -> why it was not flown.

    Examples
    --------
    >>> flights, missing = fly(designs_at(0.2), "twin", True, (5,), scale=0.5)
    >>> sorted(flights) == sorted(CONTROLLERS) or bool(missing), flights["LQG"].rest
    (True, ({},))
    """
    ts = float(designs.model.dt)
    twin = world == "twin"
    plants = [
        make_plant(world, "1dof", ts, seed=s, still_air=still_air, quantised=quantised)
        if twin
        else make_plant(world, "1dof", ts, seed=s)
        for s in seeds
    ]
    built = [controllers_for(designs, p, inversion) for p in plants]
    reference = square_reference(ts, scale)
    flights = {}
    for name in built[0][0]:
        records = _runs(plants, [b[0][name] for b in built], reference, seeds, ts)
        levels = sorted({float(v) for v in reference if v != 0.0})
        rest: list[dict[float, float]] = [{} for _ in seeds]
        if not still_air:
            for level in levels:
                values = rest_std(plants, [b[0][name] for b in built], seeds, level)  # each run resets them
                for i, v in enumerate(values):
                    rest[i][level] = v
        flights[name] = Flight(tuple(records), tuple(rest))
    return flights, built[0][1]


def summarise_steps(name: str, case: str, flight: Flight, half_period: float) -> ControllerCase:
    """A flight's steps (all seeds) in one row (:class:`ControllerCase`): means of overshoot, RMS control and
    saturated share (of each step's half period), medians of the settled steps' settling times, counts of the
    steps never settled, the noise band and the voltage jump.

    Examples
    --------
    >>> flights, _ = fly(designs_at(0.2), "linear", False, (0,))
    >>> row = summarise_steps("LQG", "linear model", flights["LQG"], 15.0)
    >>> row.steps, row.unsettled, bool(row.band >= 0.02), bool(row.jump < 0.2)
    (4, 0, True, True)
    """
    runs = [(r, s) for r, s in zip(flight.records, flight.rest) if r is not None]
    if len(runs) < len(flight.records):
        nan = math.nan
        return ControllerCase(
            name, case, nan, nan, 0, 0, nan, nan, f"diverged at {len(flight.records) - len(runs)} seed(s)"
        )
    steps: list[StepMetrics] = []
    wide: list[StepMetrics] = []
    bands = []
    for record, rest in runs:
        here = square_wave_metrics(record, rest_std=rest)
        steps += here
        wide += square_wave_metrics(record, band=WIDE_BAND)
        swing = max(abs(s.target - s.initial) for s in here)  # the full swing at this flight's amplitude
        bands.append(noise_band(swing, max(rest.values(), default=0.0)))
    settle = np.array([s.settling_time for s in steps])
    settle_w = np.array([s.settling_time for s in wide])
    jump = max(s.largest_move * FULL_SWING / abs(s.target - s.initial) for s in steps)
    return ControllerCase(
        name,
        case,
        float(np.mean([s.overshoot for s in steps])),
        float(np.median(settle[np.isfinite(settle)])) if np.isfinite(settle).any() else math.nan,
        int(np.isnan(settle).sum()),
        len(steps),
        float(np.mean([s.rms_control for s in steps])),
        float(np.mean([s.saturated_time for s in steps])) / half_period,
        settling_wide=float(np.median(settle_w[np.isfinite(settle_w)])) if np.isfinite(settle_w).any() else math.nan,
        unsettled_wide=int(np.isnan(settle_w).sum()),
        band=max(bands),
        jump=float(jump),
    )


def compare_controllers(
    seeds: Sequence[int] = (0, 1, 2),
    sample_time: float = SAMPLE_TIME_1DOF,
    cases: Sequence[str] = tuple(CASES),
    push: bool = True,
    inversion: bool = INVERSION,
) -> Comparison:
    """Fly every controller on every case and the push at ``seeds`` (see the module docstring).

    Parameters
    ----------
    seeds : sequence of int
        Plant seeds (noise, turbulence), the same for every controller.
    sample_time : float
        Sample time of the designs and the plants (s): the thesis's 0.2 s, or 0.1 s.
    cases : sequence of str
        Keys of :data:`CASES` to fly (all by default).
    push : bool
        Fly the push too.
    inversion : bool
        Fly the twin behind the thrust-curve inversion (:data:`~trms.experiments.ch8_designs.INVERSION`).

    Returns
    -------
    Comparison

    Examples
    --------
    >>> c = compare_controllers(seeds=(0,), cases=["linear model"], push=False)
    >>> [(k.controller, k.unsettled, k.steps) for k in c.cases][:4]
    [('LQG', 0, 4), ('PID', 0, 4), ('MPC', 0, 4), ('H-infinity', 0, 4)]
    >>> round(c.margins["LQG"].gain_margin_db, 1), all(m.meets() for m in c.damping.values())
    (10.2, True)
    """
    seeds = tuple(int(s) for s in seeds)
    if not seeds:
        raise InputError("seeds must name at least one seed")
    ts = float(check_choice("sample_time", float(sample_time), (0.2, 0.1), error=InputError))
    for case in cases:
        check_choice("case", case, tuple(CASES), error=InputError)
    designs = designs_at(ts)
    rows = []
    records: dict[tuple[str, str], Record] = {}
    for case in cases:
        world, still = CASES[case]
        flights, missing = fly(designs, world, still, seeds, inversion=inversion)
        for name in CONTROLLERS:
            if name not in flights:
                nan = math.nan
                rows.append(ControllerCase(name, case, nan, nan, 0, 0, nan, nan, f"not flown: {missing[name]}"))
                continue
            rows.append(summarise_steps(name, case, flights[name], SQUARE[1] / 2.0))
            first = flights[name].records[0]
            if first is not None:
                records[(name, case)] = first
    peak, recovery = _push(designs, seeds, ts, inversion) if push else ({}, {})
    return Comparison(
        tuple(rows), peak, recovery, _margins(designs), seeds, ts, records, design_damping(designs), inversion
    )


def _margins(designs: Designs) -> dict[str, DiskMargin | None]:
    """Disk margins at the plant input of every controller's feedback law on the design model."""
    controllers, _ = controllers_for(designs, make_plant("linear", "1dof", float(designs.model.dt)), False)
    out: dict[str, DiskMargin | None] = dict.fromkeys(CONTROLLERS)
    for name, c in controllers.items():
        k = feedback_compensator(c)
        out[name] = None if k is None else disk_margin(control.series(designs.model, k))
    return out


def _push(
    designs: Designs, seeds: tuple[int, ...], ts: float, inversion: bool
) -> tuple[dict[str, float], dict[str, float]]:
    """Every controller at hover on the twin in moving air, pushed as in ch. 7.4."""
    from trms.twin import Push

    t_push, impulse, width = PUSH
    n = int(round(PUSH_DURATION / ts))
    peaks: dict[str, list[float]] = {c: [] for c in CONTROLLERS}
    backs: dict[str, list[float]] = {c: [] for c in CONTROLLERS}
    for seed in seeds:
        plant = make_plant("twin", "1dof", ts, seed=seed, pushes=[Push.impulse(t_push, impulse, width, "pitch")])
        controllers, _ = controllers_for(designs, plant, inversion)
        for name, controller in controllers.items():
            record = closed_loop(plant, controller, np.zeros(n), seed=seed)
            y = record.deviations()[1][:, 0]
            after = record.time >= t_push
            peaks[name].append(float(np.max(np.abs(y[after]))))
            outside = np.flatnonzero(after & (np.abs(y) > RECOVERY_BAND))
            last = record.time[outside[-1]] if outside.size else t_push
            backs[name].append(math.inf if outside.size and outside[-1] == len(y) - 1 else float(last - t_push))
    med = {c: float(np.median(v)) if v else math.nan for c, v in peaks.items()}
    rec = {c: float(np.median(v)) if v else math.nan for c, v in backs.items()}
    return med, rec


def _push_cell(values: dict[str, float], controller: str, otherwise: str) -> float | str:
    """A push cell: "not flown" without a push run, else the value or ``otherwise`` (a recovery never reached)."""
    if controller not in values:
        return "not flown"
    return finite_or(values[controller], otherwise)


def table_controllers(comparison: Comparison) -> ComparisonTable:
    """The comparison as a table: one row per controller and case, the push in the twin's moving-air rows.

    Examples
    --------
    >>> case = ControllerCase("LQG", "linear model", 4.1, 9.7, 0, 4, 0.3, 0.0)
    >>> t = table_controllers(Comparison((case,), {"LQG": 0.1}, {"LQG": 3.0}, {}, (0,), 0.2))
    >>> t.rows[0][:4]
    ['LQG', 'linear model', 4.1, 9.7]
    """
    table = ComparisonTable(
        f"Ch. 8 future work: LQG, PID, MPC and H-infinity on the 1-DOF pitch (Ts = {comparison.sample_time:g} s)",
        [
            "controller",
            "case",
            "overshoot (%)",
            "settling, noise band (s)",
            "steps unsettled, noise band",
            "settling, 5 % (s)",
            "steps unsettled, 5 %",
            "noise band (% of the step)",
            "voltage jump per 0.4 rad step (V)",
            "RMS control (V)",
            "time saturated (%)",
            "push peak (rad)",
            "push recovery (s)",
        ],
    )
    for c in comparison.cases:
        flown = c.status == "flown"
        twin_moving = c.case == "twin, moving air"
        table.rows.append(
            [
                c.controller,
                c.case,
                finite_or(c.overshoot, "not flown"),
                finite_or(c.settling, "none settled") if flown else "not flown",
                f"{c.unsettled}/{c.steps}" if flown else c.status,
                finite_or(c.settling_wide, "none settled") if flown else "not flown",
                f"{c.unsettled_wide}/{c.steps}" if flown else "-",
                finite_or(100.0 * c.band, "-"),
                finite_or(c.jump, "-"),
                finite_or(c.rms_control, "not flown"),
                finite_or(100.0 * c.saturated, "not flown"),
                _push_cell(comparison.push_peak, c.controller, "not flown") if twin_moving else "-",
                _push_cell(comparison.push_recovery, c.controller, "never") if twin_moving else "-",
            ]
        )
    sq = SQUARE
    pf = reference_prefilter(comparison.sample_time).name
    table.notes += [
        f"Square wave +-{sq[2]:g} rad, period {sq[1]:g} s, {sq[0]:g} s; seeds {', '.join(map(str, comparison.seeds))}, "
        "the same for every controller; means over the steps and seeds, settling the median of the settled steps.",
        "Settling in the noise band: max(2 % of the step, 3 standard deviations of the same loop's measured pitch "
        f"at rest at the step's target), the rest measured on a {REST[0]:g} s run of that loop at that seed holding "
        f"the target (its first {REST[1]:g} s, the way there, left out); in still air nothing moves the twin at rest "
        "and the band is 2 %. The band column gives the widest, as a share of the 0.4 rad step; the 5 % band beside "
        "it.",
        f"Every controller follows the reference through the thesis's CSAS prefilter ({PREFILTER}: {pf}); "
        "the voltage jump is the largest change of the command from one sample to the next after a step, per "
        f"{FULL_SWING:g} rad of step. On the twin the controllers fly "
        + (
            "behind the thrust-curve inversion (trms.control.inversion: the command is read as thrust about "
            "hover and sent through the inverse of the twin's calibrated thrust curve)."
            if comparison.inversion
            else "without the thrust-curve inversion."
        ),
    ]
    return table


def table_designs(comparison: Comparison) -> ComparisonTable:
    """Each design on eq. (3.11): the pitch mode's damping in its closed loop (and the least damped closed-loop
    pole), and the disk margin at the plant input.

    Examples
    --------
    >>> from trms.control.damping import mode_damping
    >>> from trms.control.margins import DiskMargin
    >>> from trms.control.pid import PIDController, PIDGains
    >>> from trms.worlds import design_model
    >>> m = mode_damping(design_model("1dof"), -PIDController(PIDGains(0.1, 0.1, 0.0), 0.2).compensator()[0, 1])
    >>> margin = DiskMargin(1.05, (0.31, 3.21), 10.1, 55.4, 0.05, True)
    >>> t = table_designs(Comparison((), {}, {}, {"PID": margin}, (0,), 0.2, damping={"PID": m}))
    >>> t.rows[0][0], t.rows[0][-1]
    ('PID', '10.1 dB, 55.4 deg')
    """
    table = ComparisonTable(
        "Ch. 8 designs on eq. (3.11): the 0.34 Hz pitch mode damped, not cancelled "
        f"(Ts = {comparison.sample_time:g} s)",
        [
            "controller",
            "plant mode (Hz)",
            "plant damping",
            "closed-loop mode (Hz)",
            "closed-loop damping",
            f"damped (>= {MIN_DAMPING:g})",
            "least damped closed-loop pole (Hz, damping)",
            "disk margin (dB, deg)",
        ],
    )
    for name in CONTROLLERS:
        d = comparison.damping.get(name)
        margin = comparison.margins.get(name)
        if d is None and margin is None:
            continue
        table.rows.append(
            [
                name,
                "-" if d is None else d.plant.frequency_hz,
                "-" if d is None else d.plant.damping,
                "-" if d is None else d.closed.frequency_hz,
                "-" if d is None else d.closed.damping,
                "-" if d is None else ("yes" if d.meets() else "no"),
                "-" if d is None else f"{d.least.frequency_hz:.3g} Hz, {d.least.damping:.3g}",
                "-" if margin is None else f"{margin.gain_margin_db:.1f} dB, {margin.phase_margin_deg:.1f} deg",
            ]
        )
    table.notes += [
        "Each design's feedback law (MPC: its law while no constraint acts) closed around eq. (3.11); the plant's "
        "mode followed as the loop gain grows from 0 to the design's (trms.control.damping.mode_damping). A "
        "closed-loop damping equal to the plant's means the controller cancels the mode: a reference step does not "
        "excite it, any input disturbance does.",
        "The designs: LQG R = 75 (the thesis's); PID with a second-order measurement filter, tuned with the damping "
        f"constraint {MIN_DAMPING:g} (a PID alone reaches 0.09); MPC horizon 30, +-10 V, 1 V per sample, the end "
        "stops; H-infinity mixed sensitivity with the default weights, with "
        f"{HINF_ROBUST}, and with the default weights and W3 = W_I(s) (the twin's input uncertainty over the "
        f"parameter spread, {SPREAD_WEIGHT}), each with the lightest input-disturbance weight Wd of "
        f"{DISTURBANCE_GRID} V that damps the mode to {DESIGN_DAMPING:g}; disk margins at the plant input.",
    ]
    return table
