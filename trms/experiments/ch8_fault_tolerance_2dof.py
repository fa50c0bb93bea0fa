"""Fault-tolerant 2-DOF control on the twin (ch. 8's future work): the tail rotor sticks under the MIMO LQG.

The loop is ch. 8's MIMO integral LQG (:func:`trms.experiments.ch8_mimo_lqg.controllers`, both outputs tracked, two
inputs, Ts = 0.1 s) in the two ch. 8 scenarios (the pitch and the yaw step,
:data:`~trms.experiments.ch8_mimo_lqg.SCENARIOS`) on the twin in moving air. The fault: from :data:`FAULT_AT` the
tail rotor's voltage sticks at its trim (:class:`~trms.twin.faults.StuckRotor`), so the tail rotor no longer
answers the command, the classical total loss of an actuator.

**Detection.** As in :mod:`trms.experiments.ch8_fault_tolerance`: a windowed chi-square test on the nominal Kalman
predictor's innovations (both outputs), calibrated on fault-free runs of both scenarios (:data:`TRAIN_SEEDS`) for
:data:`~trms.experiments.ch8_fault_tolerance.FALSE_ALARM_RATE` false alarms per sample, its false alarms measured on
unseen fault-free seeds (:data:`FALSE_ALARM_SEEDS`).

**Reconfiguration.** :class:`~trms.control.reconfiguration.ReconfiguringLQG` estimates both inputs' effectiveness
after an alarm; an input below :data:`DROP_BELOW` is dropped. One input cannot hold two outputs at independent
set-points, so the re-design (:func:`design`) then keeps the pitch's integrator only (the axis gravity loads and
the one near its stops); the yaw error still reaches the estimator and the yaw is regulated through the main rotor's
reaction torque, without integral action, as far as the re-designed model lets u1 reach it
(:func:`reaches_yaw`).

**What the runs show** (:func:`fault_tolerance_2dof`; the table counts, per scenario, the runs in which the
re-designed loop holds each axis better than the nominal one): the fault is found within a few seconds and the tail
rotor's effectiveness estimated near 0 and dropped in the faulty runs. The yaw stays in u1's reach (controllable
subspace), but one input cannot hold both set-points: whether dropping the yaw's integral action pays depends on the
scenario (with the autopilot's tight pitch weight the nominal loop, which keeps bending the pitch towards the yaw,
holds the pitch step better, and the re-designed one the yaw step).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import control
import numpy as np

from trms.control.detection import ChiSquareDetector
from trms.control.loop import Controller, closed_loop, deviation_limits
from trms.control.lqg import LQGDesign, design_lqg
from trms.control.reconfiguration import ReconfiguringLQG
from trms.errors import check_in_range
from trms.experiments.ch8_fault_tolerance import (
    FALSE_ALARM_RATE,
    FAULT_AT,
    calibrate_and_count,
    check_seeds,
    design_innovations,
    rms_after,
)
from trms.experiments.ch8_mimo_lqg import DURATION, SCENARIOS, control_weights, controllers, scenario_reference, weights
from trms.present.tables import ComparisonTable
from trms.record import Record
from trms.twin.faults import FaultyTwin, StuckRotor
from trms.worlds import design_model, make_plant

__all__ = [
    "DROP_BELOW",
    "StuckTailRun",
    "StuckTail",
    "design",
    "reaches_yaw",
    "fault_tolerance_2dof",
    "table_fault_tolerance_2dof",
]

#: The chi-square test's window (samples: 4 s at Ts = 0.1 s).
WINDOW = 40
#: Samples after an alarm before the effectiveness is estimated (4 s).
DECIDE_AFTER = 40
#: An input whose estimated effectiveness is below this is dropped from the re-design.
DROP_BELOW = 0.3
#: The output that keeps its integrator when one input remains (0: the pitch).
KEPT_OUTPUT = 0
#: Seeds of the calibration runs, the false-alarm runs and the faulty runs: three disjoint sets.
TRAIN_SEEDS = tuple(range(20))
FALSE_ALARM_SEEDS = tuple(range(1000, 1020))
FAULT_SEEDS = tuple(range(2000, 2010))


@dataclass(frozen=True)
class StuckTailRun:
    """One scenario with the tail rotor stuck, at one seed.

    Attributes
    ----------
    scenario : str
    seed : int
    delay : float
        Detection delay of the calibrated test on the nominal loop's innovations (s from the fault; NaN: never).
    estimated : tuple of float
        The reconfiguring loop's least-squares effectiveness of (u1, u2) at its first decision after the fault
        (NaN: none).
    effectiveness : tuple of float
        The effectiveness of (u1, u2) it flies with at the end (0: dropped; 1, 1: never re-designed).
    switch_delay : float
        When it first re-designed itself after the fault (s from the fault; NaN: never).
    rms_healthy, rms_nominal, rms_reconfigured : tuple of float
        RMS tracking error of (pitch, yaw) from the fault to the end (rad): without the fault, under the nominal LQG,
        under the reconfiguring LQG.
    yaw_reachable : bool
        The loop's final design model lets its remaining inputs reach the yaw and yaw rate (:func:`reaches_yaw`).
    """

    scenario: str
    seed: int
    delay: float
    estimated: tuple[float, ...]
    effectiveness: tuple[float, ...]
    switch_delay: float
    rms_healthy: tuple[float, ...]
    rms_nominal: tuple[float, ...]
    rms_reconfigured: tuple[float, ...]
    yaw_reachable: bool


@dataclass(frozen=True)
class StuckTail:
    """The study: the calibrated test, its measured false alarms, and every faulty run.

    Attributes
    ----------
    detector : ChiSquareDetector
        The calibrated test on both innovations (covariance rad^2, threshold).
    false_alarm_rate : float
        Measured per-sample false-alarm rate on the unseen fault-free runs (NaN: none flown).
    runs_with_false_alarm : float
        Fraction of those runs with at least one alarm.
    wrong_switches : int
        Unseen fault-free runs in which the reconfiguring loop re-designed itself.
    n_false_alarm_runs : int
        Unseen fault-free runs (seeds times scenarios).
    runs : tuple of StuckTailRun
    n_train_runs : int
        Fault-free runs the test was calibrated on (seeds times scenarios).
    """

    detector: ChiSquareDetector
    false_alarm_rate: float
    runs_with_false_alarm: float
    wrong_switches: int
    n_false_alarm_runs: int
    runs: tuple[StuckTailRun, ...]
    n_train_runs: int


def design(model: control.StateSpace) -> LQGDesign:
    """Ch. 8's MIMO LQG of a 2-DOF model; with one input left (a zero column of ``B``), the pitch's integrator only.

    The weights are :func:`~trms.experiments.ch8_mimo_lqg.weights` and
    :func:`~trms.experiments.ch8_mimo_lqg.control_weights`: on the healthy model, the design of
    ``controllers(model)["MIMO LQG"]``.

    Examples
    --------
    >>> m = design_model("2dof")
    >>> design(m).tracked
    (0, 1)
    >>> lost = control.ss(m.A, np.asarray(m.B) * [1.0, 0.0], m.C, m.D, m.dt, states=list(m.state_labels),
    ...                   outputs=list(m.output_labels))
    >>> d = design(lost)
    >>> d.tracked, bool(np.all(d.K[1] == 0.0))  # the pitch integrated; the dropped input gets no gain
    ((0,), True)
    """
    kept = int(np.count_nonzero(np.any(np.asarray(model.B) != 0.0, axis=0)))
    tracked = list(range(model.noutputs)) if kept >= model.noutputs else [KEPT_OUTPUT]
    rows = [*range(model.nstates), *(model.nstates + i for i in tracked)]
    q = weights(model)[np.ix_(rows, rows)]
    return design_lqg(model, Q=q, R=control_weights(), tracked_outputs=tracked)


def reaches_yaw(model: control.StateSpace) -> bool:
    """Whether the yaw angle and rate lie in the controllable subspace of ``(A, B)``: u can move and stop the yaw.

    Examples
    --------
    >>> m = design_model("2dof")
    >>> reaches_yaw(m)
    True
    >>> reaches_yaw(control.ss(m.A, np.asarray(m.B) * [0.0, 1.0], m.C, m.D, m.dt, states=list(m.state_labels)))
    True
    """
    A, B = np.asarray(model.A, float), np.asarray(model.B, float)
    reach = control.ctrb(A, B)
    rank = np.linalg.matrix_rank(reach)
    labels = list(model.state_labels)
    unit = np.eye(A.shape[0])[:, [labels.index("yaw"), labels.index("yaw_rate")]]
    return bool(np.linalg.matrix_rank(np.hstack([reach, unit])) == rank)


def _fly(
    seed: int, scenario: str, stuck: bool, detector: ChiSquareDetector | None, steps: int
) -> tuple[Record, Controller]:
    """One run on the twin in moving air, the tail rotor stuck at its trim voltage from :data:`FAULT_AT` or healthy:
    the nominal MIMO LQG (no detector) or the reconfiguring one (returned with the record)."""
    twin = make_plant("twin", "2dof", seed=seed)
    model = design_model("2dof", twin.sample_time)
    limits = deviation_limits(twin)
    faults = (StuckRotor("u2", FAULT_AT, float(twin.operating_point.inputs[1])),) if stuck else ()
    if detector is None:
        loop: Controller = controllers(model, 1.0, limits)["MIMO LQG"]
    else:
        loop = ReconfiguringLQG(model, design, detector, limits, DECIDE_AFTER, 0.1, drop_below=DROP_BELOW)
    ref = scenario_reference(scenario, twin.sample_time)[:steps]
    meta = {"scenario": scenario, "tail rotor stuck": stuck}
    return closed_loop(FaultyTwin(twin, faults), loop, ref, seed=seed, metadata=meta), loop


def _reconfigured(
    seed: int, scenario: str, stuck: bool, detector: ChiSquareDetector, steps: int
) -> tuple[Record, ReconfiguringLQG]:
    record, loop = _fly(seed, scenario, stuck, detector, steps)
    assert isinstance(loop, ReconfiguringLQG)
    return record, loop


def fault_tolerance_2dof(
    train_seeds: Sequence[int] = TRAIN_SEEDS,
    false_alarm_seeds: Sequence[int] = FALSE_ALARM_SEEDS,
    fault_seeds: Sequence[int] = FAULT_SEEDS,
    scenarios: Sequence[str] = tuple(SCENARIOS),
    duration: float = DURATION,
) -> StuckTail:
    """Calibrate the test, count its false alarms, and fly the stuck tail rotor in every scenario at every seed.

    Parameters
    ----------
    train_seeds, false_alarm_seeds, fault_seeds : sequence of int
        Seeds of the calibration runs, the false-alarm runs and the faulty runs (disjoint sets), each flown in every
        scenario.
    scenarios : sequence of str
        Keys of :data:`trms.experiments.ch8_mimo_lqg.SCENARIOS`.
    duration : float
        Length of each run (s), in ``[FAULT_AT + 5, DURATION]``: the scenario's reference cut short.

    Returns
    -------
    StuckTail

    Examples
    --------
    >>> study = fault_tolerance_2dof((0,), (), (20,), ["pitch step"], duration=40.0)
    >>> run = study.runs[0]
    >>> # found, the tail rotor dropped, and the nominal loop holding the pitch step better (module docstring)
    >>> bool(run.delay < 5.0), run.effectiveness[1], bool(run.rms_reconfigured[0] < run.rms_nominal[0])
    (True, 0.0, False)
    """
    check_seeds(train_seeds, false_alarm_seeds, fault_seeds, scenarios, SCENARIOS)
    duration = check_in_range("duration", duration, FAULT_AT + 5.0, DURATION, unit=" s")
    model = design_model("2dof")
    nominal = design(model)
    start = int(round(FAULT_AT / model.dt))
    steps = int(round(duration / model.dt))
    fa = calibrate_and_count(
        lambda key: _fly(key[1], key[0], False, None, steps)[0],
        lambda key, detector: _reconfigured(key[1], key[0], False, detector, steps)[1],
        nominal,
        [(name, s) for name in scenarios for s in train_seeds],
        [(name, s) for name in scenarios for s in false_alarm_seeds],
        WINDOW,
    )
    detector = fa.detector
    runs = []
    for name in scenarios:
        for s in fault_seeds:
            healthy, _ = _fly(s, name, False, None, steps)
            faulty, _ = _fly(s, name, True, None, steps)
            fixed, loop = _reconfigured(s, name, True, detector, steps)
            hits = np.flatnonzero(detector.run(design_innovations(faulty, nominal)).alarms[start:])
            nan = float("nan")
            runs.append(
                StuckTailRun(
                    name,
                    int(s),
                    float(hits[0] * loop.sample_time) if hits.size else nan,
                    next((tuple(map(float, e)) for k, e in loop.estimates if k >= start), (nan, nan)),
                    tuple(float(v) for v in loop.effectiveness),
                    next(((k - start) * loop.sample_time for _, k in loop.switches if k >= start), nan),
                    rms_after(healthy, start),
                    rms_after(faulty, start),
                    rms_after(fixed, start),
                    reaches_yaw(loop.controller.design.model),
                )
            )
    return StuckTail(detector, fa.rate, fa.runs_alarmed, fa.redesigned, fa.runs, tuple(runs), fa.calibration_runs)


def _axes(rows: Sequence[StuckTailRun], field: str) -> str:
    values = np.array([getattr(r, field) for r in rows])
    return f"{np.median(values[:, 0]):.3f} / {np.median(values[:, 1]):.3f}"


def table_fault_tolerance_2dof(study: StuckTail) -> ComparisonTable:
    """The study as a table: per scenario, detection, the effectiveness estimated, and each axis' tracking loss.

    Examples
    --------
    >>> run = StuckTailRun("yaw step", 20, 10.1, (0.97, 0.02), (0.97, 0.0), 14.1, (0.05, 0.13),
    ...                    (0.05, 0.16), (0.06, 0.15), True)
    >>> study = StuckTail(ChiSquareDetector(np.eye(2) * 1e-5, WINDOW), 0.0, 0.0, 0, 40, (run,), 40)
    >>> table_fault_tolerance_2dof(study).rows[0][:4]
    ['yaw step', '1/1', 10.1, '0.97 (0.97-0.97) / 0.02 (0.02-0.02)']
    """
    table = ComparisonTable(
        "Ch. 8 future work: the tail rotor stuck at trim under the MIMO LQG on the twin (moving air)",
        [
            "scenario",
            "detected (runs)",
            "delay median (s)",
            "effectiveness estimated u1 / u2",
            "u2 dropped (runs)",
            "re-designed after (s)",
            "RMS healthy pitch / yaw (rad)",
            "RMS nominal LQG pitch / yaw (rad)",
            "RMS reconfigured pitch / yaw (rad)",
            "reconfigured better than nominal, pitch / yaw (runs)",
        ],
    )
    for name in dict.fromkeys(r.scenario for r in study.runs):
        rows = [r for r in study.runs if r.scenario == name]
        delays = np.array([r.delay for r in rows])
        switched = np.array([r.switch_delay for r in rows])
        eta = np.array([r.estimated for r in rows])
        found = np.isfinite(delays)
        table.rows.append(
            [
                name,
                f"{int(found.sum())}/{len(rows)}",
                float(np.median(delays[found])) if found.any() else float("nan"),
                " / ".join(
                    f"{np.nanmedian(e):.2f} ({np.nanmin(e):.2f}-{np.nanmax(e):.2f})" if np.isfinite(e).any() else "-"
                    for e in eta.T
                ),
                f"{sum(r.effectiveness[1] == 0.0 for r in rows)}/{len(rows)}",
                float(np.median(switched[np.isfinite(switched)])) if np.isfinite(switched).any() else "-",
                _axes(rows, "rms_healthy"),
                _axes(rows, "rms_nominal"),
                _axes(rows, "rms_reconfigured"),
                " / ".join(
                    f"{sum(r.rms_reconfigured[i] < r.rms_nominal[i] for r in rows)}/{len(rows)}" for i in (0, 1)
                ),
            ]
        )
    reach = [r.yaw_reachable for r in study.runs if r.effectiveness[1] == 0.0]
    d = study.detector
    table.notes += [
        f"Test: chi-square over {WINDOW} samples ({WINDOW * 0.1:g} s) of the nominal predictor's pitch and yaw "
        f"innovations, calibrated on {study.n_train_runs} fault-free runs for {FALSE_ALARM_RATE:g} false alarms per "
        f"sample (threshold {d.threshold:.3g}).",
        (
            f"Measured on {study.n_false_alarm_runs} unseen fault-free runs: {study.false_alarm_rate:.2g} alarms per "
            f"sample, {study.runs_with_false_alarm:.0%} of the runs with any alarm, {study.wrong_switches} re-designed "
            "the loop."
            if study.n_false_alarm_runs
            else "False alarms not measured (no unseen fault-free runs)."
        ),
        f"The tail rotor sticks at its trim voltage at {FAULT_AT:g} s; RMS tracking errors from then to the end, "
        "medians over the seeds. An input estimated below "
        f"{DROP_BELOW:g} is dropped; the re-design then integrates the pitch only.",
        (
            f"With u2 dropped, the re-designed model's u1 reaches the yaw and yaw rate (controllable subspace) in "
            f"{sum(reach)}/{len(reach)} runs."
            if reach
            else "u2 was never dropped."
        ),
    ]
    return table
