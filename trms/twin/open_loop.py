"""Open-loop runs of the twin as native ``mujoco.rollout`` calls over the whole record.

Everything a run of :meth:`Twin.step <trms.twin.Twin.step>` computes in Python per control interval -- the
saturation, the thrust curve, the rotor-wash turbulence it holds, the gust and push torques, the encoder's noise --
depends on the inputs and the seeds alone, never on the state. So an open-loop run draws it all beforehand (the same
draws, in the same order, from the same generators) and expands it into the controls of every physics step (the
rotor controls held over each interval, ``qfrc_applied`` with a push where it acts); ``mujoco.rollout`` then steps
the whole record, in chunks of whole intervals, on the twin's own data, recording the state sensors of
:mod:`trms.twin.state_sensors` at every physics step. The samples, the channels and ``at_stop`` (every physics step's
position, each interval's start and end included) are read off that record.

A stepped run's rules are kept: a run whose record shows a MuJoCo warning, a MuJoCo reset, or a non-finite or
runaway state at the end of an interval is not used; :meth:`~OpenLoop.open_loop` says so (None), and the run is
stepped from its start, which raises the error a stepped run raises and leaves the twin where it leaves it. A run
that succeeds leaves the twin exactly where the steps would have left it (state, delay lines, warm start, random
generators, the data's every field), and its record equals theirs bit for bit.

A closed loop batched over many twins runs one interval at a time the same way: :meth:`~OpenLoop.interval_controls`
gives what one step feeds MuJoCo, a rollout runs it, and :meth:`~OpenLoop.finish_interval` takes the state it reached.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
from mujoco import rollout

from trms.errors import as_finite_array
from trms.plant import InputVector, saturate
from trms.twin.disturbances import NormalDraws
from trms.twin.interval import AXES, FULL_STATE, MAX_RATE, ROLLOUT_CONTROL, SAVED_STATE, IntervalPhysics
from trms.twin.rotors import rotor_controls
from trms.twin.sensors import Encoder
from trms.twin.state_sensors import StateColumns, state_columns

__all__ = ["CHUNK_STEPS"]

#: Physics steps per rollout call (whole intervals, at least one): bounds the buffers of a long record.
CHUNK_STEPS = 4096
_CTRL_ONLY = mujoco.mjtState.mjSTATE_CTRL


class OpenLoop(IntervalPhysics):
    """Open-loop runs of a whole record, and single intervals run by a rollout (a base of
    :class:`~trms.twin.twin.Twin`, which sets every attribute and method declared here)."""

    encoder: Encoder
    input_names: tuple[str, ...]
    input_rotors: np.ndarray
    output_qpos: np.ndarray
    _limits: tuple[np.ndarray, np.ndarray]
    _volts: np.ndarray
    _free_qpos: np.ndarray
    _noise_rng: NormalDraws
    _gust_rng: NormalDraws
    _turbulence_rng: NormalDraws
    _full_size: int
    reset: Callable[..., np.ndarray]
    _command: Callable[[InputVector], np.ndarray]
    _commit: Callable[..., np.ndarray]

    def open_loop(
        self, inputs: np.ndarray, seed: int | None = None, channels: bool = True
    ) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]] | None:
        """Reset with ``seed`` and hold each row of ``inputs`` (absolute V) for one sample, natively.

        What :func:`trms.plant.drive` records of the same run, step by step, the same bits; the twin is left where
        the steps leave it.

        Parameters
        ----------
        inputs : numpy.ndarray
            ``(N, n_inputs)`` absolute voltages (V).
        seed : int, optional
            Passed to :meth:`reset`.
        channels : bool
            Also return the channels of every sample.

        Returns
        -------
        (outputs, applied, channels) or None
            The measurements at ``t_0 .. t_{N-1}`` (rad, ``(N, n_outputs)``), the applied voltages (V) and the
            channels (``N`` rows each; empty without ``channels``); None where the run cannot be taken natively
            (a model whose sensors do not hold its state) or did not succeed (a warning, a reset, a non-finite or
            runaway state): step it then, which reports the failure as :meth:`step` does.

        Raises
        ------
        InputError
            Inputs that are not finite or not ``(N, n_inputs)`` (the twin is not touched).

        Examples
        --------
        >>> from trms.twin import Twin
        >>> from trms.plant import drive
        >>> twin = Twin("1dof", 0.1, seed=3)
        >>> u = twin.operating_point.inputs + np.linspace(-1.0, 1.0, 50)[:, None]
        >>> y, applied, ch = twin.open_loop(u)
        >>> stepped = drive(twin, 50, lambda k, y: u[k], seed=3)
        >>> bool((y == stepped.outputs).all() and (ch["qpos"] == stepped.extras["qpos"]).all())
        True
        """
        u = as_finite_array(f"inputs ({', '.join(self.input_names)}) in V", inputs, (None, len(self.input_names)))
        columns = state_columns(self.model)
        if columns is None:
            return None
        y0 = self.reset(seed)
        n = u.shape[0]
        if n == 0:
            return y0[None][:0], u.copy(), {}
        ts = self.sample_time
        applied, _ = saturate(u, *self._limits)
        volts = np.empty((n, self._volts.size))
        volts[:] = self._volts
        volts[:, self.input_rotors] = applied
        turbulence = self.turbulence.path(self._turbulence, ts, self._turbulence_rng, n)
        gust = self.gust.path(self._gust_torque, ts, self._gust_rng, n)
        ctrl = rotor_controls(self.curves, volts, self.model.nu, self._spinning)
        if self._wash.size:
            ctrl[:, self._wash] = turbulence[:n]
        pushed = self._push_steps(n)
        states = self._roll(columns, ctrl, gust, pushed)
        if states is None:
            return None
        q, v, act, near_start, near_any = states
        # An interval touched a stop if any of its physics steps' starts did, or its end (the next one's start).
        stops = near_any | np.concatenate([near_start[1:], self._near(self.data.qpos[self._stop_qpos][None])])
        measured = self.encoder.measure(q[1:, self.output_qpos], self._noise_rng)  # every later sample's draw
        outputs = np.concatenate([y0[None], measured[:-1]])
        self._step_index = n
        self._volts = volts[-1].copy()
        self._interval_stops = self._axes_of(stops[-1:])[0]
        self._gust_torque, self._turbulence = gust[n].copy(), turbulence[n].copy()
        self.data.ctrl[:] = ctrl[-1]
        self.data.qfrc_applied[:] = 0.0
        if not channels:
            return outputs, applied, {}
        true, rates = np.zeros((n, len(AXES))), np.zeros((n, len(AXES)))
        true[:, self._free] = q[:n, self._free_qpos]
        rates[:, self._free] = v[:n, self._free_dof]
        speed = np.column_stack([c.rotor_state(a) for c, a in zip(self.curves, act[:n].T)])
        disturbance = gust[:n] + (pushed[:: self._nsub] if pushed is not None else np.zeros(2))
        return (
            outputs,
            applied,
            {
                "true_angles": true,
                "rates": rates,
                "rotor_thrust": act[:n],
                "rotor_speed": speed,
                "disturbance": disturbance,
                "turbulence": turbulence[:n],
                "qpos": q[:n],
                "at_stop": np.concatenate([self._axes_of(near_start[:1]), self._axes_of(stops[:-1])]),
            },
        )

    def interval_controls(self, u: InputVector) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What one :meth:`step` under voltages ``u`` (V) feeds MuJoCo, for ``mujoco.rollout`` to run it.

        The twin keeps ``u`` (saturated, recorded as by :meth:`step`) until :meth:`finish_interval`.

        Returns
        -------
        controls : numpy.ndarray
            ``(nsub, nu + nv)``: per physics step the rotor controls (thrust-curve outputs, N) and
            ``qfrc_applied`` (gust and push torques, N m), in the layout of
            ``mjSTATE_CTRL | mjSTATE_QFRC_APPLIED``.
        state : numpy.ndarray
            The full-physics state (``mjSTATE_FULLPHYSICS``) the interval starts from.
        warmstart : numpy.ndarray
            The constraint solver's warm start (``nv``).

        Raises
        ------
        InputError
            Wrong shape or non-finite voltages (state unchanged).

        Examples
        --------
        >>> from trms.twin import Twin
        >>> twin = Twin("1dof", 0.1)
        >>> controls, state, warm = twin.interval_controls(twin.operating_point.inputs)
        >>> round(controls.shape[0] * twin.model.opt.timestep, 9), controls.shape[1] == twin.model.nu + twin.model.nv
        (0.1, True)
        """
        volts = self._command(u)
        m, d = self.model, self.data
        state = np.empty(self._full_size)
        mujoco.mj_getState(m, d, state, FULL_STATE)
        self._pending = volts
        controls = self._interval_rows(volts)
        self._pending_ctrl = controls[0, : m.nu].copy()
        return controls, state, d.qacc_warmstart.copy()

    def finish_interval(self, state: np.ndarray, start_state: np.ndarray) -> np.ndarray:
        """Take the state a rollout of :meth:`interval_controls` reached; return the measurement (rad).

        Parameters
        ----------
        state : numpy.ndarray
            Full-physics state at the end of the interval.
        start_state : numpy.ndarray
            The state :meth:`interval_controls` returned (restored if the interval diverged).

        Raises
        ------
        DivergenceError
            The interval blew up (MuJoCo reset the data, or non-finite or runaway state); the twin
            is left at the interval's start, as by :meth:`step`.
        """
        m, d = self.model, self.data
        volts = self._pending
        mujoco.mj_getState(m, d, self._state_buf, SAVED_STATE)  # the interval's start, warm start included
        mujoco.mj_setState(m, d, state, FULL_STATE)
        d.ctrl[:] = self._pending_ctrl
        reset = not state[0] >= start_state[0] + (self._nsub - 0.5) * m.opt.timestep  # MuJoCo resets a blow-up
        if reset or not self._finite_state():
            raise self._restore(start_state, volts)
        return self._commit(volts, self._stops_in_interval(volts))

    def _push_steps(self, n: int) -> np.ndarray | None:
        """The pushes' torque (pitch, yaw; N m) at each physics step of an ``n``-interval run, summed in their
        order from 0 as a step sums them; None without pushes."""
        if not self.pushes:
            return None
        total = n * self._nsub
        torque = np.zeros((total, len(AXES)))
        for p in self.pushes:
            a, b = p.steps(self.model.opt.timestep)
            if a < total:
                torque[a:b] += p.torque
        return torque

    def _near(self, q: np.ndarray) -> np.ndarray:
        """Per row of ``q`` (positions of the stopped axes, rad), whether each activates its limit (MuJoCo's rule)."""
        return (q - self._stop_lo < self._stop_margin) | (self._stop_hi - q < self._stop_margin)

    def _axes_of(self, near: np.ndarray) -> np.ndarray:
        """Rows of per-stopped-axis flags as rows of (pitch, yaw) flags."""
        out = np.zeros((near.shape[0], len(AXES)), bool)
        out[:, self._stop_axis] = near
        return out

    def _roll(
        self, columns: StateColumns, ctrl: np.ndarray, gust: np.ndarray, pushed: np.ndarray | None
    ) -> tuple[np.ndarray, ...] | None:
        """Step the twin's data through every interval of ``ctrl`` (rotor controls per interval) under the torques
        ``gust`` (per interval) and ``pushed`` (per physics step) in chunked rollouts.

        Returns the positions, rates and activations at every sample, the end included (``N + 1`` rows each), and per
        interval whether its start, and whether any of its physics steps' starts, activated a stop (one column per
        stopped axis); None at a warning, a reset or a non-finite or runaway state at an interval's end.
        """
        m, d, nsub = self.model, self.data, self._nsub
        n, nu = ctrl.shape
        torques = bool(self.gust.std) or pushed is not None
        spec = ROLLOUT_CONTROL if torques else _CTRL_ONLY
        per = max(1, CHUNK_STEPS // nsub)
        size = min(per, n) * nsub
        controls = np.zeros((1, size, mujoco.mj_stateSize(m, spec)))
        record = np.empty((1, size, m.nsensordata))
        start = np.empty((1, mujoco.mj_stateSize(m, FULL_STATE)))
        q, v, act = np.empty((n + 1, m.nq)), np.empty((n + 1, m.nv)), np.empty((n + 1, m.na))
        near_start = np.empty((n, self._stop_qpos.size), bool)
        near_any = np.empty_like(near_start)
        dt = m.opt.timestep
        stop_cols = columns.qpos[self._stop_qpos]
        with rollout.Rollout(nthread=0) as pool:
            for a in range(0, n, per):
                b = min(n, a + per)
                steps = (b - a) * nsub
                c = controls[:, :steps]
                per_step = c.reshape(b - a, nsub, -1)
                per_step[:, :, :nu] = ctrl[a:b, None, :]
                if torques:
                    held = np.broadcast_to(gust[a:b, None, :], (b - a, nsub, len(AXES)))
                    if pushed is not None:
                        held = held + pushed[a * nsub : b * nsub].reshape(b - a, nsub, len(AXES))
                    per_step[:, :, nu + self._free_dof] = held[:, :, self._free]
                mujoco.mj_getState(m, d, start[0], FULL_STATE)
                t0 = d.time
                pool.rollout(
                    [m],
                    [d],
                    start,
                    c,
                    control_spec=spec,
                    nstep=steps,
                    initial_warmstart=d.qacc_warmstart[None].copy(),
                    sensordata=record[:, :steps],
                    skip_checks=True,
                )
                rows = record[0, :steps]
                samples = rows[::nsub]
                q[a:b], v[a:b], act[a:b] = samples[:, columns.qpos], samples[:, columns.qvel], samples[:, columns.act]
                q[b], v[b], act[b] = d.qpos, d.qvel, d.act  # the chunk's end: the next chunk's start, or the run's end
                ends = slice(a + 1, b + 1)
                if (
                    d.warning.number.any()  # rollout counts each call's warnings from zero, and stops at one
                    or d.time < t0 + (steps - 0.5) * dt  # MuJoCo resets the data when accelerations blow up
                    or not (np.abs(v[ends]).max(initial=0.0) <= MAX_RATE)
                    or not (np.isfinite(q[ends]).all() and np.isfinite(act[ends]).all())
                ):
                    return None
                near = self._near(rows[:, stop_cols]).reshape(b - a, nsub, -1)
                near_start[a:b] = near[:, 0]
                near_any[a:b] = near.any(axis=1)
        return q, v, act, near_start, near_any
