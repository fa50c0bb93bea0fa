"""Time-domain calibration against recorded time series, with ``mujoco.sysid``.

A rig owner has time series, not spectra: voltages in, encoder angles out. This module
fits named physical parameters (:data:`trms.twin.parameters.PARAMETERS`, within their
bounds) so that the twin, driven by the recorded voltages, reproduces the recorded pitch
and yaw. The work is ``mujoco.sysid``'s:

- each parameter is a ``mujoco.sysid.Parameter`` whose modifier writes it into a copy of
  the MjSpec through the project's parameter registry (so new registry entries -- a
  thrust-curve coefficient, an actuator delay -- plug in without code here);
- the residual is ``mujoco.sysid.build_residual_fn`` over ``ModelSequences`` (one per
  record set), the optimiser ``mujoco.sysid.optimize`` (box-constrained Gauss-Newton of
  ``mujoco.minimize`` with finite-difference Jacobians, every candidate of a Jacobian
  rolled out in one ``mujoco.rollout`` batch on all cores), the confidence intervals
  ``mujoco.sysid.calculate_intervals`` and the HTML report ``mujoco.sysid.default_report``.

What the library does not know about this rig, and is written here:

- the input side: the rig's control is a voltage, the actuator's is a thrust. The custom
  rollout (``mujoco.sysid``'s ``custom_rollout`` hook) passes every candidate's voltages
  through that candidate's thrust curve (the Hammerstein map the twin applies once per
  control interval, with the spin motors' commands: ``trms.twin.rotors.rotor_controls``),
  holds them for one control interval (zero-order hold, not the library's linear
  resampling) and starts each record from the candidate's own hover trim (``Twin.put_at_trim``:
  the motors at hover, the actuators' delay lines full of the hover controls) with the axes
  at the first recorded angles. So the thrust curve, the motor lag and any actuator delay
  in the registry are fitted through the same path as the structure;
- honest intervals: ``calculate_intervals`` takes the residuals as white noise; gusts make
  them correlated over seconds, so the reported intervals are the sandwich
  (autocorrelation-consistent) ones of :mod:`~trms.calibration.timedomain.intervals`, built on
  the library's own Jacobian at the optimum (the optimiser's last log entry). Rotor-wash
  turbulence rings the pitch mode that the fitted parameters shape, and they absorb much of
  it: at a tenth of a volt the residuals then understate the scatter about twofold (on a
  faked rig at +-0.12 V, 3 fits in 8 left a true value outside its sandwich interval). So
  each interval is the wider of the sandwich one and one from seeded draws of the fitted
  model's own turbulence, rolled out on the records and scaled to the residuals
  (:func:`~trms.calibration.timedomain.intervals.disturbance_intervals`); the white ones are
  reported too;
- the transport delay: MuJoCo's actuator delay acts in whole physics steps, so a
  finite-difference Jacobian does not see it; it is fitted by a profile (the other
  parameters fitted at each delay of a parabolic search on the physics steps' centres)
  and its interval comes from a central difference over 10 steps in the same sandwich,
  plus half a step (the truth can lie anywhere in the step found);
- speed: the rollouts record the sensors only (MuJoCo's full state, with the actuators'
  delay lines, costs more to copy out every step than the physics), on one persistent
  ``mujoco.rollout.Rollout`` thread pool; the library asks for one record at a time, so the
  first request for a set of candidates rolls out all the records for them in one batch,
  and each candidate is compiled once, not once a record;
- which samples compare: the rollout returns the sensors at the record's sample times,
  so the library's default residual compares sample for sample (``resample_true=False``);
- a start the optimiser can move from: a start whose twin runs into an end stop that the
  records never reach makes the residual flat in the parameters (the optimiser stops on
  its first step, nothing changes). The start is rolled out on the records first; if it
  hits such a stop, a coarse seeded Latin-hypercube stage picks the best candidate that
  does not, or the calibration is refused naming the axis, record and time
  (:mod:`~trms.calibration.timedomain.feasible_start`);
- a fit that cannot be trusted is said so: no optimiser step, a fit below 0 % or worse
  than the start's on the held-out records are ``failures`` (never ``all_met``), and the
  iteration count is the optimiser's own (its termination line);
- progress: one tqdm bar a stage on a terminal (:class:`~trms.calibration.calibrate.Progress`);
- the report: ``mujoco.sysid``'s HTML report, with the reported intervals and plotly.js
  inside the page (:mod:`~trms.calibration.timedomain.report`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np
import scipy.optimize

from trms.calibration.calibrate import Progress
from trms.calibration.timedomain.feasible_start import stop_reached
from trms.calibration.timedomain.intervals import disturbance_intervals, sandwich_intervals
from trms.calibration.timedomain.report import write_sysid_report
from trms.calibration.timedomain.result import TimeDomainResult
from trms.calibration.timedomain.rig import Rig, parameter_dict, require_sysid, sysid
from trms.calibration.timedomain.stages import (
    FitOutcome,
    Tracker,
    delay_column,
    disturbed_draws,
    fit_bounded,
    fit_failures,
    profile_delay,
    start_clear_of_stops,
)
from trms.errors import ConfigurationError, InputError, check_in_range
from trms.identification.validation import fit_percents
from trms.record import Record
from trms.twin.model import get_configuration, load_spec
from trms.twin.parameters import PARAMETERS, read_parameters, with_parameters

__all__ = [
    "DEFAULT_TIME_DOMAIN",
    "MAX_ITERS",
    "calibrate_records",
    "scaled_spec",
]

#: Parameters fitted by default in each configuration: those its outputs observe.
DEFAULT_TIME_DOMAIN: dict[str, tuple[str, ...]] = {
    "1dof": ("counterweight_mass", "pitch_damping", "main_motor_gain", "main_motor_lag"),
    "2dof": (
        "counterweight_mass",
        "pitch_damping",
        "main_motor_gain",
        "main_motor_lag",
        "yaw_damping",
        "cable_stiffness",
    ),
    "yaw": ("yaw_damping", "cable_stiffness", "tail_motor_gain", "tail_motor_lag"),
}


def _record_config(records: Sequence[Record], labels: Sequence[str], config: str | None) -> str:
    found = None
    for rec, label in zip(records, labels):
        cfg = rec.metadata.get("config")
        if cfg is None:
            raise InputError(
                f"record {label} has no 'config' in its metadata; say which rig configuration "
                f"it was taken in (one of {', '.join(repr(c) for c in DEFAULT_TIME_DOMAIN)})"
            )
        if config is not None and cfg != config:
            raise ConfigurationError(
                f"record {label} was taken in configuration {cfg!r}; the model is calibrated in {config!r}"
            )
        if found is not None and cfg != found:
            raise ConfigurationError(f"record {label} was taken in configuration {cfg!r}, the others in {found!r}")
        found = cfg
    assert found is not None
    cfgobj = get_configuration(found)
    for rec, label in zip(records, labels):
        for kind, want, have in (
            ("input", cfgobj.inputs, rec.input_names),
            ("output", cfgobj.outputs, rec.output_names),
        ):
            missing = [w for w in want if w not in have]
            if missing:
                raise InputError(
                    f"record {label} lacks {kind} {missing[0]!r} of configuration {found!r} (it has {', '.join(have)})"
                )
    return found


def _check_records(records: Sequence[Record], labels: Sequence[str], n_fit: int, config: str) -> float:
    """The records' one sample time (s), after refusing what the fit cannot use, in one line naming the record.

    Refused: records at different sample times (each named with its own), fewer than 3 samples, a NaN or infinite
    input or output of the configuration (the row and the time on the record's own clock named), and the same
    samples given twice (twice to the fit, or to the fit and the held-out check).
    """
    times = [round(rec.sample_time, 9) for rec in records]
    if len(set(times)) > 1:
        other = next(i for i, t in enumerate(times) if t != times[0])
        raise InputError(
            f"record {labels[other]} is sampled every {times[other]:g} s, record {labels[0]} every {times[0]:g} s; "
            "calibrate the records of one sample time at a time"
        )
    cfgobj = get_configuration(config)
    seen: dict[bytes, str] = {}
    for i, (rec, label) in enumerate(zip(records, labels)):
        if len(rec) < 3:
            raise InputError(f"record {label} has {len(rec)} samples; at least 3 are needed")
        start = float(rec.metadata.get("start_time", 0.0))
        for kind, names, values, wanted in (
            ("input", rec.input_names, rec.inputs, cfgobj.inputs),
            ("output", rec.output_names, rec.outputs, cfgobj.outputs),
        ):
            for name in wanted:
                column = values[:, names.index(name)]
                bad = np.flatnonzero(~np.isfinite(column))
                if bad.size:
                    k = int(bad[0])
                    what = "NaN" if np.isnan(column[k]) else f"{column[k]:+}"
                    raise InputError(
                        f"record {label}: {kind} {name!r} is {what} in {bad.size} sample(s), first at row {k} "
                        f"(t = {start + rec.time[k] - rec.time[0]:.6g} s); the fit compares every sample: give "
                        "records without gaps (cut them at the gap)"
                    )
        key = rec.inputs.tobytes() + rec.outputs.tobytes()
        if key in seen:
            role = "held-out " if i >= n_fit else ""
            same = "is given twice" if label == seen[key] else f"holds the same samples as record {seen[key]}"
            raise InputError(
                f"{role}record {label} {same}: "
                + (
                    "a held-out record must be one the fit never sees"
                    if i >= n_fit and seen[key] in labels[:n_fit]
                    else "a record given twice counts twice; give each record once"
                )
            )
        seen[key] = label
    return float(times[0])


#: The most Gauss-Newton iterations a time-domain calibration may be given.
MAX_ITERS = 1000


def calibrate_records(
    records: Sequence[Record],
    names: Sequence[str] | None = None,
    spec: mujoco.MjSpec | None = None,
    *,
    held_out: Sequence[Record] = (),
    labels: Sequence[str] | None = None,
    held_out_labels: Sequence[str] | None = None,
    config: str | None = None,
    max_iters: int = 30,
    n_threads: int | None = None,
    report_dir: str | os.PathLike[str] | None = None,
    voltage_limit: float = 10.0,
    progress: Progress | None = None,
    seed: int = 0,
) -> TimeDomainResult:
    """Fit the twin's named parameters to recorded time series with ``mujoco.sysid``.

    Parameters
    ----------
    records : sequence of Record
        Absolute voltages in, absolute angles (rad) out, one configuration, metadata
        ``config`` set (Records from :func:`~trms.rig.exports.record_from_csv` or the twin).
    names : sequence of str, optional
        Parameters to fit (default :data:`DEFAULT_TIME_DOMAIN` of the configuration).
    spec : mujoco.MjSpec, optional
        Starting model (default: the shipped MJCF). Not modified.
    held_out : sequence of Record
        Records the fit never sees; the fit before/after is measured on them.
    labels, held_out_labels : sequence of str, optional
        Names of the records in messages and the report (default ``record 0`` ...).
    config : str, optional
        The model's configuration; records taken in another one are refused.
    max_iters : int
        Most Gauss-Newton iterations, 1 to :data:`MAX_ITERS`.
    n_threads : int, optional
        Rollout threads (default: every core).
    report_dir : path-like, optional
        Where ``mujoco.sysid``'s HTML report goes (none written by default).
    voltage_limit : float
        Motor voltage saturation (V).
    progress : Progress, optional
        Progress bars (default: none).
    seed : int
        Seed of the coarse start stage's candidates (used only when the start hits an end stop).

    Returns
    -------
    TimeDomainResult
        ``failures`` says when the fit cannot be trusted (no optimiser step, a fit below 0 %
        or worse than the start's).

    Raises
    ------
    InputError, ConfigurationError
        No records, records of different or unknown configurations, missing channels,
        unknown parameter names, sample times the twin cannot run.
    EstimationError
        The start and every candidate of the coarse stage run into an end stop that the
        records do not reach (the message names the axis, record and time).

    Examples
    --------
    A 1-DOF twin whose motor lag is 20 % longer than the shipped model's, recorded for 4 s:

    >>> from trms.twin import Twin, load_spec
    >>> truth = scaled_spec(load_spec(), {"main_motor_lag": 1.2})
    >>> twin = Twin("1dof", 0.05, spec=truth, counts_per_rev=0, still_air=True)
    >>> u = twin.operating_point.inputs + 0.2 * np.sign(np.sin(np.arange(80) / 5))[:, None]
    >>> result = calibrate_records([twin.run(u)], ["main_motor_lag"], max_iters=10)
    >>> result.iterations > 0, abs(result.values["main_motor_lag"] / result.start["main_motor_lag"] - 1.2) < 1e-3
    (True, True)
    """
    require_sysid()
    records = list(records)
    held = list(held_out)
    if not records:
        raise InputError("time-domain calibration needs at least one record")
    max_iters = int(check_in_range("max_iters", max_iters, 1, MAX_ITERS))
    labels = list(labels) if labels is not None else [f"record {i}" for i in range(len(records))]
    held_labels = (
        list(held_out_labels) if held_out_labels is not None else [f"held-out record {i}" for i in range(len(held))]
    )
    cfg = _record_config(records + held, labels + held_labels, config)
    names = list(names) if names is not None else list(DEFAULT_TIME_DOMAIN[cfg])
    for n in names:
        if n not in PARAMETERS:
            raise InputError(f"unknown parameter {n!r}; known: {', '.join(PARAMETERS)}")
    ts = _check_records(records + held, labels + held_labels, len(records), cfg)
    spec = spec if spec is not None else load_spec()
    threads = int(n_threads or os.cpu_count() or 1)
    rig = Rig(spec, cfg, ts, voltage_limit, threads)
    tracker = Tracker(progress or Progress(enabled=False), rig, max_iters)
    try:
        return _calibrate(rig, spec, records, held, labels, held_labels, names, max_iters, report_dir, tracker, seed)
    finally:
        tracker.close()
        rig.close()


#: Seeded draws of the fitted model's turbulence that the disturbance intervals are estimated from.
DISTURBANCE_DRAWS = 32


def _intervals(
    rig: Rig,
    records: list[Record],
    residual: np.ndarray,
    jac: np.ndarray,
    residual_fn: Any,
    opt_params: Any,
    fit_seq: list,
    with_delay: bool,
    seed: int,
    tracker: Tracker,
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """The 95 % half-widths and covariance in the Jacobian's column order: the wider, parameter by parameter, of the
    sandwich intervals and the disturbance refits' (:mod:`~trms.calibration.timedomain.intervals`), infinite where
    the library finds a direction undetermined; the sandwich's bandwidth (samples) and the white half-widths."""
    n_out = len(rig.config.outputs)
    sizes = [(len(rec) - 1) * n_out for rec in records]
    residuals_star = np.split(residual, np.cumsum(sizes)[:-1])
    _, white_half = sysid.calculate_intervals(residuals_star, jac)
    half, cov, bandwidth = sandwich_intervals(residuals_star, jac, np.linalg.pinv(jac.T @ jac), n_out)
    tracker.begin("disturbance intervals")
    disturbed = disturbed_draws(rig, residual_fn, opt_params, fit_seq[0], DISTURBANCE_DRAWS, seed)
    lags = max(1, int(round(1.0 / rig.start.sample_time)))
    half_d, _, _ = disturbance_intervals(residuals_star, jac, disturbed, n_out, lags)
    widen = np.maximum(half_d / np.where(half > 0, half, np.inf), 1.0)
    half = half * widen  # the wider of the two, parameter by parameter
    cov = cov * np.outer(widen, widen)  # the sandwich's correlations, at the reported widths
    half = np.where(np.isfinite(white_half), half, np.inf)  # the library's verdict on undetermined directions
    if with_delay:  # the truth can lie anywhere in the fitted step: add its half-width
        half[-1] += 0.5 * float(rig.start.model.opt.timestep)
    return half, cov, bandwidth, white_half


def _fit_check(rig: Rig, check_fn: Any, params0: Any, opt_params: Any) -> tuple[dict, dict]:
    """The fit (%) of each output on each checked record before and after (the start without, the fit with the fitted
    delay)."""
    fit_before: dict[str, list[float]] = {}
    fit_after: dict[str, list[float]] = {}
    fitted_delay = rig.delay
    for key, p in (("before", params0), ("after", opt_params)):
        rig.delay = None if key == "before" else fitted_delay
        _, preds, meas = check_fn(p.as_vector(), p, return_pred_all=True)
        per = [fit_percents(mm[0].data, pp[0].data) for pp, mm in zip(preds, meas)]
        target = fit_before if key == "before" else fit_after
        for j, o in enumerate(rig.config.outputs):
            target[o] = [float(f[j]) for f in per]
    return fit_before, fit_after


def _undetermined(values: dict[str, float], intervals: dict[str, float]) -> list[str]:
    """A line for each parameter at a bound of its range, or whose interval spans zero: what the data do not fix."""
    problems = []
    for n, v in values.items():
        lo, hi = PARAMETERS[n].bounds
        h = intervals[n]
        if min(v - lo, hi - v) <= 1e-6 * (hi - lo):
            problems.append(
                f"{n} = {v:.5g} {PARAMETERS[n].unit} sits at a bound of [{lo}, {hi}]: the data ask for more"
            )
        elif not np.isfinite(h) or h >= abs(v):
            problems.append(f"{n} is not determined by these records (95 % interval +-{h:.3g} around {v:.5g})")
    return problems


def _stop_contacts(rig: Rig, records: list[Record], labels: list[str]) -> list[str]:
    """Each fitted record's first end-stop contact, with how far its inputs swing."""
    out = []
    for rec, label in zip(records, labels):
        angles = rec.outputs[:, [rec.output_names.index(o) for o in rig.config.outputs]]
        reached = stop_reached(angles, _clock(rec), rig.stops, rig.config.outputs, label)
        if reached is not None:
            out.append(f"{reached}, its inputs {_swing(rec, rig.config.inputs)}")
    return out


def _report(
    rig: Rig,
    report_dir: str | os.PathLike[str],
    fit_seq: list,
    params0: Any,
    fit: FitOutcome,
    residual_fn: Any,
    half: np.ndarray,
    cov: np.ndarray,
    p: int,
) -> str:
    """The library's HTML report of the fit (its first ``p`` parameters, the smooth ones), self-contained; its path."""
    opt_params = fit.params
    result = scipy.optimize.OptimizeResult(x=opt_params.as_vector(), jac=fit.jacobian, extras=fit.extras)
    return str(
        write_sysid_report(
            report_dir,
            fit_seq,
            params0,
            opt_params,
            residual_fn,
            result,
            half[:p],
            cov[:p, :p],
            title=f"trms time-domain calibration ({rig.config.name})",
            build_model=rig.build,
        )
    )


def _calibrate(
    rig: Rig,
    spec: mujoco.MjSpec,
    records: list[Record],
    held: list[Record],
    labels: list[str],
    held_labels: list[str],
    names: list[str],
    max_iters: int,
    report_dir: str | os.PathLike[str] | None,
    tracker: Tracker,
    seed: int,
) -> TimeDomainResult:
    cfg = rig.config.name
    common = dict(
        build_model=rig.build,
        custom_rollout=rig.rollout,
        n_threads=rig.threads,
        resample_true=False,
        enabled_observations=rig.observations(),
    )
    fit_seq = [rig.sequences(records, labels, "records")]
    residual_fn = sysid.build_residual_fn(models_sequences=fit_seq, **common)
    smooth = [n for n in names if n != "input_delay"]
    params0 = parameter_dict(spec, smooth)
    start = read_parameters(spec, names)

    t0 = time.perf_counter()
    origins = [float(_clock(rec)[0]) for rec in records]
    fit_from, start_check, candidates = start_clear_of_stops(rig, residual_fn, params0, labels, origins, tracker, seed)
    fit_start = {n: float(fit_from[n].value[0]) for n in smooth}
    profile_fits = 0
    if "input_delay" in names:
        tracker.begin("delay profile")
        delay, fit, profile_fits = profile_delay(rig, fit_from, residual_fn, max_iters, start["input_delay"], tracker)
        fit_start["input_delay"] = float(start["input_delay"])
    else:
        tracker.begin("fit")
        fit = fit_bounded(fit_from, residual_fn, max_iters, tracker)
    opt_params = fit.params
    values = {n: float(opt_params[n].value[0]) for n in smooth}
    jac = fit.jacobian
    if "input_delay" in names:
        values["input_delay"] = delay
        jac = np.column_stack([jac, delay_column(rig, opt_params, residual_fn, delay)])
    t_opt = time.perf_counter() - t0

    t0 = time.perf_counter()
    with_delay = "input_delay" in names
    half, cov, bandwidth, white_half = _intervals(
        rig, records, fit.residual, jac, residual_fn, opt_params, fit_seq, with_delay, seed, tracker
    )
    order = smooth + (["input_delay"] if "input_delay" in names else [])
    white = {n: float(white_half[order.index(n)]) for n in names}
    intervals = {n: float(half[order.index(n)]) for n in names}
    values = {n: values[n] for n in names}
    start = {n: float(start[n]) for n in names}
    fit_start = {n: fit_start[n] for n in names}
    t_int = time.perf_counter() - t0

    t0 = time.perf_counter()
    tracker.begin("held-out check" if held else "fit check")
    check_seq = [rig.sequences(held, held_labels, "held_out")] if held else fit_seq
    check_fn = sysid.build_residual_fn(models_sequences=check_seq, **common)
    fit_before, fit_after = _fit_check(rig, check_fn, params0, opt_params)
    t_check = time.perf_counter() - t0

    problems = _undetermined(values, intervals)
    at_stops = _stop_contacts(rig, records, labels)
    failures = fit_failures(
        fit,
        fit_before,
        fit_after,
        held_labels if held else labels,
        "held-out" if held else "fitted",
        at_stops,
    )

    t0 = time.perf_counter()
    html = None
    if report_dir is not None:
        tracker.begin("report")
        html = _report(rig, report_dir, fit_seq, params0, fit, residual_fn, half, cov, len(smooth))
    t_rep = time.perf_counter() - t0
    return TimeDomainResult(
        cfg,
        start,
        values,
        intervals,
        white,
        bandwidth,
        fit_before,
        fit_after,
        "held-out" if held else "fitted",
        problems,
        {"optimisation": t_opt, "intervals": t_int, "fit_check": t_check, "report": t_rep},
        fit.iterations,
        rig.evaluations,
        html,
        labels,
        held_labels,
        fit.stopped,
        profile_fits,
        failures,
        start_check,
        fit_start,
        candidates,
    )


def _clock(rec: Record) -> np.ndarray:
    """A record's sample times (s) on its own clock: a rig export's log (its ``start_time``), else the record's."""
    return rec.time - rec.time[0] + float(rec.metadata.get("start_time", rec.time[0] if len(rec) else 0.0))


def _swing(rec: Record, inputs: Sequence[str]) -> str:
    """How far a record's inputs swing from its operating point (from their median without one), in words."""
    u = rec.inputs[:, [rec.input_names.index(n) for n in inputs]]
    centre = (
        rec.operating_point.inputs[[rec.input_names.index(n) for n in inputs]]
        if "operating_point" in rec.metadata
        else np.median(u, axis=0)
    )
    swing = np.max(np.abs(u - centre), axis=0)
    where = "its operating point" if "operating_point" in rec.metadata else "their median"
    return "swing " + ", ".join(f"{n} up to {v:.3g} V" for n, v in zip(inputs, swing)) + f" from {where}"


def scaled_spec(spec: mujoco.MjSpec, factors: dict[str, float]) -> mujoco.MjSpec:
    """A copy of ``spec`` with each named parameter multiplied by its factor (hidden truths for checks).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> truth = scaled_spec(load_spec(), {"main_motor_lag": 1.2})
    """
    values = read_parameters(spec, list(factors))
    return with_parameters(spec, {n: values[n] * f for n, f in factors.items()})
