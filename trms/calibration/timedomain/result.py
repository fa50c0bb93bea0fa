"""What a time-domain calibration found."""

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from trms.calibration.timedomain.intervals import INTERVAL_NAME
from trms.twin.parameters import PARAMETERS

__all__ = ["TimeDomainResult"]


@dataclass
class TimeDomainResult:
    """What a time-domain calibration found.

    Attributes
    ----------
    config : str
        The rig configuration of the records.
    start, values : dict of str to float
        Parameters before and after (units of :data:`~trms.twin.parameters.PARAMETERS`).
    intervals : dict of str to float
        Half-width of each parameter's 95 % confidence interval: the wider of the sandwich one
        (:func:`~trms.calibration.timedomain.intervals.sandwich_intervals`: the residuals' correlation
        in time kept) and the disturbance one
        (:func:`~trms.calibration.timedomain.intervals.disturbance_intervals`: seeded draws of the
        model's turbulence scaled to the residuals), ``inf`` where the data do not determine it.
    white_intervals : dict of str to float
        ``calculate_intervals``'s half-widths: they take the residuals as white.
    bandwidth : int
        Bartlett bandwidth of the sandwich (samples): how far apart residuals are taken
        to be correlated (the longest record, less one: ``b = 1``).
    fit_before, fit_after : dict of str to list of float
        Fit (%) of each output on each held-out record (or on the fitted records when none
        is held out), with the start and the calibrated parameters.
    fit_on : str
        ``"held-out"`` or ``"fitted"``: which records the fits are measured on.
    problems : list of str
        Parameters at a bound or not determined by the data.
    timings : dict of str to float
        Wall time (s) of the optimisation (with the start check and any coarse stage), the
        intervals, the held-out check and the report.
    iterations, evaluations : int
        The optimiser's own iteration count (its termination line; the best delay-profile
        fit's when the delay is fitted), and rollouts of one record (every candidate counts).
    report_html : str or None
        The ``mujoco.sysid`` HTML report, when written.
    records, held_out : list of str
        Labels of the fitted and the held-out records.
    stopped : str
        Why the optimiser stopped (its last line, without its own iteration count).
    profile_fits : int
        Gauss-Newton fits of the transport-delay profile (0 when the delay is not fitted).
    failures : list of str
        Why the calibration cannot be trusted at all: the optimiser took no step, or the fit
        on the held-out records (the fitted ones when none is held out) is below 0 % or worse
        than the start's. ``trms calibrate`` exits non-zero and writes no model.
    start_check : str
        Empty when the start hits no end stop that the records do not reach; else which stop,
        record and time, and where the fit started instead.
    fit_start : dict of str to float
        Where the optimiser started: the start, or the coarse stage's best candidate.
    start_candidates : int
        Candidates the coarse stage rolled out (0 when the start was fitted from).

    Examples
    --------
    A calibration of one parameter that landed within its bounds, its fit better than the start's:

    >>> r = TimeDomainResult(
    ...     "1dof", {"main_motor_lag": 0.2}, {"main_motor_lag": 0.24}, {"main_motor_lag": 0.01},
    ...     {"main_motor_lag": 0.004}, 1, {"pitch": [80.0]}, {"pitch": [95.0]}, "fitted", [], {})
    >>> r.all_met, r.to_dict()["parameters"]["main_motor_lag"]["calibrated"]
    (True, 0.24)
    """

    config: str
    start: dict[str, float]
    values: dict[str, float]
    intervals: dict[str, float]
    white_intervals: dict[str, float]
    bandwidth: int
    fit_before: dict[str, list[float]]
    fit_after: dict[str, list[float]]
    fit_on: str
    problems: list[str]
    timings: dict[str, float]
    iterations: int = 0
    evaluations: int = 0
    report_html: str | None = None
    records: list[str] = field(default_factory=list)
    held_out: list[str] = field(default_factory=list)
    stopped: str = ""
    profile_fits: int = 0
    failures: list[str] = field(default_factory=list)
    start_check: str = ""
    fit_start: dict[str, float] = field(default_factory=dict)
    start_candidates: int = 0

    @property
    def all_met(self) -> bool:
        """No failure, and no parameter at a bound or undetermined."""
        return not self.problems and not self.failures

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable summary (``calibration.json``)."""

        def num(x: float) -> float | str:
            return float(x) if np.isfinite(x) else str(x)

        return {
            "method": "time domain (mujoco.sysid)",
            "config": self.config,
            "records": self.records,
            "held_out": self.held_out,
            "intervals": {
                "interval_95": f"half-width of the {INTERVAL_NAME} (the wider of the sandwich interval, residuals "
                "correlated in time kept, and the interval from seeded draws of the model's turbulence scaled to "
                "the residuals, with the white rest)",
                "interval_95_white": "half-width of the white-noise 95 % interval (calculate_intervals)",
            },
            "parameters": {
                n: {
                    "start": self.start[n],
                    "fit_start": self.fit_start.get(n, self.start[n]),
                    "calibrated": self.values[n],
                    "interval_95": num(self.intervals[n]),
                    "interval_95_white": num(self.white_intervals[n]),
                    "unit": PARAMETERS[n].unit,
                    "bounds": list(PARAMETERS[n].bounds),
                }
                for n in self.values
            },
            "fit_percent": {"on": self.fit_on, "before": self.fit_before, "after": self.fit_after},
            "sandwich_bandwidth_samples": self.bandwidth,
            "delay_profile_fits": self.profile_fits,
            "failed": self.failures,
            "problems": self.problems,
            "all_met": self.all_met,
            "start_check": self.start_check,
            "start_candidates": self.start_candidates,
            "timings_s": self.timings,
            "iterations": self.iterations,
            "stopped": self.stopped,
            "evaluations": self.evaluations,
            "report_html": self.report_html,
        }

    def table(self) -> str:
        """The parameter table (start, calibrated, 95 % interval) as Markdown."""
        lines = [f"| parameter | start | calibrated | {INTERVAL_NAME} (+-) | unit |", "|---|---|---|---|---|"]
        for n, v in self.values.items():
            lines.append(f"| {n} | {self.start[n]:.5g} | {v:.5g} | {self.intervals[n]:.3g} | {PARAMETERS[n].unit} |")
        return "\n".join(lines)
