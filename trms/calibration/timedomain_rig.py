"""The records of one rig configuration as ``mujoco.sysid`` sees them, and the rollout hook.

:class:`_Rig` turns Records (absolute volts in, radians out) into ``ModelSequences``, compiles each
candidate's Twin once, and rolls every candidate out on the records in batches on one persistent
``mujoco.rollout.Rollout`` thread pool, the voltages through each candidate's thrust curve and held
one control interval (see :mod:`trms.calibration.timedomain`).
"""

from __future__ import annotations

import collections
from collections.abc import Callable, Sequence
from typing import Any

import mujoco
import mujoco.rollout
import numpy as np

from trms.errors import ConfigurationError
from trms.record import Record
from trms.twin.model import ROTORS, WASHES, configure_spec, get_configuration, spinning
from trms.twin.parameters import PARAMETERS, Parameter, read_parameters
from trms.twin.rotors import rotor_controls
from trms.twin.state_sensors import with_state_sensors
from trms.twin.twin import Twin

try:  # the mujoco[sysid] extra
    from mujoco import sysid

    _SYSID_ERROR: Exception | None = None if hasattr(sysid, "optimize") else ImportError("mujoco.sysid lacks optimize")
except ImportError as exc:  # pragma: no cover - depends on the installation
    sysid = None
    _SYSID_ERROR = exc

__all__: list[str] = []

_ROTOR_OF_INPUT = {"u1": 0, "u2": 1}
_CACHE = 64


def _require_sysid() -> None:
    if _SYSID_ERROR is not None:
        raise ConfigurationError(
            "time-domain calibration needs the sysid extra (mujoco.sysid is missing): "
            "install it with pip install 'trms[sysid]'"
        ) from _SYSID_ERROR


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
        # The candidates are twins: their models carry the state sensors (trms.twin.state_sensors), so does this.
        self.configured = configure_spec(
            with_state_sensors(spec), self.config, voltage_limit, timestep=self.start.model.opt.timestep
        )
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
