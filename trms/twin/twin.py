"""The Twin: the MuJoCo model of the rig as a :class:`trms.plant.Plant`.

One control interval is one native ``mujoco.mj_step(model, data, nstep)`` call (split
only where a push starts or ends inside the interval): no Python runs per physics step.
Only an interval that failed (a MuJoCo warning or a runaway state) is replayed one physics
step at a time, to report where it failed, before the state is restored exactly. An interval
that starts within reach of an end stop runs as one native ``mujoco.rollout`` call on the twin's
own data instead, which records the position at every physics step (bit-identical to ``mj_step``),
so the ``at_stop`` channel sees a stop touched between two samples; one that only ends within
reach of a stop is replayed that way on scratch data.
The rotor voltage passes through the static thrust curve once per interval (Hammerstein
form) and the motor lag is the actuator's exact first-order activation inside MuJoCo.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from typing import Any

import control
import mujoco
import numpy as np

from trms import reference
from trms.control.realization import continuous_jacobians
from trms.errors import (
    ConfigurationError,
    InputError,
    check_in_range,
    check_seed,
    short_repr,
)
from trms.modes import Mode
from trms.plant import InputVector, check_input_vector, simulate
from trms.record import OperatingPoint, Record
from trms.twin.built import built
from trms.twin.disturbances import Gust, NormalDraws, OUStep, Push, Turbulence
from trms.twin.interval import AXES, FULL_STATE, SAVED_STATE, raised_warnings
from trms.twin.linearise import Linearisation, c2d_with_delay, oscillatory_modes, state_names, transition_jacobians
from trms.twin.model import (
    WASHES,
    Configuration,
    check_spec,
    encoder_noise,
    get_configuration,
    input_delay,
    load_spec,
    spin_dofs,
    spinning,
    thrust_curves,
    turbulence,
)
from trms.twin.open_loop import OpenLoop
from trms.twin.sampling import check_sample_time, physics_timestep
from trms.twin.sensors import DEFAULT_COUNTS_PER_REV, Encoder

__all__ = ["Twin"]

_INPUT_ROTOR = {"u1": 0, "u2": 1}


class Twin(OpenLoop):
    """The TRMS twin as a Plant: absolute volts in, encoder angles (rad) out.

    Parameters
    ----------
    config : {"1dof", "2dof", "yaw"}
        ``1dof``: yaw locked, SISO u1 -> pitch. ``2dof``: u1, u2 -> pitch, yaw.
        ``yaw``: pitch locked flat, u1, u2 -> yaw. An absent rotor is held at 0 V.
    sample_time : float
        Control sample time (s): 0.001 to 32.767 in 0.001 s steps, a whole multiple of the
        physics step (1 ms).
    seed : int
        Seed of measurement noise and gusts (``reset`` may override it).
    model_path : path-like, optional
        MJCF file (default: the shipped, calibrated ``trms/models/trms.xml``).
    spec : mujoco.MjSpec, optional
        An already parsed (e.g. modified) spec instead of ``model_path``.
    counts_per_rev : int
        Encoder resolution; 0 disables quantisation. See :data:`~trms.twin.sensors.DEFAULT_COUNTS_PER_REV`.
    noise_std : float, optional
        Standard deviation of white noise on each measured angle before quantisation (rad); default:
        the rig's electronics noise on each axis (the MJCF's custom numeric ``encoder_noise``, calibrated
        parameters), 0 with ``still_air``.
    still_air : bool
        The noiseless twin: no rotor-wash turbulence (:attr:`turbulence`) and, unless ``noise_std``
        is given, no electronics noise. By default the twin, like the rig, is never still.
    gust : Gust, optional
        Gust torques (an experiment's moving air; off by default).
    pushes : sequence of Push
        Torque pulses on the beam.
    voltage_limit : float
        Motor voltage saturation (V), in ``(0, 10]``: 10 V on the rig, whose drives saturate there.

    Attributes
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
        The compiled configuration and its live state.
    trim : Trim
        Hover trim (voltages of both rotors, joint angles, lagged thrusts).
    turbulence : Turbulence
        The rotor-wash turbulence in effect: the model's (custom numeric ``rotor_turbulence``), none
        with ``still_air`` or a model without turbulence actuators.
    input_rotors : numpy.ndarray
        Rotor (actuator) index of each plant input.
    output_qpos : numpy.ndarray
        ``qpos`` index of each measured angle.
    """

    def __init__(
        self,
        config: str = "2dof",
        sample_time: float = 0.1,
        seed: int = 0,
        *,
        model_path: str | os.PathLike[str] | None = None,
        spec: mujoco.MjSpec | None = None,
        counts_per_rev: int = DEFAULT_COUNTS_PER_REV,
        noise_std: float | None = None,
        still_air: bool = False,
        gust: Gust | None = None,
        pushes: Iterable[Push] = (),
        voltage_limit: float = reference.VOLTAGE_LIMIT,
    ) -> None:
        self.configuration: Configuration = get_configuration(config)
        if spec is not None and not isinstance(spec, mujoco.MjSpec):
            raise InputError(
                f"spec = {short_repr(spec)} must be a mujoco.MjSpec (e.g. from trms.twin.load_spec) or None"
            )
        if spec is not None and model_path is not None:
            raise InputError("pass either spec or model_path, not both")
        if gust is not None and not isinstance(gust, Gust):
            raise InputError(f"gust = {short_repr(gust)} must be a trms.twin.Gust (e.g. Gust(0.004, 2.0)) or None")
        if isinstance(pushes, Push) or not isinstance(pushes, Iterable) or isinstance(pushes, (str, bytes)):
            raise InputError(
                f"pushes = {short_repr(pushes)} must be a sequence of trms.twin.Push, "
                "e.g. [Push(18.0, 0.1, (0.02, 0.0))]"
            )
        self._spec = spec.copy() if spec is not None else load_spec(model_path)
        if spec is not None:  # a file is checked as it loads; a spec here, before the cache of built models hides it
            check_spec(self._spec)
        try:  # the drives saturate at +-10 V, and the thrust curve is measured within them
            self.voltage_limit = check_in_range(
                "voltage_limit", voltage_limit, 0.0, reference.VOLTAGE_LIMIT, unit=" V", low_open=True
            )
        except InputError as exc:
            raise InputError(f"{exc} (the rig's drives saturate at +-{reference.VOLTAGE_LIMIT:g} V)") from None
        step = physics_timestep(sample_time, self._spec.option.timestep)
        # The compiled rig, and the same rig without the transport delay (trim and linearisation, which adds the
        # delay exactly), with its hover trim: built once per model and settings in the process.
        trim_rotors = tuple(_INPUT_ROTOR[u] for u in self.configuration.trim_inputs)
        self.model, self._model_lin, self.trim = built(
            self._spec, self.configuration, self.voltage_limit, step, trim_rotors, AXES
        )
        self.input_delay = input_delay(self._spec)
        self.data = mujoco.MjData(self.model)
        self._physics_step = float(self.model.opt.timestep)  # s (read once: each read builds an object)
        self._nsub = check_sample_time(sample_time, self._physics_step)
        self.sample_time = float(self._nsub * self._physics_step)
        self.seed = check_seed("seed", seed, allow_none=False)
        if not isinstance(still_air, (bool, np.bool_)):
            raise InputError(f"still_air = {still_air!r} must be True or False")
        self.still_air = bool(still_air)
        per_axis = dict(zip(AXES, encoder_noise(self._spec)))
        noise = (
            (0.0 if self.still_air else tuple(per_axis[a] for a in self.configuration.outputs))
            if noise_std is None
            else noise_std
        )
        self.encoder = Encoder(counts_per_rev, noise)
        self.gust = gust or Gust()
        self.turbulence = Turbulence() if self.still_air else turbulence(self._spec)
        names = [self.model.actuator(i).name for i in range(self.model.nu)]
        self._wash = np.array([names.index(w) for w in WASHES if w in names], dtype=int)
        self._wash_list = self._wash.tolist()
        self._spinning = spinning(self.model)
        self.pushes = tuple(pushes)
        bad = next((p for p in self.pushes if not isinstance(p, Push)), None)
        if bad is not None:
            raise InputError(f"pushes must hold trms.twin.Push instances, got {short_repr(bad)}")
        self.curves = thrust_curves(self._spec)

        cfg = self.configuration
        self.input_names: tuple[str, ...] = cfg.inputs
        self.output_names: tuple[str, ...] = cfg.outputs
        self.input_rotors = np.array([_INPUT_ROTOR[u] for u in cfg.inputs])
        n_in = len(self.input_names)
        self._limits = (np.full(n_in, -self.voltage_limit), np.full(n_in, self.voltage_limit))
        self._axis_qpos = {a: self.model.jnt_qposadr[self.model.joint(a).id] for a in AXES if a not in cfg.locked}
        self._axis_dof = {a: self.model.jnt_dofadr[self.model.joint(a).id] for a in AXES if a not in cfg.locked}
        self.output_qpos = np.array([self._axis_qpos[a] for a in cfg.outputs])
        # The same as plain lists, and the data's warning counters (a view), for the per-interval path.
        self._input_rotor_list: list[int] = self.input_rotors.tolist()
        self._output_qpos_list: list[int] = self.output_qpos.tolist()
        self._warning_counts = self.data.warning.number
        self._output_dof = np.array([self._axis_dof[a] for a in cfg.outputs])
        self._output_dof_list: list[int] = self._output_dof.tolist()
        self._index_stops()
        # The same as index arrays, for the per-sample channels: free axes (in AXES order) and where they live.
        self._free = np.array([a in self._axis_qpos for a in AXES])
        self._free_qpos = np.array([self._axis_qpos[a] for a in AXES if a in self._axis_qpos], dtype=int)
        self._free_dof = np.array([self._axis_dof[a] for a in AXES if a in self._axis_dof], dtype=int)
        # Per free axis, its dof and its place in a (pitch, yaw) torque; views of the data the intervals read and write.
        self._torque_slots = [(int(self._axis_dof[a]), i) for i, a in enumerate(AXES) if a in self._axis_dof]
        d = self.data
        self._qfrc_applied, self._ctrl = d.qfrc_applied, d.ctrl
        self._qpos, self._qvel, self._act = d.qpos, d.qvel, d.act
        self._op = OperatingPoint(
            self.trim.voltages[self.input_rotors], np.zeros(len(cfg.outputs)), cfg.inputs, cfg.outputs
        )
        self._state_buf = np.empty(mujoco.mj_stateSize(self.model, SAVED_STATE))
        self._full_size = mujoco.mj_stateSize(self.model, FULL_STATE)
        self._interval_span = (self._nsub - 0.5) * self._physics_step  # less: MuJoCo reset the data
        self._step_index = 0
        self._gust_torque = np.zeros(2)
        self._turbulence = np.zeros(2)
        self._ou_cache: tuple[Any, ...] = (None, None, None, None)
        self._volts = self.trim.voltages.copy()
        self.reset()

    # ------------------------------------------------------------ Plant API
    @property
    def operating_point(self) -> OperatingPoint:
        """Hover trim: the input voltages (V) that hold the beam flat, outputs 0 rad."""
        return self._op

    @property
    def input_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Absolute voltage limits (V): +-``voltage_limit`` on every input."""
        lo, hi = self._limits
        return lo.copy(), hi.copy()

    @property
    def applied_input(self) -> np.ndarray:
        """Voltages held during the last step, after saturation (V)."""
        return self._volts[self.input_rotors].copy()

    @property
    def spec(self) -> mujoco.MjSpec:
        """A copy of the parameter set this twin was built from (build another twin of the same rig with it)."""
        return self._spec.copy()

    def reset(self, seed: int | None = None) -> np.ndarray:
        """Put the rig at the hover trim, reseed noise, turbulence and gusts, return the first measurement (rad).

        Parameters
        ----------
        seed : int, optional
            Overrides the constructor's seed for this run.
        """
        seed = self.seed if seed is None else check_seed("seed", seed)
        self._run_seed = seed
        noise_ss, gust_ss, turbulence_ss = np.random.SeedSequence(seed).spawn(3)
        # Each stream's normals drawn a block at a time (the same numbers in the same order as one by one).
        self._noise_rng = NormalDraws(np.random.default_rng(noise_ss))
        self._gust_rng = NormalDraws(np.random.default_rng(gust_ss))
        self._turbulence_rng = NormalDraws(np.random.default_rng(turbulence_ss))
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        self.put_at_trim(m, d)
        self._step_index = 0
        self._interval_stops = None
        self._volts = self.trim.voltages.copy()
        self._gust_torque = self.gust.start(self._gust_rng)
        self._turbulence = self.turbulence.start(self._turbulence_rng) if self.turbulence.active else np.zeros(2)
        return self._measure()

    def step(self, u: InputVector) -> np.ndarray:
        """Hold voltages ``u`` (V) for one sample; return the encoder angles at the next sample (rad).

        Voltages beyond +-``voltage_limit`` saturate (recorded in ``applied_input`` and the
        Record's ``saturated`` channel).

        Raises
        ------
        InputError
            Wrong shape or non-finite voltages (state unchanged).
        DivergenceError
            The simulation blew up (a non-finite or runaway state, or MuJoCo's BADQACC, BADQPOS or
            BADQVEL warning): the message gives the physics step where it happened and the last
            finite state before it; the state is restored bit-exactly to before the step.
        SimulationError
            Any other MuJoCo warning during the interval (every counter of ``data.warning`` is
            checked after each interval); the state is restored the same way.
        """
        return self._interval(self._command(u))

    def step_checked(self, u: np.ndarray) -> np.ndarray:
        """:meth:`step` for voltages already checked (V): a float64 array of ``n_inputs`` finite numbers, as
        :func:`trms.plant.check_input_vector` returns them (what the environments pass). They are saturated, not
        checked again.

        Examples
        --------
        >>> a, b = Twin("1dof", 0.1), Twin("1dof", 0.1)
        >>> u = a.operating_point.inputs + 0.5
        >>> bool((a.step(u) == b.step_checked(u)).all())
        True
        """
        return self._interval(self._saturate(u.tolist()))

    def _interval(self, volts: np.ndarray) -> np.ndarray:
        """Hold ``volts`` (both rotors', saturated; V) for one control interval: :meth:`step` after its checks."""
        m, d = self.model, self.data
        mujoco.mj_getState(m, d, self._state_buf, SAVED_STATE)
        counters = self._warning_counts
        warnings_before = counters.tolist()  # every counter, one list (no per-warning objects)
        t_start = d.time
        ctrl = self._thrust(volts)
        self._ctrl[:] = ctrl
        k = self._step_index
        start = k * self._nsub
        torqued = bool(self.pushes) or bool(self.gust.std)
        start_values = self._stop_start()
        recorded = self._stop_ahead(start_values)
        if recorded:  # near an end stop: the same interval, every physics step's position recorded
            positions = self._run_recorded(d, volts)
            counters[:] += warnings_before  # rollout counts the interval's warnings from zero
        elif torqued and self.pushes and self._pushed(k):
            for n_steps, torque in self._segments(start):
                self._apply_torque(torque)
                mujoco.mj_step(m, d, n_steps)
        elif torqued:  # the gusts alone (plus no push: a push's sum starts from 0.0)
            self._apply_torque(self._gust_torque, plus_zero=bool(self.pushes))
            mujoco.mj_step(m, d, self._nsub)
        else:  # no torque to apply: qfrc_applied holds zeros already
            mujoco.mj_step(m, d, self._nsub)
        if torqued:
            self._qfrc_applied[:] = 0.0
        # MuJoCo resets the data (and its warning counters) when accelerations blow up: time running backwards
        # catches a reset that left the counters where they were.
        reset = d.time < t_start + self._interval_span
        qpos, qvel = self._qpos.tolist(), self._qvel.tolist()
        if reset or counters.tolist() != warnings_before or not self._finite_state(qpos, qvel):
            self._refuse_interval(volts, ctrl, start, raised_warnings(d, warnings_before))
        if recorded:
            stops = self._against_stops(positions)
        else:
            stops = self._stops_in_interval(volts, qpos, qvel, start_values)
        return self._commit(volts, stops, qpos)

    def _command(self, u: InputVector) -> np.ndarray:
        """Validate and saturate ``u`` (V); return the voltages of both rotors to hold."""
        return self._saturate(check_input_vector(u, len(self.input_names), self.input_names).tolist())

    def _saturate(self, asked: list[float]) -> np.ndarray:
        """The voltages of both rotors (V) to hold for the inputs ``asked`` (V, plain floats), saturated."""
        limit = self.voltage_limit
        volts = self._volts.tolist()
        for rotor, v in zip(self._input_rotor_list, asked):
            volts[rotor] = min(max(v, -limit), limit)  # plain floats: np.clip's values
        return np.array(volts)

    def _commit(self, volts: np.ndarray, at_stop: np.ndarray, qpos: list[float] | None = None) -> np.ndarray:
        """Close an interval: hold ``volts``, record its end-stop contact, advance time, gusts and turbulence,
        measure (``qpos``: the data's as plain floats, when at hand)."""
        self._volts = volts
        self._interval_stops = at_stop
        self._step_index += 1
        gust_step, turbulence_step = self._ou_steps()
        self._gust_torque = np.zeros(2) if gust_step is None else gust_step(self._gust_torque, self._gust_rng)
        if turbulence_step is not None:
            self._turbulence = turbulence_step(self._turbulence, self._turbulence_rng)
        return self._measure(qpos)

    def _ou_steps(self) -> tuple[OUStep | None, OUStep | None]:
        """The gusts' and the turbulence's interval step (None where off), built again if either was replaced."""
        cached = self._ou_cache
        if cached[0] is not self.gust or cached[1] is not self.turbulence:
            gust, turbulence, ts = self.gust, self.turbulence, self.sample_time
            cached = self._ou_cache = (
                gust,
                turbulence,
                OUStep(gust.std, gust.time_constant, ts) if gust.std else None,
                OUStep(turbulence.std, turbulence.time_constant, ts) if turbulence.active else None,
            )
        return cached[2], cached[3]

    def readings(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Now: the true angle (rad) and rate (rad/s) of each measured axis and the tachometer reading of each input's
        rotor (rotor state), as :meth:`channels` gives them (``true_angles``, ``rates``, ``rotor_speed``) for the
        plant's outputs and inputs alone, without building the other channels.

        Examples
        --------
        >>> twin = Twin("2dof", 0.1)
        >>> _ = twin.step(twin.operating_point.inputs + 0.5)
        >>> true, rates, speed = twin.readings()
        >>> ch = twin.channels()
        >>> bool((true == ch["true_angles"]).all() and (speed == ch["rotor_speed"][twin.input_rotors]).all())
        True
        """
        true, rates, speed = self.reading_values()
        return np.array(true), np.array(rates), np.array(speed)

    def reading_values(self) -> tuple[list[float], list[float], list[float]]:
        """:meth:`readings` as plain floats (rad, rad/s, rotor state): the environments' per-step path, the same bits.

        Examples
        --------
        >>> twin = Twin("1dof", 0.1)
        >>> _ = twin.step(twin.operating_point.inputs + 0.5)
        >>> [a.tolist() for a in twin.readings()] == list(twin.reading_values())
        True
        """
        qpos, qvel, act = self._qpos.tolist(), self._qvel.tolist(), self._act.tolist()
        curves = self.curves
        return (
            [qpos[i] for i in self._output_qpos_list],
            [qvel[i] for i in self._output_dof_list],
            [curves[r]._rotor_state_of(act[r]) for r in self._input_rotor_list],
        )

    def channels(self) -> dict[str, np.ndarray]:
        """Extra channels at the current sample.

        ``true_angles`` (pitch, yaw; rad, 0 when locked), ``rates`` (rad/s), ``rotor_thrust``
        (lagged thrust, N), ``rotor_speed`` (tachometer: rotor state tau, volts-equivalent
        units), ``disturbance`` (gust plus push torque on pitch, yaw; N m), ``turbulence`` (the rotor-wash
        thrust fluctuation of the main and tail rotor held over the coming interval; N) and ``qpos``
        (every joint, rad; enough to render the sample), ``at_stop`` (pitch, yaw; True when the axis
        touched an end stop during the interval that ended at this sample, i.e. MuJoCo's joint-limit
        constraint was active at any physics step of it, its start and end included; after ``reset``,
        whether it is active now), like ``saturated`` for the inputs.
        """
        d = self.data
        true, rates = np.zeros(len(AXES)), np.zeros(len(AXES))
        true[self._free], rates[self._free] = d.qpos[self._free_qpos], d.qvel[self._free_dof]
        speed = np.array([c._rotor_state_of(f) for c, f in zip(self.curves, d.act.tolist())])
        return {
            "true_angles": true,
            "rates": rates,
            "rotor_thrust": d.act.copy(),
            "rotor_speed": speed,
            "disturbance": self._gust_torque + self._push_torque(self._step_index * self._nsub),
            "turbulence": self._turbulence.copy(),
            "qpos": d.qpos.copy(),
            "at_stop": self._stops_now() if self._interval_stops is None else self._interval_stops.copy(),
        }

    def run(self, inputs: np.ndarray | Sequence[Sequence[float]], seed: int | None = None) -> Record:
        """Reset, apply ``inputs`` (absolute V, shape ``(N, n_inputs)``), return the Record.

        Same seed, bit-identical Record.
        """
        seed = self.seed if seed is None else check_seed("seed", seed)
        meta: dict[str, Any] = {
            "config": self.configuration.name,
            "counts_per_rev": self.encoder.counts_per_rev,
            "noise_std": list(self.encoder.noise_std)
            if isinstance(self.encoder.noise_std, tuple)
            else self.encoder.noise_std,
            "still_air": self.still_air,
            "turbulence": {"std": list(self.turbulence.std), "time_constant": self.turbulence.time_constant},
            "gust": {"std": self.gust.std, "time_constant": self.gust.time_constant},
            "pushes": [{"time": p.time, "duration": p.duration, "torque": list(p.torque)} for p in self.pushes],
            "physics_timestep": float(self.model.opt.timestep),
        }
        return simulate(self, inputs, seed, meta)

    # ------------------------------------------------------------ internals
    def put_at_trim(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """Set ``d`` (freshly reset) to the hover trim, the delay lines holding the trim controls."""
        d.qpos[:] = self.trim.qpos
        d.qvel[:] = self.trim.qvel
        d.act[:] = self.trim.act
        d.ctrl[:] = self.trim.ctrl
        for i in range(m.nu):
            nsample = int(m.actuator_history[i, 0])
            if nsample > 0:
                mujoco.mj_initCtrlHistory(m, d, i, None, np.full((nsample, 1), self.trim.ctrl[i]))
        mujoco.mj_forward(m, d)

    def _measure(self, qpos: list[float] | None = None) -> np.ndarray:
        """The encoders' reading now (``qpos``: the data's as plain floats, when at hand)."""
        q = self.data.qpos.tolist() if qpos is None else qpos
        return self.encoder.measure_values([q[i] for i in self._output_qpos_list], self._noise_rng)

    # ------------------------------------------------------------ analysis
    def linearise(self) -> Linearisation:
        """Linearise at the hover trim: inputs are voltage deviations (V), outputs angle deviations (rad).

        The thrust curve's slope (and the rotor speed's) at the trim voltage converts the
        actuators' inputs to volts; the transport delay is added exactly in ``discrete``.
        """
        m = self._model_lin
        d = mujoco.MjData(m)
        self.put_at_trim(m, d)
        A_d, B_d, h = transition_jacobians(m, d)
        A_c, B_c = continuous_jacobians(A_d, B_d, h)
        n_rot = len(self.curves)
        volts = self.trim.voltages
        B_v = np.zeros((A_c.shape[0], len(self.input_rotors)))
        for col, i in enumerate(self.input_rotors):
            B_v[:, col] = B_c[:, i] * float(self.curves[i].slope(volts[i]))
            if self._spinning:  # the spin motor's speed command moves with the voltage too
                dw = self.curves[i].w_per_state * self.curves[i].k * (not self.curves[i].at_full_speed(volts[i]))
                B_v[:, col] += B_c[:, n_rot + i] * dw
        names = state_names(m)
        keep = np.setdiff1d(np.arange(A_c.shape[0]), spin_dofs(m))  # spin angles: cyclic, nothing depends on them
        A_c, B_v, names = A_c[np.ix_(keep, keep)], B_v[keep], [names[k] for k in keep]
        C = np.zeros((len(self.output_names), A_c.shape[0]))
        for row, axis in enumerate(self.output_names):
            C[row, names.index(axis)] = 1.0
        D = np.zeros((len(self.output_names), len(self.input_names)))
        sys_c = control.ss(
            A_c,
            B_v,
            C,
            D,
            inputs=list(self.input_names),
            outputs=list(self.output_names),
            states=names,
            name=f"twin_{self.configuration.name}",
        )
        sys_d = c2d_with_delay(sys_c, self.sample_time, self.input_delay)
        return Linearisation(sys_c, sys_d, names, self.input_delay)

    def yaw_rate_to_pitch_torque(self, eps: float = 1e-4) -> float:
        """The pitch torque per yaw rate at the hover trim (N m s/rad): the rig's gyroscopic coupling.

        Computed from MuJoCo's own equations of motion: the derivative of the generalised force on the
        pitch axis (actuator and passive forces less the bias forces, which hold the rotors' gyroscopic and
        Coriolis terms) with respect to the yaw rate, by central differences of ``eps`` rad/s.

        Raises
        ------
        ConfigurationError
            A configuration with a locked axis (the coupling needs both).

        Examples
        --------
        >>> k = Twin("2dof", 0.1).yaw_rate_to_pitch_torque()
        >>> 0.0 < k < 0.05
        True
        """
        if self.configuration.locked:
            raise ConfigurationError(
                f"the yaw-rate-to-pitch coupling needs both axes free; configuration {self.configuration.name!r} "
                f"locks {', '.join(self.configuration.locked)} (use '2dof')"
            )
        m = self._model_lin
        d = mujoco.MjData(m)
        self.put_at_trim(m, d)
        pitch, yaw = (int(m.jnt_dofadr[m.joint(a).id]) for a in AXES)
        force = []
        for sign in (1.0, -1.0):
            d.qvel[yaw] = self.trim.qvel[yaw] + sign * eps
            mujoco.mj_forward(m, d)
            force.append(d.qfrc_actuator[pitch] + d.qfrc_passive[pitch] - d.qfrc_bias[pitch])
        return float((force[0] - force[1]) / (2.0 * eps))

    def modes(self) -> list[Mode]:
        """Natural frequency (Hz) and damping ratio of each oscillatory mode at the hover trim."""
        lin = self.linearise()
        return oscillatory_modes(np.asarray(lin.continuous.A), lin.state_names)

    def __repr__(self) -> str:
        return (
            f"Twin(config={self.configuration.name!r}, sample_time={self.sample_time}, seed={self.seed}, "
            f"hover={self._op.inputs.round(4).tolist()} V)"
        )
