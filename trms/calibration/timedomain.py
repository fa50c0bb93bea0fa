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
  (autocorrelation-consistent) ones of :mod:`~trms.calibration.intervals`, built on
  the library's own Jacobian at the optimum (the optimiser's last log entry). Rotor-wash
  turbulence rings the pitch mode that the fitted parameters shape, and they absorb much of
  it: at a tenth of a volt the residuals then understate the scatter about twofold (on a
  faked rig at +-0.12 V, 3 fits in 8 left a true value outside its sandwich interval). So
  each interval is the wider of the sandwich one and one from seeded draws of the fitted
  model's own turbulence, rolled out on the records and scaled to the residuals
  (:func:`~trms.calibration.intervals.disturbance_intervals`); the white ones are
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
  (:mod:`~trms.calibration.feasible_start`);
- a fit that cannot be trusted is said so: no optimiser step, a fit below 0 % or worse
  than the start's on the held-out records are ``failures`` (never ``all_met``), and the
  iteration count is the optimiser's own (its termination line);
- progress: one tqdm bar a stage on a terminal (:class:`~trms.calibration.calibrate.Progress`);
- the report: ``mujoco.sysid``'s HTML report, with the reported intervals and plotly.js
  inside the page (:mod:`~trms.calibration.sysid_report`).
