"""Fault-tolerant pitch control on the twin (the thesis's future work, ch. 8): detect, isolate, reconfigure.

The loop is the thesis's 1-DOF integral LQG (``R = 75``, designed on eq. 3.11, Ts = 0.2 s) tracking the ch. 6
square wave on the twin in moving air. Faults (:mod:`trms.twin.faults`) begin at :data:`FAULT_AT`:

* the main rotor loses 30 % or 50 % of its thrust;
* the pitch encoder drops out (its reading freezes) for 10 s.

**Detection.** The nominal Kalman predictor's innovations (:func:`~trms.control.detection.innovations`) are tested
by a windowed chi-square test (:class:`~trms.control.detection.ChiSquareDetector`). Eq. (3.11) is not the twin and
the thesis's estimator covariances are tuning, not noise: the innovations are neither of the predicted covariance
nor white. So the test is calibrated on fault-free runs (:meth:`~trms.control.detection.ChiSquareDetector.calibrated`
at seeds :data:`TRAIN_SEEDS`) for the stated per-sample false-alarm rate, and that rate is then measured on other
fault-free seeds (:data:`FALSE_ALARM_SEEDS`).

**Reconfiguration.** :class:`~trms.control.reconfiguration.ReconfiguringLQG` estimates, after an alarm, the main
rotor's effectiveness by least squares from the innovations and re-designs the LQG on eq. (3.11) with that input gain;
a pitch reading that has not moved for :data:`FROZEN` samples is taken as a dead encoder, and the loop runs on its
model until the reading moves again.
The tracking loss is the RMS tracking error from the fault to the end, healthy, faulty under the nominal LQG, and
faulty under the reconfiguring one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

import control
import numpy as np

from trms.control.detection import ChiSquareDetector, innovations
from trms.control.loop import closed_loop, deviation_limits
from trms.control.lqg import LQGDesign
from trms.control.reconfiguration import ReconfiguringLQG
from trms.errors import InputError
from trms.experiments.ch67_lqg import case_setup, design
from trms.present.tables import ComparisonTable
from trms.record import Record
from trms.twin.faults import EncoderDropout, Fault, FaultyTwin, ThrustLoss
from trms.worlds import design_model, make_plant

__all__ = [
    "FAULT_AT",
    "SCENARIOS",
    "FaultRun",
    "FaultTolerance",
    "check_seeds",
    "FalseAlarms",
    "calibrate_and_count",
    "design_innovations",
    "rms_after",
    "fault_tolerance",
    "table_fault_tolerance",
]

#: When every fault begins (s): the middle of the square wave's second half-period.
FAULT_AT = 30.0
#: The control weight of the loop (the thesis's ch. 6 design).
R_WEIGHT = 75.0
#: Length of each run (s): two periods of the 40 s square wave.
DURATION = 80.0
#: The window of the chi-square test (samples: 8 s at Ts = 0.2 s; a shorter one alarms at every step of the
#: square wave, where eq. 3.11's mismatch with the twin is largest).
WINDOW = 40
#: The per-sample false-alarm rate the test is designed for.
FALSE_ALARM_RATE = 1e-3
#: A run's key in :func:`calibrate_and_count`.
T = TypeVar("T")
#: Samples after an alarm before the effectiveness is estimated (4 s: the window before the alarm and these).
DECIDE_AFTER = 40
#: Samples without a change of the pitch reading after which the reconfiguring loop takes the encoder as frozen (2 s;
#: the twin's reading, like the rig's, moves every few samples in moving air).
FROZEN = 10
#: Seeds of the fault-free runs the test is calibrated on, of those its false alarms are counted on, and of the
#: faulty runs: three disjoint sets.
TRAIN_SEEDS = tuple(range(20))
FALSE_ALARM_SEEDS = tuple(range(1000, 1050))
FAULT_SEEDS = tuple(range(2000, 2010))
#: The faults flown.
SCENARIOS: dict[str, tuple[Fault, ...]] = {
    "main rotor thrust -30 %": (ThrustLoss("u1", 0.3, at=FAULT_AT),),
    "main rotor thrust -50 %": (ThrustLoss("u1", 0.5, at=FAULT_AT),),
    "pitch encoder dropout 10 s": (EncoderDropout("pitch", at=FAULT_AT, duration=10.0),),
}


@dataclass(frozen=True)
class FaultRun:
    """One faulty scenario at one seed.

    Attributes
    ----------
    scenario : str
    seed : int
    delay : float
        Detection delay of the calibrated test on the nominal loop's innovations (s from the fault; NaN: never).
    effectiveness : float
        The main rotor's effectiveness the reconfiguring loop estimated and re-designed for (1: it never did).
    rms_healthy, rms_nominal, rms_reconfigured : float
        RMS tracking error from the fault to the end (rad): without the fault, under the nominal LQG, under the
        reconfiguring LQG.
    sensor_delay : float
        When the reconfiguring loop took the pitch reading as frozen (s from the fault; NaN: it never did).
    """

    scenario: str
    seed: int
    delay: float
    effectiveness: float
    rms_healthy: float
    rms_nominal: float
    rms_reconfigured: float
    sensor_delay: float = float("nan")


@dataclass(frozen=True)
class FaultTolerance:
    """The study: the calibrated test, its measured false alarms, and every faulty run.

    Attributes
    ----------
    detector : ChiSquareDetector
        The calibrated test (covariance rad^2, threshold).
    false_alarm_rate : float
        Measured per-sample false-alarm rate on the unseen fault-free runs.
    runs_with_false_alarm : float
        Fraction of those runs with at least one alarm.
    wrong_switches : int
        Unseen fault-free runs in which the reconfiguring loop re-designed itself.
    n_false_alarm_runs : int
    runs : tuple of FaultRun
    n_train_runs : int
        Fault-free runs the test was calibrated on.
    """

    detector: ChiSquareDetector
    false_alarm_rate: float
    runs_with_false_alarm: float
    wrong_switches: int
    n_false_alarm_runs: int
    runs: tuple[FaultRun, ...]
    n_train_runs: int = len(TRAIN_SEEDS)


def _design(model: control.StateSpace) -> LQGDesign:
    return design(model, R_WEIGHT)


def _fly(
    seed: int, faults: Sequence[Fault], detector: ChiSquareDetector | None, model: control.StateSpace
) -> tuple[Record, ReconfiguringLQG | None]:
    """One run on the twin in moving air: the nominal LQG, or with ``detector`` the reconfiguring one (returned)."""
    twin = make_plant("twin", "1dof", seed=seed)
    nominal, ref, _, meta = case_setup(twin, R_WEIGHT, "SAS", duration=DURATION, model=model)
    limits = deviation_limits(twin)
    loop = None if detector is None else ReconfiguringLQG(model, _design, detector, limits, DECIDE_AFTER, 0.1, FROZEN)
    record = closed_loop(FaultyTwin(twin, faults), nominal if loop is None else loop, ref, seed=seed, metadata=meta)
    return record, loop


def _reconfigured(
    seed: int, faults: Sequence[Fault], detector: ChiSquareDetector, model: control.StateSpace
) -> tuple[Record, ReconfiguringLQG]:
    record, loop = _fly(seed, faults, detector, model)
    assert loop is not None
    return record, loop


def design_innovations(record: Record, lqg: LQGDesign) -> np.ndarray:
    """The innovations of ``lqg``'s Kalman predictor (on its design model) over a closed-loop Record's deviations."""
    du, dy = record.deviations()
    m = lqg.model
    return innovations(m.A, m.B, m.C, lqg.Lp, du, dy)


def rms_after(record: Record, start: int) -> tuple[float, ...]:
    """RMS tracking error of each tracked output (rad) from sample ``start`` on."""
    err = record.extras["reference"][start:] - record.deviations()[1][start:, : record.extras["reference"].shape[1]]
    return tuple(float(v) for v in np.sqrt(np.mean(err**2, axis=0)))


@dataclass(frozen=True)
class FalseAlarms:
    """The χ² test calibrated on fault-free runs, and its false alarms on unseen fault-free runs.

    Attributes
    ----------
    detector : ChiSquareDetector
    rate : float
        Alarms per sample, pooled (after each run's first window).
    runs_alarmed : float
        Share of the runs with any alarm.
    redesigned : int
        Runs of the reconfiguring loop that re-designed.
    runs : int
        Fault-free runs judged.
    calibration_runs : int
    """

    detector: ChiSquareDetector
    rate: float
    runs_alarmed: float
    redesigned: int
    runs: int
    calibration_runs: int


def calibrate_and_count(
    healthy: Callable[[T], Record],
    reconfigured: Callable[[T, ChiSquareDetector], ReconfiguringLQG],
    nominal: LQGDesign,
    train: Sequence[T],
    unseen: Sequence[T],
    window: int = WINDOW,
) -> FalseAlarms:
    """Calibrate the test on the ``train`` runs' innovations (:data:`FALSE_ALARM_RATE`, a ``window``-sample window),
    then count its alarms, and the reconfiguring loop's re-designs, on the ``unseen`` fault-free runs.

    Parameters
    ----------
    healthy : callable
        A run's key -> the nominal loop's fault-free Record.
    reconfigured : callable
        A run's key and the test -> the reconfiguring loop after its fault-free run.
    nominal : LQGDesign
        The nominal loop's design (its predictor gives the innovations).
    train, unseen : sequence
        The runs' keys (seeds, or scenario and seed).
    window : int
        The test's window (samples).

    Returns
    -------
    FalseAlarms
    """
    # the first window of each run is the predictor's start-up from rest
    calibration = [design_innovations(healthy(k), nominal)[window:] for k in train]
    detector = ChiSquareDetector.calibrated(calibration, window, FALSE_ALARM_RATE)
    alarms, any_alarm, wrong = [], [], 0
    for k in unseen:
        result = detector.run(design_innovations(healthy(k), nominal)[window:])
        alarms.append(result.alarms[window - 1 :])
        any_alarm.append(bool(result.alarms.any()))
        wrong += reconfigured(k, detector).switch_sample is not None
    pooled = np.concatenate(alarms) if alarms else np.zeros(0, bool)
    return FalseAlarms(
        detector,
        float(pooled.mean()) if pooled.size else float("nan"),
        float(np.mean(any_alarm)) if any_alarm else float("nan"),
        wrong,
        len(any_alarm),
        len(calibration),
    )


def check_seeds(
    train_seeds: Sequence[int],
    false_alarm_seeds: Sequence[int],
    fault_seeds: Sequence[int],
    scenarios: Sequence[str],
    allowed: Mapping[str, object],
) -> None:
    """Refuse, in one line, a fault study's seeds that overlap or name no calibration run, or unknown scenarios.

    Parameters
    ----------
    train_seeds, false_alarm_seeds, fault_seeds : sequence of int
        Seeds of the calibration, false-alarm and faulty runs.
    scenarios : sequence of str
        Scenario names, each a key of ``allowed``.
    allowed : mapping
        The study's scenarios by name.

    Examples
    --------
    >>> check_seeds((0, 1), (5,), (1,), [], SCENARIOS)
    Traceback (most recent call last):
    ...
    trms.errors.InputError: the calibration, false-alarm and fault seeds must be disjoint sets
    """
    seeds = [set(train_seeds), set(false_alarm_seeds), set(fault_seeds)]
    if any(a & b for i, a in enumerate(seeds) for b in seeds[i + 1 :]):
        raise InputError("the calibration, false-alarm and fault seeds must be disjoint sets")
    if isinstance(scenarios, str) or not all(isinstance(x, str) for x in scenarios):
        raise InputError(f"scenarios must be a list of names, got {scenarios!r}; allowed: {list(allowed)}")
    unknown = [s for s in scenarios if s not in allowed]
    if unknown:
        raise InputError(f"unknown scenarios {unknown}; allowed: {list(allowed)}")
    if not list(train_seeds):
        raise InputError("train_seeds must name at least one calibration run")


def fault_tolerance(
    train_seeds: Sequence[int] = TRAIN_SEEDS,
    false_alarm_seeds: Sequence[int] = FALSE_ALARM_SEEDS,
    fault_seeds: Sequence[int] = FAULT_SEEDS,
    scenarios: Sequence[str] = tuple(SCENARIOS),
) -> FaultTolerance:
    """Calibrate the test, count its false alarms, and fly every scenario at every seed (see the module docstring).

    Parameters
    ----------
    train_seeds, false_alarm_seeds, fault_seeds : sequence of int
        Seeds of the calibration runs, the false-alarm runs and the faulty runs (disjoint sets).
    scenarios : sequence of str
        Keys of :data:`SCENARIOS`.

    Returns
    -------
    FaultTolerance

    Examples
    --------
    >>> study = fault_tolerance((0, 1), (), (20,), ["main rotor thrust -50 %"])
    >>> run = study.runs[0]
    >>> bool(run.delay < 3.0), bool(0.4 < run.effectiveness < 0.7), bool(run.rms_reconfigured < run.rms_nominal)
    (True, True, True)
    """
    check_seeds(train_seeds, false_alarm_seeds, fault_seeds, scenarios, SCENARIOS)
    model = design_model("1dof")
    nominal = design(model, R_WEIGHT)
    start = int(round(FAULT_AT / model.dt))
    fa = calibrate_and_count(
        lambda s: _fly(s, (), None, model)[0],
        lambda s, detector: _reconfigured(s, (), detector, model)[1],
        nominal,
        list(train_seeds),
        list(false_alarm_seeds),
    )
    detector = fa.detector
    runs = []
    healthy_rms = {s: rms_after(_fly(s, (), None, model)[0], start)[0] for s in fault_seeds}  # the same per scenario
    for name in scenarios:
        for s in fault_seeds:
            faulty, _ = _fly(s, SCENARIOS[name], None, model)
            fixed, loop = _reconfigured(s, SCENARIOS[name], detector, model)
            stat = detector.run(design_innovations(faulty, nominal)).alarms
            hits = np.flatnonzero(stat[start:])
            delay = float(hits[0] * model.dt) if hits.size else float("nan")
            runs.append(
                FaultRun(
                    name,
                    int(s),
                    delay,
                    float(loop.effectiveness[0]),
                    healthy_rms[s],
                    rms_after(faulty, start)[0],
                    rms_after(fixed, start)[0],
                    (loop.sensor_faults[0][0] - start) * float(model.dt) if loop.sensor_faults else float("nan"),
                )
            )
    return FaultTolerance(detector, fa.rate, fa.runs_alarmed, fa.redesigned, fa.runs, tuple(runs), fa.calibration_runs)


def _median_or_dash(values: list[float]) -> float | str:
    found = [v for v in values if np.isfinite(v)]
    return float(np.median(found)) if found else "-"


def table_fault_tolerance(study: FaultTolerance) -> ComparisonTable:
    """The study as a table: per scenario, detection delay, the effectiveness estimated, and the tracking loss.

    Examples
    --------
    >>> run = FaultRun("main rotor thrust -50 %", 20, 0.6, 0.52, 0.114, 0.143, 0.129)
    >>> study = FaultTolerance(ChiSquareDetector([[1e-5]], WINDOW), 0.0, 0.0, 0, 50, (run,))
    >>> table_fault_tolerance(study).rows[0][:4]
    ['main rotor thrust -50 %', '1/1', 0.6, '0.52 (0.52-0.52)']
    """
    table = ComparisonTable(
        "Ch. 8 future work: fault-tolerant pitch LQG on the twin (R = 75, square wave, moving air)",
        [
            "scenario",
            "detected (runs)",
            "delay median (s)",
            "effectiveness estimated",
            "encoder taken as frozen after (s)",
            "RMS healthy (rad)",
            "RMS nominal LQG (rad)",
            "RMS reconfigured (rad)",
        ],
    )
    for name in dict.fromkeys(r.scenario for r in study.runs):
        rows = [r for r in study.runs if r.scenario == name]
        delays = np.array([r.delay for r in rows])
        found = np.isfinite(delays)
        eta = np.array([r.effectiveness for r in rows])
        estimated = f"{np.median(eta):.2f} ({eta.min():.2f}-{eta.max():.2f})"
        table.rows.append(
            [
                name,
                f"{int(found.sum())}/{len(rows)}",
                float(np.median(delays[found])) if found.any() else float("nan"),
                estimated,
                _median_or_dash([r.sensor_delay for r in rows]),
                float(np.median([r.rms_healthy for r in rows])),
                float(np.median([r.rms_nominal for r in rows])),
                float(np.median([r.rms_reconfigured for r in rows])),
            ]
        )
    d = study.detector
    table.notes += [
        f"Test: chi-square over {WINDOW} samples ({WINDOW * 0.2:g} s) of the nominal predictor's innovations, "
        f"calibrated on {study.n_train_runs} fault-free runs for {FALSE_ALARM_RATE:g} false alarms per sample "
        f"(threshold {d.threshold:.3g}; innovation std {float(np.sqrt(d.covariance[0, 0])):.3g} rad).",
        (
            f"Measured on {study.n_false_alarm_runs} unseen fault-free runs: {study.false_alarm_rate:.2g} alarms per "
            f"sample, {study.runs_with_false_alarm:.0%} of the runs with any alarm, {study.wrong_switches} re-designed "
            "the loop."
            if study.n_false_alarm_runs
            else "False alarms not measured (no unseen fault-free runs)."
        ),
        f"Faults begin at {FAULT_AT:g} s; RMS tracking errors from then to the end, medians over the seeds.",
    ]
    return table