"""

from __future__ import annotations

import collections
import io
import os
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import mujoco
import mujoco.rollout
import numpy as np
import scipy.optimize
import scipy.signal

from trms.calibration.calibrate import Progress
from trms.calibration.feasible_start import SPREAD, StopHit, best_feasible, latin_hypercube, stop_hit, stop_reached
from trms.calibration.intervals import INTERVAL_NAME, disturbance_intervals, sandwich_intervals
from trms.calibration.sysid_report import write_sysid_report
from trms.errors import ConfigurationError, EstimationError, InputError, check_in_range
from trms.record import Record
from trms.twin.model import ROTORS, WASHES, configure_spec, get_configuration, load_spec, spinning
from trms.twin.parameters import PARAMETERS, Parameter, read_parameters, with_parameters
from trms.twin.rotors import rotor_controls
from trms.twin.twin import Twin

try:  # the mujoco[sysid] extra
    from mujoco import sysid

    _SYSID_ERROR: Exception | None = None if hasattr(sysid, "optimize") else ImportError("mujoco.sysid lacks optimize")
except ImportError as exc:  # pragma: no cover - depends on the installation
    sysid = None
    _SYSID_ERROR = exc

__all__ = [
    "DEFAULT_TIME_DOMAIN",
    "MAX_ITERS",
    "TimeDomainResult",
    "calibrate_records",
    "fit_percent",
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
_ROTOR_OF_INPUT = {"u1": 0, "u2": 1}
_CACHE = 64
#: Step at which Gauss-Newton stops, relative to the parameters' norm (the last step is taken).
#: The library's 1e-8 spends its last iterations raising the damping against round-off, at
#: three times the rollouts; with 1e-8 the benchmark's gust-free truths miss the same intervals.
_XTOL = 1e-6


def _require_sysid() -> None:
    if _SYSID_ERROR is not None:
        raise ImportError(
            "time-domain calibration needs the sysid extra (mujoco.sysid is missing): "
            "install it with pip install 'trms[sysid]'"
        ) from _SYSID_ERROR


def fit_percent(measured: np.ndarray, predicted: np.ndarray) -> np.ndarray:
    """Normalised fit per column, ``100 (1 - ||y - yhat|| / ||y - mean(y)||)`` (%; 100 is perfect).

    Parameters
    ----------
    measured, predicted : numpy.ndarray
        Shape ``(N, n)``.

    Returns
    -------
    numpy.ndarray
        Shape ``(n,)``.

    Examples
    --------
    >>> fit_percent(np.array([[0.0], [1.0], [2.0]]), np.array([[0.0], [1.0], [2.0]]))
    array([100.])
    """
    y = np.asarray(measured, float)
    e = np.linalg.norm(y - np.asarray(predicted, float), axis=0)
    spread = np.linalg.norm(y - y.mean(axis=0), axis=0)
    return 100.0 * (1.0 - e / np.where(spread > 0, spread, np.nan))


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
        (:func:`~trms.calibration.intervals.sandwich_intervals`: the residuals' correlation
        in time kept) and the disturbance one
        (:func:`~trms.calibration.intervals.disturbance_intervals`: seeded draws of the
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
        The optimiser's last line: why it stopped.
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


class _Rig:
    """The records of one configuration as ``mujoco.sysid`` sees them, and the rollout hook.

    ``build`` compiles a candidate (a :class:`~trms.twin.Twin` on a copy of the spec with
    the candidate's parameters, through each ``sysid.Parameter``'s modifier, and the
    profile's transport delay when one is set) and keeps the Twin so that ``rollout``
    finds the candidate's thrust curves and trim. The library builds each candidate once
    a record; the Twins are kept by parameter values, so a candidate is compiled once.
    """

    def __init__(
        self, spec: mujoco.MjSpec, config: str, sample_time: float, voltage_limit: float, threads: int = 1
    ) -> None:
        self.spec = spec
        self.config = get_configuration(config)
        self.sample_time = sample_time
        self.voltage_limit = voltage_limit
        self.start = Twin(config, sample_time, spec=spec, counts_per_rev=0, voltage_limit=voltage_limit)
        self.configured = configure_spec(spec, self.config, voltage_limit)
        self.nsub = int(round(self.start.sample_time / self.start.model.opt.timestep))
        self.rotor_columns = [self.start.model.actuator(r).id for r in ROTORS]
        self.delay: float | None = None  # the transport delay (s) a delay profile holds fixed; None: the spec's
        self._twins: collections.OrderedDict[tuple[float | None, bytes], Twin] = collections.OrderedDict()
        self._by_model: dict[int, Twin] = {}
        self._group_of: dict[int, list[tuple[Any, np.ndarray]]] = {}  # a record's control -> its set's records
        self._done: dict[tuple[int, int], Any] = {}  # (model, control) -> trajectory rolled out ahead
        self.evaluations = 0
        self.threads = threads
        self.pool = mujoco.rollout.Rollout(nthread=threads)  # one thread pool for every rollout of the fit
        missing = [
            o for o in self.config.outputs if mujoco.mj_name2id(self.start.model, mujoco.mjtObj.mjOBJ_SENSOR, o) < 0
        ]
        if missing:
            raise ConfigurationError(
                f"the model has no sensor named {missing[0]!r} to compare the record's output with"
            )
        m = self.start.model
        self.stops: list[tuple[float, float] | None] = []  # each output's joint range (rad), None: no stops
        for o in self.config.outputs:
            sid = m.sensor(o).id
            j = int(m.sensor_objid[sid])
            on_joint = m.sensor_objtype[sid] == mujoco.mjtObj.mjOBJ_JOINT
            self.stops.append(
                (float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1])) if on_joint and m.jnt_limited[j] else None
            )
        self.on_rollout: Callable[[], None] | None = None  # called after every batch of rollouts (progress)
        self.wash_columns = [
            m.actuator(w).id for w in WASHES if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, w) >= 0
        ]

    def close(self) -> None:
        """Stop the rollout threads."""
        self.pool.close()

    # ---------------------------------------------------------------- the data
    def sequences(self, records: Sequence[Record], labels: Sequence[str], name: str) -> sysid.ModelSequences:
        """One ``ModelSequences`` holding ``records`` (absolute volts in, radians out)."""
        model = self.start.model
        ctrl, sens, init = [], [], []
        for rec in records:
            # One column per actuator (the library checks the width); the rotors' columns hold
            # their voltages, the others (spin motors) follow them inside the rollout.
            volts = np.zeros((len(rec), model.nu))
            cols = [self.rotor_columns[_ROTOR_OF_INPUT[u]] for u in self.config.inputs]
            volts[:, cols] = rec.inputs[:, [rec.input_names.index(u) for u in self.config.inputs]]
            volts = np.clip(volts, -self.voltage_limit, self.voltage_limit)
            t = np.arange(len(rec)) * self.start.sample_time
            ctrl.append(sysid.TimeSeries.from_control_names(t, volts, model))
            y = np.full((len(rec), model.nsensordata), np.nan)
            for o in self.config.outputs:
                adr = model.sensor_adr[model.sensor(o).id]
                y[:, adr] = rec.outputs[:, rec.output_names.index(o)]
            sens.append(sysid.TimeSeries.from_names(t, y, model))
            init.append(self._initial_state(self.start, self._at_rest(y)))
        seq = sysid.ModelSequences(name, self.configured, list(labels), init, ctrl, sens)
        group = [(traj.control, traj.initial_state) for traj in seq.measured_rollout]
        for control, _ in group:
            self._group_of[id(control)] = group
        return seq

    def _at_rest(self, y: np.ndarray) -> np.ndarray:
        """The record's starting angles: the mean of its samples before the transport delay has passed.

        The rig is at rest in hover when a record starts, and its voltages cannot show in the
        angles before the start model's transport delay: every sample until then measures the
        starting angles. One noisy sample would start the candidate a noise's width off, and the
        lightly damped pitch mode rings that offset through the record: a bias of the fitted
        parameters of about one interval on 20 s records at the faked rig's encoder noise.
        """
        k = max(1, min(len(y), int(np.ceil(self.start.input_delay / self.start.sample_time - 1e-9))))
        y0 = y[0].copy()
        cols = [self.start.model.sensor_adr[self.start.model.sensor(o).id] for o in self.config.outputs]
        y0[cols] = y[:k, cols].mean(axis=0)
        return y0

    def observations(self) -> list[tuple[str, Any]]:
        """The measured angles, as ``(sensor name, SignalType)`` pairs."""
        return [(o, sysid.SignalType.MjSensor) for o in self.config.outputs]

    def _initial_state(self, twin: Twin, y0: np.ndarray) -> np.ndarray:
        """The candidate's hover trim (motors at their hover thrust), axes at the measured ``y0``.

        The rig is taken to be at rest in hover when a record starts, as the twin's records do.
        """
        m = twin.model
        d = mujoco.MjData(m)
        twin.put_at_trim(m, d)  # the trim, the actuators' delay lines holding the trim controls
        for o, q in zip(self.config.outputs, twin.output_qpos):
            d.qpos[q] = y0[m.sensor_adr[m.sensor(o).id]]
        mujoco.mj_forward(m, d)
        state = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
        mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        return state

    # ---------------------------------------------------------------- hooks
    def build(self, params: sysid.ParameterDict, _spec: mujoco.MjSpec | None = None) -> mujoco.MjModel:
        """``BuildModelFn``: the candidate's compiled configuration (its Twin is kept for the rollout)."""
        key = (self.delay, params.as_vector().tobytes())
        twin = self._twins.get(key)
        if twin is None:
            spec = sysid.apply_param_modifiers_spec(params, self.spec.copy())
            if self.delay is not None:
                PARAMETERS["input_delay"].set(spec, self.delay)
            twin = Twin(
                self.config.name, self.sample_time, spec=spec, counts_per_rev=0, voltage_limit=self.voltage_limit
            )
            self._twins[key] = twin
            self._by_model[id(twin.model)] = twin
            while len(self._twins) > _CACHE:
                del self._by_model[id(self._twins.popitem(last=False)[1].model)]
        self._twins.move_to_end(key)
        return twin.model

    def rollout(
        self,
        *,
        models: Sequence[mujoco.MjModel],
        control_signal: Sequence[Any],
        initial_states: Sequence[np.ndarray],
        **_: Any,
    ) -> list[Any]:
        """``CustomRolloutFn``: voltages through each candidate's thrust curve, held one interval, rolled out.

        The library asks for one record at a time (every candidate on it); the first request
        for a set of candidates rolls out every record of that record's set for them in one
        batch on all threads, and the next records' requests are answered from it. The
        sensors are returned at the record's sample times ``t_1 .. t_{N-1}``.
        """
        missing = [i for i, (m, c) in enumerate(zip(models, control_signal)) if (id(m), id(c)) not in self._done]
        if missing:
            wanted = {(id(m), id(c)) for m, c in zip(models, control_signal)}
            self._done = {k: v for k, v in self._done.items() if k in wanted}
            unique = list({id(models[i]): models[i] for i in missing}.values())
            group = self._group_of.get(id(control_signal[0]))
            runs = (
                [(m, c, x) for m in unique for c, x in group]
                if group is not None
                else [(models[i], control_signal[i], initial_states[i]) for i in missing]
            )
            for (m, c, _state), traj in zip(runs, self._roll(runs)):
                self._done[(id(m), id(c))] = traj
        return [self._done.pop((id(m), id(c))) for m, c in zip(models, control_signal)]

    def _roll(
        self, runs: Sequence[tuple[mujoco.MjModel, Any, np.ndarray]], washes: Sequence[np.ndarray] | None = None
    ) -> list[Any]:
        """Roll out ``(model, control, initial state)`` triples, batched on the rig's thread pool.

        ``washes``, one a run, drive the turbulence actuators (N, one row a control interval;
        none: still air).

        Only the sensors are recorded at each physics step: MuJoCo's full state (thousands of
        numbers with the actuators' delay lines) would cost more to copy out than to compute,
        so the trajectories' ``state`` holds the sample times and no state signal (this
        calibration compares sensors only).
        """
        self.evaluations += len(runs)
        out: list[Any] = [None] * len(runs)
        # One mujoco.rollout batch per record length and model size (a transport delay sets
        # the length of the actuators' history, so candidates may differ in state size).
        full = mujoco.mjtState.mjSTATE_FULLPHYSICS
        by_length: dict[tuple[int, int], list[int]] = {}
        for i, (m, c, _) in enumerate(runs):
            by_length.setdefault((c.data.shape[0], mujoco.mj_stateSize(m, full)), []).append(i)
        m0 = runs[0][0]
        sensor_map = sysid.TimeSeries.compute_all_sensor_mapping(m0)
        for (n, nstate), idx in by_length.items():
            batch = [runs[i][0] for i in idx]
            data = [mujoco.MjData(batch[0]) for _ in range(self.threads)]
            # mj_step evaluates the sensors before it integrates: the sensors of step j are the
            # state after step j - 1, so one extra step gives the sensors at the last sample.
            nstep = (n - 1) * self.nsub + 1
            ctrl = np.empty((len(idx), nstep, m0.nu))
            init = np.empty((len(idx), nstate))
            for row, i in enumerate(idx):
                model, control, initial = runs[i]
                twin = self._by_model[id(model)]
                controls = rotor_controls(twin.curves, control.data[:, self.rotor_columns], m0.nu, spinning(m0))
                ctrl[row] = np.repeat(controls, self.nsub, axis=0)[:nstep]
                if washes is not None:
                    ctrl[row][:, self.wash_columns] = np.repeat(washes[i], self.nsub, axis=0)[:nstep]
                y0 = np.zeros(m0.nsensordata)
                qpos0 = initial[1 : 1 + m0.nq]
                for o, q in zip(self.config.outputs, twin.output_qpos):
                    y0[m0.sensor_adr[m0.sensor(o).id]] = qpos0[q]
                init[row] = self._initial_state(twin, y0)
            sensordata = np.empty((len(idx), nstep, m0.nsensordata))
            self.pool.rollout(
                batch,
                data,
                init,
                ctrl,
                skip_checks=True,
                nstep=nstep,
                control_spec=mujoco.mjtState.mjSTATE_CTRL.value,
                initial_warmstart=None,
                state=None,
                sensordata=sensordata,
                chunk_size=1,
            )
            pick = np.arange(1, n) * self.nsub
            for row, i in enumerate(idx):
                model, control, _ = runs[i]
                times = control.times[1:n]
                out[i] = sysid.SystemTrajectory(
                    model=model,
                    control=control,
                    sensordata=sysid.TimeSeries(times, sensordata[row, pick], sensor_map),
                    initial_state=init[row],
                    state=sysid.TimeSeries(times, times[:, None], {}),
                )
        if self.on_rollout is not None:
            self.on_rollout()
        return out


def _parameter_dict(spec: mujoco.MjSpec, names: Sequence[str]) -> sysid.ParameterDict:
    """``sysid.ParameterDict`` of the registry's parameters, starting at their values in ``spec``."""
    start = read_parameters(spec, names)
    out = sysid.ParameterDict()
    for n in names:
        p: Parameter = PARAMETERS[n]
        lo, hi = p.bounds
        out.add(
            sysid.Parameter(
                n, start[n], lo, hi, modifier=lambda s, sp, _p=p: _p.set(s, float(np.clip(sp.value[0], *_p.bounds)))
            )
        )
    return out


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
        ``config`` set (Records from :func:`~trms.rigdata.record_from_csv` or the twin).
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
    _require_sysid()
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
    ts = {rec.sample_time for rec in records + held}
    if len({round(t, 9) for t in ts}) != 1:
        raise InputError(f"records have different sample times {sorted(ts)} s; calibrate one sample time at a time")
    for rec, label in zip(records + held, labels + held_labels):
        if len(rec) < 3:
            raise InputError(f"record {label} has {len(rec)} samples; at least 3 are needed")
    spec = spec if spec is not None else load_spec()
    threads = int(n_threads or os.cpu_count() or 1)
    rig = _Rig(spec, cfg, ts.pop(), voltage_limit, threads)
    tracker = _Tracker(progress or Progress(enabled=False), rig, max_iters)
    try:
        return _calibrate(rig, spec, records, held, labels, held_labels, names, max_iters, report_dir, tracker, seed)
    finally:
        tracker.close()
        rig.close()


class _Tracker:
    """Feeds the progress bar: the stage, the optimiser's iteration and cost, and the rollouts so far."""

    def __init__(self, progress: Progress, rig: _Rig, max_iters: int) -> None:
        self.progress = progress
        self.rig = rig
        self.max_iters = max_iters
        self.stage = ""
        self.iteration = 0
        self.cost = float("nan")
        self.fraction = 0.0
        rig.on_rollout = self.rolled

    def begin(self, stage: str, fraction: float = 0.0) -> None:
        """Show ``stage`` (closing the previous one) at ``fraction`` done."""
        if stage != self.stage and self.stage:
            self.progress.done(self.stage, f"{self.rig.evaluations} rollouts")
        self.stage, self.fraction, self.iteration = stage, fraction, 0
        self.rolled()

    def iterated(self, trace: Sequence[Any]) -> None:
        """``iter_callback`` of the optimiser: one more Gauss-Newton iteration."""
        self.iteration, self.cost = len(trace), float(trace[-1].objective)
        if self.stage == "fit":
            self.fraction = min(self.iteration / self.max_iters, 1.0)
        self.rolled()

    def rolled(self) -> None:
        """A batch of rollouts finished."""
        detail = f"{self.rig.evaluations} rollouts"
        if self.iteration:
            detail = f"iteration {self.iteration}, cost {self.cost:.4g}, {detail}"
        self.progress.update(self.stage, self.fraction, detail)

    def close(self) -> None:
        """Finish the last stage's bar."""
        if self.stage:
            self.progress.done(self.stage, f"{self.rig.evaluations} rollouts")
        self.rig.on_rollout = None


@dataclass
class _Fit:
    """One Gauss-Newton fit: the parameters, and the residual and Jacobian at them."""

    params: Any
    residual: np.ndarray
    jacobian: np.ndarray
    iterations: int
    stopped: str
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def sse(self) -> float:
        return float(self.residual @ self.residual)


#: A sum of squares (rad^2) at or below which the start reproduces the records to round-off.
_EXACT = 1e-20
_TERMINATED = re.compile(r"Terminated after (\d+) iterations")


def _fit(params: Any, residual_fn: Any, max_iters: int, tracker: _Tracker | None = None) -> _Fit:
    """``mujoco.sysid.optimize`` from ``params``.

    The optimiser's result holds the Jacobian at the end and, per iteration, the objective and
    candidate; its last log entry (kept by the iteration callback) the residual there. The
    iteration count is the optimiser's own, from its termination line (``Terminated after N
    iterations: why``): the result itself carries none, and its trace has one entry more than
    the steps taken (the end point), or as many when the last step was below the tolerance.
    """
    log = io.StringIO()  # mujoco.minimize's per-iteration lines; the last one says why it stopped
    kept: dict[str, Any] = {}

    def callback(trace: Sequence[Any]) -> None:
        kept["trace"] = trace
        if tracker is not None:
            tracker.iterated(trace)

    opt_params, result = sysid.optimize(
        params,
        residual_fn,
        optimizer="mujoco",
        verbose=False,
        max_iters=int(max_iters),
        output=log,
        x_scale="jac",  # parameters three orders of magnitude apart: steps in Jacobian-scaled units
        xtol=_XTOL,
        iter_callback=callback,
    )
    stopped = next((line for line in reversed(log.getvalue().splitlines()) if line.startswith("Terminated")), "")
    found = _TERMINATED.match(stopped)
    extras = dict(result.extras)
    iterations = int(found.group(1)) if found else len(extras["objective"]) - 1
    residual = np.ravel(kept["trace"][-1].residual)
    return _Fit(opt_params, residual, np.asarray(result.jac), iterations, stopped, extras)


def _stop_hits(
    rig: _Rig, residual_fn: Any, params: Any, candidates: np.ndarray, labels: Sequence[str]
) -> tuple[np.ndarray, list[StopHit | None]]:
    """Sum of squares of each candidate (a column of ``candidates``) and its first end-stop hit on the records.

    All candidates roll out in one batch, through the library's residual (the optimiser's objective).
    """
    res, preds, meas = residual_fn(candidates, params.copy(), return_pred_all=True)
    k = candidates.shape[1]
    sse = np.array([sum(float(r[:, c] @ r[:, c]) for r in res) for c in range(k)])
    hits: list[StopHit | None] = []
    for c in range(k):
        found = (
            stop_hit(pr[c].data, mm[0].data, pr[c].times, rig.stops, rig.config.outputs, label)
            for pr, mm, label in zip(preds, meas, labels)
        )
        hits.append(next((h for h in found if h is not None), None))
    return sse, hits


def _feasible_start(
    rig: _Rig, residual_fn: Any, params: Any, labels: Sequence[str], tracker: _Tracker, seed: int
) -> tuple[Any, str, int]:
    """The parameters to fit from, a note when they are not the start, and how many candidates were tried.

    The start is rolled out on the fitted records; when it runs into an end stop that a record
    stays away from (or diverges), seeded Latin-hypercube candidates are drawn, first within a
    factor :data:`~trms.calibration.feasible_start.SPREAD` of the start, then over the
    whole bounds, and the one of least sum of squares that hits no such stop is the start.
    """
    x0 = params.as_vector()
    tracker.begin("start check")
    _, (hit,) = _stop_hits(rig, residual_fn, params, x0[:, None], labels)
    if hit is None:
        return params, "", 0
    lower, upper = params.get_bounds()
    n = max(8, 3 * x0.size)
    tried = 0
    for k, spread in enumerate((SPREAD, None)):
        tracker.begin("coarse start", k / 2)
        cand = latin_hypercube(x0, lower, upper, n, seed + k, spread)
        sse, hits = _stop_hits(rig, residual_fn, params, cand.T, labels)
        tried += n
        best = best_feasible(sse, hits)
        if best is not None:
            out = params.copy()
            out.update_from_vector(cand[best])
            note = (
                f"with the starting parameters {hit}; the fit started from the best of {tried} seeded "
                "Latin-hypercube candidates that hits no stop the records do not reach"
            )
            return out, note, tried
    raise EstimationError(
        f"no feasible start: with the starting parameters {hit}, and each of {tried} seeded Latin-hypercube "
        "candidates within the parameters' bounds also runs into a stop the records do not reach (or diverges); "
        "check the records' units and channels, or start from a model nearer the rig (--start-from)"
    )


def _profile_delay(
    rig: _Rig, params: Any, residual_fn: Any, max_iters: int, start: float, tracker: _Tracker
) -> tuple[float, _Fit, int]:
    """The transport delay that minimises the profile sum of squares, and the fit there.

    MuJoCo's actuator delay acts in whole physics steps: every delay strictly inside one
    step ``(k dt, (k + 1) dt)`` gives the same motion, so a finite-difference Jacobian sees
    none of it and the delay is known to a step at best. The profile runs on the steps'
    centres ``(k + 1/2) dt`` (an exact multiple of ``dt`` falls on either side by round-off):
    at each the other parameters are fitted (warm-started from the nearest delay already
    fitted). The search starts at ``start`` and its neighbours ``+-h`` steps (``h`` the
    larger of 10 and 10 % of ``start``), steps out by ``2 h`` while the least sum of
    squares is at an end, moves to the vertex of the parabola through the least point and
    its two neighbours until that vertex is already fitted, then walks one step at a time
    while the sum of squares falls. Returns the delay (s), its fit, and how many fits it took.
    """
    step = float(rig.start.model.opt.timestep)
    bounds = PARAMETERS["input_delay"].bounds
    lo, hi = int(np.ceil(bounds[0] / step - 0.5)), int(np.floor(bounds[1] / step - 0.5))
    fits: dict[int, _Fit] = {}

    def at(k: int) -> int:
        k = int(np.clip(k, lo, hi))
        if k not in fits:
            rig.delay = (k + 0.5) * step
            warm = params.copy()
            if fits:
                warm.update_from_vector(fits[min(fits, key=lambda j: abs(j - k))].params.as_vector())
            tracker.fraction = min(len(fits) / 10, 0.99)  # a profile takes some 5 to 10 fits
            fits[k] = _fit(warm, residual_fn, max_iters, tracker)
        return k

    k0 = at(int(round(start / step - 0.5)))
    h = max(10, int(round(0.1 * k0)))
    at(k0 - h)
    at(k0 + h)
    for _ in range(20):
        ks = sorted(fits)
        sse = [fits[k].sse for k in ks]
        b = int(np.argmin(sse))
        if b in (0, len(ks) - 1):
            nxt = int(np.clip(ks[b] + (2 * h if b else -2 * h), lo, hi))
            if nxt in fits:
                break  # the least sum of squares is at a bound
            at(nxt)
            continue
        x = np.array(ks[b - 1 : b + 2], float)
        curv, slope, _ = np.polyfit(x - x[1], sse[b - 1 : b + 2], 2)
        vertex = int(round(x[1] - slope / (2 * curv))) if curv > 0 else ks[b]
        if vertex in fits:
            break
        at(vertex)
    best = min(fits, key=lambda k: fits[k].sse)
    for direction in (-1, 1):
        while fits[at(best + direction)].sse < fits[best].sse:
            best = int(np.clip(best + direction, lo, hi))
    rig.delay = (best + 0.5) * step
    return rig.delay, fits[best], len(fits)


def _delay_column(rig: _Rig, params: Any, residual_fn: Any, delay: float, steps: int = 10) -> np.ndarray:
    """Central difference of the residual in the transport delay, over ``+-steps`` physics steps (per s)."""
    dt = float(rig.start.model.opt.timestep)
    lo, hi = PARAMETERS["input_delay"].bounds
    ends = [float(np.clip(delay + sgn * steps * dt, lo, hi)) for sgn in (-1, 1)]
    cols = []
    for d in ends:
        rig.delay = d
        cols.append(np.concatenate(residual_fn(params.as_vector(), params)[0]))
    rig.delay = delay
    return (cols[1] - cols[0]) / (ends[1] - ends[0])


#: Seeded draws of the fitted model's turbulence that the disturbance intervals are estimated from.
DISTURBANCE_DRAWS = 32


def _disturbed(rig: _Rig, residual_fn: Any, params: Any, seq: Any, draws: int, seed: int) -> np.ndarray:
    """The change of the residual when the fitted model is driven by each of ``draws`` seeded turbulence draws.

    Each draw is the model's own rotor-wash turbulence (an Ornstein-Uhlenbeck thrust per rotor, held
    over each control interval, from its stationary distribution: :class:`~trms.twin.disturbances.Turbulence`)
    at the model's own level; :func:`~trms.calibration.intervals.disturbance_intervals` scales it to the data.
    Returns ``(draws, R)`` in the residual's layout; zeros when the model has no turbulence.
    """
    base = np.concatenate(residual_fn(params.as_vector(), params)[0])
    model = rig.build(params)
    turb = rig._by_model[id(model)].turbulence
    if not turb.active or not rig.wash_columns:
        return np.zeros((1, base.size))
    a = float(np.exp(-rig.sample_time / turb.time_constant))
    std = np.asarray(turb.std, float)[: len(rig.wash_columns)]
    group = [(traj.control, traj.initial_state) for traj in seq.measured_rollout]
    rng = np.random.default_rng(np.random.SeedSequence([seed, 1]))
    washes = []
    for _ in range(draws):
        for c, _ in group:
            w = rng.standard_normal((c.data.shape[0], std.size))
            w[0] /= np.sqrt(1.0 - a * a)  # the first value from the stationary distribution
            washes.append(std * np.sqrt(1.0 - a * a) * scipy.signal.lfilter([1.0], [1.0, -a], w, axis=0))
    # every draw of every record in one batch on all threads; the library's residual then finds them rolled out
    trajs = rig._roll([(model, c, x0) for _ in range(draws) for c, x0 in group], washes)
    out = np.empty((draws, base.size))
    for m in range(draws):
        rig._done = {(id(model), id(c)): trajs[m * len(group) + i] for i, (c, _) in enumerate(group)}
        out[m] = np.concatenate(residual_fn(params.as_vector(), params)[0]) - base
    rig._done = {}
    return out


def _calibrate(
    rig: _Rig,
    spec: mujoco.MjSpec,
    records: list[Record],
    held: list[Record],
    labels: list[str],
    held_labels: list[str],
    names: list[str],
    max_iters: int,
    report_dir: str | os.PathLike[str] | None,
    tracker: _Tracker,
    seed: int,
) -> TimeDomainResult:
    cfg = rig.config.name
    n_out = len(rig.config.outputs)
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
    params0 = _parameter_dict(spec, smooth)
    start = read_parameters(spec, names)

    t0 = time.perf_counter()
    fit_from, start_check, candidates = _feasible_start(rig, residual_fn, params0, labels, tracker, seed)
    fit_start = {n: float(fit_from[n].value[0]) for n in smooth}
    profile_fits = 0
    if "input_delay" in names:
        tracker.begin("delay profile")
        delay, fit, profile_fits = _profile_delay(rig, fit_from, residual_fn, max_iters, start["input_delay"], tracker)
        fit_start["input_delay"] = float(start["input_delay"])
    else:
        tracker.begin("fit")
        fit = _fit(fit_from, residual_fn, max_iters, tracker)
    opt_params = fit.params
    values = {n: float(opt_params[n].value[0]) for n in smooth}
    jac = fit.jacobian
    if "input_delay" in names:
        values["input_delay"] = delay
        jac = np.column_stack([jac, _delay_column(rig, opt_params, residual_fn, delay)])
    t_opt = time.perf_counter() - t0

    t0 = time.perf_counter()
    sizes = [(len(rec) - 1) * n_out for rec in records]
    residuals_star = np.split(fit.residual, np.cumsum(sizes)[:-1])
    order = smooth + (["input_delay"] if "input_delay" in names else [])
    _, white_half = sysid.calculate_intervals(residuals_star, jac)
    half, cov, bandwidth = sandwich_intervals(residuals_star, jac, np.linalg.pinv(jac.T @ jac), n_out)
    tracker.begin("disturbance intervals")
    disturbed = _disturbed(rig, residual_fn, opt_params, fit_seq[0], DISTURBANCE_DRAWS, seed)
    lags = max(1, int(round(1.0 / rig.start.sample_time)))
    half_d, cov_d, _ = disturbance_intervals(residuals_star, jac, disturbed, n_out, lags)
    widen = np.maximum(half_d / np.where(half > 0, half, np.inf), 1.0)
    half = half * widen  # the wider of the two, parameter by parameter
    cov = cov * np.outer(widen, widen)  # the sandwich's correlations, at the reported widths
    half = np.where(np.isfinite(white_half), half, np.inf)  # the library's verdict on undetermined directions
    if "input_delay" in names:  # the truth can lie anywhere in the fitted step: add its half-width
        half[-1] += 0.5 * float(rig.start.model.opt.timestep)
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
    fit_before: dict[str, list[float]] = {}
    fit_after: dict[str, list[float]] = {}
    fitted_delay = rig.delay
    for key, p in (("before", params0), ("after", opt_params)):
        rig.delay = None if key == "before" else fitted_delay
        _, preds, meas = check_fn(p.as_vector(), p, return_pred_all=True)
        per = [fit_percent(mm[0].data, pp[0].data) for pp, mm in zip(preds, meas)]
        target = fit_before if key == "before" else fit_after
        for j, o in enumerate(rig.config.outputs):
            target[o] = [float(f[j]) for f in per]
    t_check = time.perf_counter() - t0

    problems = []
    for n in names:
        lo, hi = PARAMETERS[n].bounds
        v, h = values[n], intervals[n]
        if min(v - lo, hi - v) <= 1e-6 * (hi - lo):
            problems.append(
                f"{n} = {v:.5g} {PARAMETERS[n].unit} sits at a bound of [{lo}, {hi}]: the data ask for more"
            )
        elif not np.isfinite(h) or h >= abs(v):
            problems.append(f"{n} is not determined by these records (95 % interval +-{h:.3g} around {v:.5g})")
    at_stops = [
        stop_reached(
            rec.outputs[:, [rec.output_names.index(o) for o in rig.config.outputs]],
            rec.time - rec.time[0],
            rig.stops,
            rig.config.outputs,
            label,
        )
        for rec, label in zip(records, labels)
    ]
    failures = _failures(
        fit,
        fit_before,
        fit_after,
        held_labels if held else labels,
        "held-out" if held else "fitted",
        [a for a in at_stops if a is not None],
    )

    html = None
    t0 = time.perf_counter()
    if report_dir is not None:
        tracker.begin("report")
        p = len(smooth)
        html = str(
            write_sysid_report(
                report_dir,
                fit_seq,
                params0,
                opt_params,
                residual_fn,
                scipy.optimize.OptimizeResult(x=opt_params.as_vector(), jac=fit.jacobian, extras=fit.extras),
                half[:p],
                cov[:p, :p],
                title=f"trms time-domain calibration ({cfg})",
                build_model=rig.build,
            )
        )
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


def _failures(
    fit: _Fit,
    before: dict[str, list[float]],
    after: dict[str, list[float]],
    labels: Sequence[str],
    kind: str,
    at_stops: Sequence[str] = (),
) -> list[str]:
    """Why a fit cannot be trusted: no optimiser step; a checked record's fit below 0 % or worse than the start's.

    Without a step, the reason named is the fitted records' first end-stop contact when they have one
    (``at_stops``, :func:`~trms.calibration.feasible_start.stop_reached`): its impacts make the
    residual jump with the parameters; else a residual flat in them.

    Examples
    --------
    >>> fit = _Fit(None, np.ones(1), np.zeros((1, 1)), 0, "norm(dx) < tol")
    >>> for line in _failures(fit, {"pitch": [-17.1]}, {"pitch": [-17.2]}, ["r3"], "held-out"):
    ...     print(line)
    the optimiser took no step (norm(dx) < tol): the residual is flat in the parameters there; nothing was calibrated
    pitch: the fit on held-out record r3 is -17.2 % after calibration, below 0 % (its mean predicts it better)
    pitch: the fit on held-out record r3 got worse than the start's (-17.1 % -> -17.2 %)
    """
    out = []
    if fit.iterations == 0 and at_stops:
        out.append(
            f"the optimiser took no step ({fit.stopped}): {at_stops[0]}, and its impacts make the residual jump "
            "with the parameters; nothing was calibrated (record the rig with inputs that keep it off its end stops)"
        )
    elif fit.iterations == 0 and fit.sse <= _EXACT:
        out.append(
            f"the optimiser took no step ({fit.stopped}): the start already reproduces the records "
            f"(sum of squares {fit.sse:.3g}); nothing was calibrated"
        )
    elif fit.iterations == 0:
        out.append(
            f"the optimiser took no step ({fit.stopped}): the residual is flat in the parameters there; "
            "nothing was calibrated"
        )
    for o in after:
        for label, b, a in zip(labels, before[o], after[o]):
            if not a >= 0:  # a NaN fit (a constant record) is no fit either
                out.append(
                    f"{o}: the fit on {kind} record {label} is {a:.1f} % after calibration, below 0 % "
                    "(its mean predicts it better)"
                )
            if a < b:
                out.append(f"{o}: the fit on {kind} record {label} got worse than the start's ({b:.1f} % -> {a:.1f} %)")
    return out


def scaled_spec(spec: mujoco.MjSpec, factors: dict[str, float]) -> mujoco.MjSpec:
    """A copy of ``spec`` with each named parameter multiplied by its factor (hidden truths for checks).

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> truth = scaled_spec(load_spec(), {"main_motor_lag": 1.2})
    """
    values = read_parameters(spec, list(factors))
    return with_parameters(spec, {n: values[n] * f for n, f in factors.items()})
